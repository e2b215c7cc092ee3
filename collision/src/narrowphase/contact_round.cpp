// collision/src/narrowphase/contact_round.cpp -- contact() in closed form for sphere-box (RTCD
// 5.1.3), in the canonically-first shape's frame, from the same core computation as
// collide()'s closed form (collide_pairs.h), whose signed distance both classify. The round
// pairs are in contact_round.h.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "collision/assert.h"
#include "narrowphase/contact_pairs.h"

namespace collision::contact_pairs {

CollideOutput sphereBox(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                        Local& out) {
    const collide_pairs::SphereBoxCore core = collide_pairs::sphereBoxCore(a, b, rel);
    const Vec3& c = core.centre;
    const Vec3& q = core.clamped;
    const Vec3& h = b.half_extents;
    const Real tol = kFeatureRelative * ctx.scale;
    out.feature_a = {FeatureType::Face, 0};
    out.signed_distance = core.signed_distance;
    if (!core.inside) {
        const Vec3 outside = c - q;
        const Vec3 n_b = -outside / outside.norm();  // from the sphere towards the box, B's frame
        out.normal = rel.rotation * n_b;
        out.point_a = a.radius * out.normal;
        out.point_b = rel.rotation * q + rel.position;
        // Only the clamped coordinates lie on the box boundary.
        Vec3 probe = q;
        for (int k = 0; k < 3; ++k) {
            if (outside[k] == 0) probe[k] = std::clamp(q[k], -h[k] + 2 * tol, h[k] - 2 * tol);
        }
        out.feature_b = boxFeature(h, probe, tol);
    } else {
        // Leave through the nearest face (sign(0) = +).
        const int k = core.face_axis;
        const Real s = signOrPlus(c[k]);
        out.normal = rel.rotation * Vec3(-s * Vec3::Unit(k));
        out.point_a = a.radius * out.normal;
        Vec3 on_face = c;
        on_face[k] = s * h[k];
        out.point_b = rel.rotation * on_face + rel.position;
        out.feature_b = {FeatureType::Face, 2 * k + (s > 0 ? 1 : 0)};
    }
    return classifySignedDistance(out.signed_distance, ctx.tolerance);
}

}  // namespace collision::contact_pairs
