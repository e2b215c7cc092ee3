// collision/src/ccd/spheres.cpp -- sphere-sphere time of impact over one step of linear motion.
// Everything is computed on relative quantities (d0, dv), so the answer does not depend on
// where the pair sits in the world: a 1e6 offset changes it by rounding of the inputs only.
#include <algorithm>
#include <cmath>
#include <limits>

#include "collision/ccd/ccd.h"
#include "collision/geometry/shape.h"

namespace collision {

namespace {

// The closed form below. `round_early`: the discriminant's factors are rounded outwards (reach
// up, miss down, by kOutward) so the computed sqrt(D') is never below the one of the relative
// quantities, q never too small and c / q never late. Near grazing (D' ~ 0) the plain form's
// rounding of D' moves t by ~sqrt(eps) of the step in either direction; this moves it earlier.
constexpr Real kOutward = Real(8) * std::numeric_limits<Real>::epsilon();

CcdOutput sphereRoot(const Vec3& c0a, const Vec3& c1a, Real ra, const Vec3& c0b, const Vec3& c1b,
                     Real rb, bool round_early) {
    CcdOutput out;
    out.state = CcdState::Failed;
    if (!c0a.allFinite() || !c1a.allFinite() || !c0b.allFinite() || !c1b.allFinite() ||
        !std::isfinite(ra) || !std::isfinite(rb) || ra < 0 || rb < 0) {
        return out;
    }
    // Relative motion of B seen from A: d(t) = d0 + t * dv.
    Vec3 d0 = c0b - c0a;
    Vec3 dv = (c1b - c0b) - (c1a - c0a);
    Real radius = ra + rb;
    // Rescale by a power of two (exact) so squares neither overflow nor underflow: t is
    // invariant under scaling, and the result is bit-identical at every power-of-two scale.
    const Real size = std::max({d0.cwiseAbs().maxCoeff(), dv.cwiseAbs().maxCoeff(), radius});
    if (size > 0) {
        int exponent = 0;
        std::frexp(size, &exponent);
        d0 = d0 * std::ldexp(Real(1), -exponent);
        dv = dv * std::ldexp(Real(1), -exponent);
        radius = std::ldexp(radius, -exponent);
    }

    // |d0 + t dv|^2 = R^2  <=>  a t^2 + 2 b' t + c = 0 (half-b form).
    const Real a = dv.squaredNorm();
    const Real half_b = d0.dot(dv);
    // c = |d0|^2 - R^2 as a difference-of-squares product: no cancellation beyond the rounding
    // of |d0| itself (exact for axis-aligned d0), unlike d0.d0 - R*R near touching.
    const Real dist0 = d0.norm();
    const Real c = (dist0 - radius) * (dist0 + radius);

    auto contactNormal = [&](Real t) -> Vec3 {
        const Vec3 d = d0 + t * dv;
        const Real len = d.norm();
        // Normalise only if the length is meaningful against the pair's size.
        if (len > kEpsilon * (radius + d0.norm())) return d / len;
        const Real len0 = d0.norm();
        if (len0 > 0) return d0 / len0;
        return Vec3::UnitX();
    };

    out.iterations = 1;
    if (c < 0) {
        out.state = CcdState::Overlapped;
        out.t = out.t_upper = 0;
        out.normal = contactNormal(0);
        return out;
    }
    // From here the spheres do not overlap at t = 0. Impact needs approach: b' < 0.
    if (a == 0 || half_b >= 0) {
        out.state = CcdState::Separated;
        out.t = out.t_upper = 1;
        return out;
    }
    // Discriminant / 4, b'^2 - a c, by Lagrange's identity (d0.dv)^2 = |d0|^2 |dv|^2 -
    // |d0 x dv|^2: D' = (|dv| R)^2 - |d0 x dv|^2, i.e. the radius against the distance of closest
    // approach, as a difference-of-squares product. The textbook b'^2 - a c cancels when the
    // motion is long against the radii (|d0| >> R): both terms are ~|d0|^2 |dv|^2 and their
    // difference ~R^2 |dv|^2, which lost (|d0| / R)^2 of precision (measured: t off by 2e-12 at
    // 1e6 sizes of motion per step; this form is exact to rounding there, and exactly 0 for
    // head-on motion where the cross product vanishes). Grazing (== 0) counts as a Hit.
    const Real reach = std::sqrt(a) * radius * (round_early ? 1 + kOutward : 1);
    const Real miss = d0.cross(dv).norm() * (round_early ? 1 - kOutward : 1);
    const Real disc = (reach - miss) * (reach + miss);
    if (disc < 0) {
        out.state = CcdState::Separated;
        out.t = out.t_upper = 1;
        return out;
    }
    // q = -(b' + sign(b') sqrt(D')) never subtracts nearly equal numbers (b' < 0 here, so
    // q = -b' + sqrt(D') > 0); the roots are c / q (the earlier one) and q / a.
    // Numerical Recipes 3rd ed. §5.6.
    const Real q = -half_b + std::sqrt(disc);
    const Real t = c / q;  // q > 0 since -b' > 0; c >= 0 so t >= 0
    if (t > 1) {
        out.state = CcdState::Separated;
        out.t = out.t_upper = 1;
        return out;
    }
    out.state = CcdState::Hit;
    out.t = out.t_upper = t;
    out.normal = contactNormal(t);
    return out;
}

}  // namespace

CcdOutput timeOfImpactSpheres(const Vec3& c0a, const Vec3& c1a, Real ra, const Vec3& c0b,
                              const Vec3& c1b, Real rb) {
    return sphereRoot(c0a, c1a, ra, c0b, c1b, rb, false);
}

// The engine's entry for a sphere pair: the sweeps' centres move linearly whatever the
// rotation (Sweep::at: position = start + t translation), so the closed form above is the
// exact motion model, not an approximation of it.
ToiOutput timeOfImpactSphereSweeps(const ToiInput& input) {
    ToiOutput out;
    out.state = CcdState::Failed;
    out.t = 0;
    if (input.a == nullptr || input.b == nullptr || input.a->type != ShapeType::Sphere ||
        input.b->type != ShapeType::Sphere || !(input.target_gap >= 0) ||
        !std::isfinite(input.target_gap) || !(input.t_max >= 0)) {
        return out;
    }
    const Real ra = input.a->radius;
    const Real rb = input.b->radius;
    const Vec3 c0a = input.sweep_a.start.position;
    const Vec3 c0b = input.sweep_b.start.position;
    const Vec3 c1a = c0a + input.sweep_a.translation;
    const Vec3 c1b = c0b + input.sweep_b.translation;
    auto witnesses = [&](Real t, const Vec3& normal) {
        const Vec3 ca = c0a + t * input.sweep_a.translation;
        const Vec3 cb = c0b + t * input.sweep_b.translation;
        out.normal = normal;
        out.point_a = ca + ra * normal;
        out.point_b = cb - rb * normal;
        out.distance = std::max(Real(0), (cb - ca).norm() - ra - rb);
    };
    // Contact itself (target gap 0) decides Overlapped, as timeOfImpact does.
    const CcdOutput contact = timeOfImpactSpheres(c0a, c1a, ra, c0b, c1b, rb);
    out.iterations = 1;
    if (contact.state == CcdState::Failed) return out;
    if (contact.state == CcdState::Overlapped) {
        out.state = CcdState::Overlapped;
        out.normal = contact.normal;
        return out;
    }
    const CcdOutput gap = sphereRoot(c0a, c1a, ra + input.target_gap, c0b, c1b, rb, true);
    if (gap.state == CcdState::Failed) return out;
    if (gap.state == CcdState::Overlapped) {
        // Within the target gap at t = 0: a Hit at 0 with the present gap (the engine asks
        // again with half of it, so a separating pair goes free).
        out.state = CcdState::Hit;
        witnesses(0, gap.normal);
        return out;
    }
    if (gap.state == CcdState::Separated) {
        out.state = CcdState::Separated;
        out.t = input.t_max;
        return out;
    }
    // Bias the rounding earlier: with the discriminant rounded outwards, c / q is at most a few
    // ulps of t past the root of the rounded relative quantities; stepping back
    // kSphereToiSlack of the step keeps t before contact.
    const Real t = std::max(Real(0), gap.t - kSphereToiSlack);
    if (t > input.t_max) {
        out.state = CcdState::Separated;
        out.t = input.t_max;
        return out;
    }
    out.state = CcdState::Hit;
    out.t = t;
    witnesses(t, gap.normal);
    return out;
}

}  // namespace collision
