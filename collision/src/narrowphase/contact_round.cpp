// collision/src/narrowphase/contact_round.cpp -- contact() in closed form for the round pairs
// (sphere-sphere, sphere-capsule, capsule-capsule; RTCD 5.1.9) and sphere-box (RTCD 5.1.3), in
// the canonically-first shape's frame; the state is collide()'s closed form on the same
// arguments.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "collision/assert.h"
#include "geometry/closest_points.h"
#include "narrowphase/contact_pairs.h"

namespace collision::contact_pairs {

namespace {

// Both shapes reduce to points/segments inflated by radii: closest core points ca (on A) and cb
// (on B), direction from A to B. Witness points are the cores' points pushed out by the radii.
void roundContact(Real ra, Real rb, const Vec3& ca, const Vec3& cb, const Vec3& fallback_normal,
                  const Ctx& ctx, Local& out) {
    const Vec3 diff = cb - ca;
    const Real d = diff.norm();
    out.normal = d > kDirectionRelative * ctx.scale ? Vec3(diff / d) : fallback_normal;
    out.signed_distance = d - ra - rb;
    out.point_a = ca + ra * out.normal;
    out.point_b = cb - rb * out.normal;
}

}  // namespace

CollideOutput sphereSphere(const Shape& a, const Shape& b, const RelativePose& rel,
                           const Ctx& ctx, Local& out) {
    // Coincident centres: A's local +x.
    roundContact(a.radius, b.radius, Vec3::Zero(), rel.position, Vec3::UnitX(), ctx, out);
    out.feature_a = {FeatureType::Face, 0};
    out.feature_b = {FeatureType::Face, 0};
    return collide_pairs::sphereSphere(a, b, rel, ctx);
}

// RTCD 5.1.2: sphere centre against the capsule's segment.
CollideOutput sphereCapsule(const Shape& a, const Shape& b, const RelativePose& rel,
                            const Ctx& ctx, Local& out) {
    const Vec3 centre_in_b = toB(rel, Vec3::Zero());
    const Real y = std::clamp(centre_in_b.y(), -b.half_height, b.half_height);
    const Vec3 on_axis = rel.rotation * Vec3(0, y, 0) + rel.position;
    // Centre on the axis: the sphere leaves along B's local -x (so the normal is B's +x).
    roundContact(a.radius, b.radius, Vec3::Zero(), on_axis, rel.rotation.col(0), ctx, out);
    out.feature_a = {FeatureType::Face, 0};
    if (centre_in_b.y() < -b.half_height) {
        out.feature_b = {FeatureType::Vertex, 0};
    } else if (centre_in_b.y() > b.half_height) {
        out.feature_b = {FeatureType::Vertex, 1};
    } else {
        out.feature_b = {FeatureType::Edge, 0};
    }
    return collide_pairs::sphereCapsule(a, b, rel, ctx);
}

CollideOutput capsuleCapsule(const Shape& a, const Shape& b, const RelativePose& rel,
                             const Ctx& ctx, Local& out) {
    const Vec3 pa(0, -a.half_height, 0);
    const Vec3 qa(0, a.half_height, 0);
    const Vec3 axis_b = rel.rotation.col(1);
    const Vec3 pb = rel.position - b.half_height * axis_b;
    const Vec3 qb = rel.position + b.half_height * axis_b;
    const SegmentParameters st = closestSegmentSegment(pa, qa, pb, qb, kEpsilon * ctx.scale);
    const Vec3 ca = pa + st.s * (qa - pa);
    const Vec3 cb = pb + st.t * (qb - pb);
    // Crossing axes: the common perpendicular (towards B's centre); parallel axes: the component
    // of B's centre off A's axis, else A's local +x.
    Vec3 fallback = Vec3::UnitY().cross(axis_b);
    if (fallback.norm() > kParallelSin) {
        fallback.normalize();
    } else {
        fallback = Vec3(rel.position.x(), 0, rel.position.z());
        const Real len = fallback.norm();
        fallback = len > kDirectionRelative * ctx.scale ? Vec3(fallback / len) : Vec3::UnitX();
    }
    if (fallback.dot(rel.position) < 0) fallback = -fallback;
    roundContact(a.radius, b.radius, ca, cb, fallback, ctx, out);
    const Real tol = kFeatureRelative * ctx.scale;
    out.feature_a = capsuleFeature(a.half_height, ca, tol);
    out.feature_b = capsuleFeature(b.half_height, toB(rel, cb), tol);
    return collide_pairs::capsuleCapsule(a, b, rel, ctx);
}

// RTCD 5.1.3: the sphere centre clamped to the box (box frame); inside, the nearest face.
CollideOutput sphereBox(const Shape& a, const Shape& b, const RelativePose& rel,
                        const Ctx& ctx, Local& out) {
    const Vec3 c = toB(rel, Vec3::Zero());
    const Vec3& h = b.half_extents;
    const Vec3 q = c.cwiseMax(-h).cwiseMin(h);
    const Vec3 outside = c - q;
    const Real tol = kFeatureRelative * ctx.scale;
    out.feature_a = {FeatureType::Face, 0};
    if (!outside.isZero()) {
        const Real d = outside.norm();
        const Vec3 n_b = -outside / d;  // from the sphere towards the box, B's frame
        out.normal = rel.rotation * n_b;
        out.signed_distance = d - a.radius;
        out.point_a = a.radius * out.normal;
        out.point_b = rel.rotation * q + rel.position;
        // Only the clamped coordinates lie on the box boundary.
        Vec3 probe = q;
        for (int k = 0; k < 3; ++k) {
            if (outside[k] == 0) probe[k] = std::clamp(q[k], -h[k] + 2 * tol, h[k] - 2 * tol);
        }
        out.feature_b = boxFeature(h, probe, tol);
        return collide_pairs::sphereBox(a, b, rel, ctx);
    }
    // Inside: leave through the nearest face (ties: lowest axis; sign(0) = +).
    int k = 0;
    const Vec3 gap = h - c.cwiseAbs();
    gap.minCoeff(&k);
    const Real s = signOrPlus(c[k]);
    out.normal = rel.rotation * Vec3(-s * Vec3::Unit(k));
    out.signed_distance = -(gap[k] + a.radius);
    out.point_a = a.radius * out.normal;
    Vec3 on_face = c;
    on_face[k] = s * h[k];
    out.point_b = rel.rotation * on_face + rel.position;
    out.feature_b = {FeatureType::Face, 2 * k + (s > 0 ? 1 : 0)};
    return collide_pairs::sphereBox(a, b, rel, ctx);
}

}  // namespace collision::contact_pairs
