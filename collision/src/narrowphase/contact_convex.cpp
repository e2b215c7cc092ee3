// collision/src/narrowphase/contact_convex.cpp -- contact() of any convex pair: GJK with witness
// points (gjk.h), EPA when the cores overlap (epa.h), and near touching the normal of EPA on the
// pair shifted into contact when that normal is stable (face contacts). The state is collide()'s
// decision (decideConvexCores) on the same GJK run.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include "collision/assert.h"
#include "narrowphase/epa.h"
#include "narrowphase/contact_pairs.h"

namespace collision::contact_pairs {

namespace {

// Near-touching pairs (gap or depth below kNormalRelative * scale): B is shifted into A by
// kShiftRelative * scale along a trial normal, so the cores overlap far above rounding, and GJK +
// EPA answer there: EPA's normal is a face normal of A - B made from support-point differences
// (exact to rounding), not a direction through a rounding-sized gap. The shift is repeated along
// the new normal until it no longer changes; then the witnesses shifted back satisfy
// point_b - point_a = separation * normal with separation = shift * (trial . normal) - depth.
constexpr Real kShiftRelative = Real(4) * kNormalRelative;
constexpr int kShiftRounds = 4;
constexpr Real kSameNormal = Real(1e-12);

struct Shifted {
    Vec3 normal;
    Real separation;
    Vec3 core_a;
    Vec3 core_b;
};

bool shiftedEpa(const ConvexCore& ca, const ConvexCore& cb, const RelativePose& rel,
                const Vec3& trial, Real scale, Shifted& out, std::int32_t& iterations) {
    const Real shift = kShiftRelative * scale;
    // A rounding-sized gap or depth leaves the trial normal arbitrary, even pointing from B to A:
    // then shifting along it separates the cores, and its opposite is tried.
    Vec3 dir = trial;
    bool flipped = false;
    for (int round = 0; round < kShiftRounds; ++round) {
        RelativePose moved = rel;
        moved.position -= shift * dir;
        const GjkWitnessOutput g = gjkWitness(ca, cb, moved, scale);
        iterations += g.iterations;
        EpaOutput e;
        if (g.state == GjkState::Overlapping) {
            e = epaPenetration(ca, cb, moved, g.simplex, scale);
            iterations += e.iterations;
        }
        if (e.state != EpaState::Converged || !(e.depth > 0)) {
            if (round > 0 || flipped) return false;
            dir = -dir;
            flipped = true;
            --round;
            continue;
        }
        if ((e.normal - dir).norm() <= kSameNormal) {
            out.normal = e.normal;
            out.separation = shift * dir.dot(e.normal) - e.depth;
            out.core_a = e.point_a;
            out.core_b = e.point_b + shift * dir;
            return true;
        }
        dir = e.normal;
    }
    return false;
}

}  // namespace

CollideOutput convexConvex(const Shape& a, const Shape& b, const RelativePose& rel,
                           const Ctx& ctx, Local& out) {
    const ConvexCore ca = ConvexCore::fromShape(a);
    const ConvexCore cb = ConvexCore::fromShape(b);
    const Real radii = ca.radius + cb.radius;
    const GjkWitnessOutput g = gjkWitness(ca, cb, rel, ctx.scale);
    // collide()'s decision on this very GJK run (its w's are gjkDistance's, bit for bit), told
    // what the full EPA's first iteration found when that ran.
    auto decide = [&](Real start_closest) {
        std::array<Vec3, 4> simplex{};
        for (int i = 0; i < g.simplex.n; ++i) {
            simplex[static_cast<std::size_t>(i)] = g.simplex.v[static_cast<std::size_t>(i)].w;
        }
        return decideConvexCores(g, simplex.data(), g.simplex.n, MinkowskiDifference{ca, cb, rel},
                                 radii, ctx.tolerance, ctx.scale, start_closest);
    };
    out.iterations = g.iterations;
    Vec3 core_a;
    Vec3 core_b;
    CollideOutput decision;
    if (g.state == GjkState::Separated && g.distance > kNormalRelative * ctx.scale) {
        decision = decide(std::numeric_limits<Real>::quiet_NaN());
        core_a = g.point_a;
        core_b = g.point_b;
        out.normal = (core_b - core_a).normalized();  // length ~ distance > 0, checked above
        out.signed_distance = g.distance - radii;
    } else if (g.state == GjkState::Failed) {
        out.state = ContactState::Failed;
        return decide(std::numeric_limits<Real>::quiet_NaN());
    } else {
        const EpaOutput e = epaPenetration(ca, cb, rel, g.simplex, ctx.scale);
        decision = decide(e.start_closest);
        out.iterations += e.iterations + (decision.iterations - g.iterations);
        // EPA started from a simplex without the origin (GJK stopped Separated, tiny gap) ends on
        // a face the origin lies outside of: a negative "depth" whose witnesses are not closest
        // points (point_b - point_a was off signed_distance * normal by more than the gap) and
        // whose normal may be far off. Such a pair is separated: GJK's distance and closest
        // points answer, consistent by construction (point_b - point_a = distance * normal).
        const bool epa_penetrating = e.state == EpaState::Converged && e.depth > 0;
        if (g.state == GjkState::Separated && g.distance > 0 && !epa_penetrating &&
            (g.point_b - g.point_a).norm() > 0) {
            core_a = g.point_a;
            core_b = g.point_b;
            out.normal = (core_b - core_a).normalized();
            out.signed_distance = g.distance;
        } else if (e.state == EpaState::Converged) {
            core_a = e.point_a;
            core_b = e.point_b;
            out.normal = e.normal;
            out.signed_distance = -e.depth;
        } else {
            out.state = ContactState::Failed;
            return decision;
        }
        // Either direction runs through a gap or depth of rounding size (a face-to-face touching
        // pair got normals 70 degrees off its face normal): shiftedEpa() measures the contact
        // again with the cores overlapping well above rounding. Only an answer whose normal is
        // stable under the shift replaces this one (face contacts, not vertex-vertex).
        Shifted shifted;
        if (std::abs(out.signed_distance) <= kNormalRelative * ctx.scale &&
            shiftedEpa(ca, cb, rel, out.normal, ctx.scale, shifted, out.iterations)) {
            out.normal = shifted.normal;
            out.signed_distance = shifted.separation;
            core_a = shifted.core_a;
            core_b = shifted.core_b;
        }
        out.signed_distance -= radii;
    }
    out.point_a = core_a + ca.radius * out.normal;
    out.point_b = core_b - cb.radius * out.normal;
    const Real tol = kFeatureRelative * ctx.scale;
    out.feature_a = coreFeature(a, core_a, tol);
    out.feature_b = coreFeature(b, toB(rel, core_b), tol);
    out.state = ContactState::Touching;  // placeholder: the caller takes the decision's
    return decision;
}

}  // namespace collision::contact_pairs
