// collision/src/narrowphase/collide_pairs.h -- the routines that decide the state of a convex
// pair (collide.cpp), private to collision. collide() dispatches to them; contact() takes its
// state from the same routines on the same arguments (the closed forms), or from the same
// decision on bit-identical GJK runs and the same box SAT measure (decideConvexCores in gjk.h,
// satBoxState and refineBoxState here), so the two agree by construction.
#pragma once

#include <algorithm>
#include <optional>

#include "collision/geometry/shape.h"
#include "collision/narrowphase/narrow_phase.h"
#include "geometry/closest_points.h"
#include "geometry/shape_measures.h"
#include "narrowphase/gjk.h"
#include "volumes/box_sat.h"

namespace collision {

/// What every pair routine of collide() and contact() gets: the touching tolerance and the scale
/// it is relative to.
struct PairContext {
    Real scale = 0;      ///< larger bounding radius of the two shapes
    Real tolerance = 0;  ///< absolute touching tolerance, kTouchRelativeTolerance * scale
};

inline PairContext pairContext(const Shape& a, const Shape& b) {
    PairContext ctx;
    ctx.scale = std::max(boundingRadius(a), boundingRadius(b));
    ctx.tolerance = kTouchRelativeTolerance * ctx.scale;
    return ctx;
}

namespace collide_pairs {

/// The one computation behind each closed form, in A's frame (A the canonically-first shape):
/// collide() classifies its signed distance, contact() builds its normal and witnesses from the
/// same numbers. Round pairs: the closest points of the cores (sphere centres, capsule
/// segments; RTCD 5.1.2, 5.1.9) and their distance.
struct RoundCores {
    Vec3 on_a = Vec3::Zero();
    Vec3 on_b = Vec3::Zero();
    Real distance = 0;  ///< |on_b - on_a|
};

// Inline, so that contact() calls the round closed forms directly (contact_round.h).
inline RoundCores sphereSphereCores(const RelativePose& b_in_a) {
    RoundCores cores;
    cores.on_b = b_in_a.position;
    cores.distance = (cores.on_b - cores.on_a).norm();
    return cores;
}

// RTCD 5.1.2: the sphere centre (A's origin) against the capsule's segment.
inline RoundCores sphereCapsuleCores(const Shape& capsule_b, const RelativePose& b_in_a) {
    const Real y = std::clamp(toB(b_in_a, Vec3::Zero()).y(), -capsule_b.half_height,
                              capsule_b.half_height);
    RoundCores cores;
    cores.on_b = b_in_a.rotation * Vec3(0, y, 0) + b_in_a.position;
    cores.distance = (cores.on_b - cores.on_a).norm();
    return cores;
}

// RTCD 5.1.9 (closestSegmentSegment) on the two capsules' segments.
inline RoundCores capsuleCapsuleCores(const Shape& a, const Shape& b,
                                      const RelativePose& b_in_a, const PairContext& ctx) {
    const Vec3 pa(0, -a.half_height, 0);
    const Vec3 qa(0, a.half_height, 0);
    const Vec3 axis_b = b_in_a.rotation.col(1);
    const Vec3 pb = b_in_a.position - b.half_height * axis_b;
    const Vec3 qb = b_in_a.position + b.half_height * axis_b;
    const SegmentParameters st = closestSegmentSegment(pa, qa, pb, qb, kEpsilon * ctx.scale);
    RoundCores cores;
    cores.on_a = pa + st.s * (qa - pa);
    cores.on_b = pb + st.t * (qb - pb);
    cores.distance = (cores.on_b - cores.on_a).norm();
    return cores;
}

/// Sphere A against box B (RTCD 5.1.3), in the box's frame: the sphere centre, its clamp to the
/// box and, when the centre is inside, the axis of the nearest face.
struct SphereBoxCore {
    Vec3 centre = Vec3::Zero();
    Vec3 clamped = Vec3::Zero();
    bool inside = false;
    int face_axis = 0;  ///< inside only; ties: the lowest axis
    Real signed_distance = 0;
};
SphereBoxCore sphereBoxCore(const Shape& a, const Shape& b, const RelativePose& b_in_a);

// Closed forms. Signed distance: positive gap, or minus the penetration depth.
CollideOutput sphereSphere(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                           const PairContext& ctx);
CollideOutput sphereBox(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                        const PairContext& ctx);
CollideOutput sphereCapsule(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                            const PairContext& ctx);
CollideOutput capsuleCapsule(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                             const PairContext& ctx);

/// The state the box SAT measure proves on its own: Penetrating when every axis's separation is
/// below -tolerance beyond its rounding bound (for boxes the least overlap over the 15 axes is
/// the exact depth), Touching when the largest lies in [-tolerance, 0] beyond its bound; nothing
/// otherwise (GJK then decides: refineBoxState).
std::optional<ContactState> satBoxState(const BoxSatMeasure& sat, Real tolerance);

/// GJK's decision on two boxes (decideConvexCores) refined by the SAT measure: a Separated
/// distance is at least the axes' proven gap, and a proven gap above the tolerance overrules a
/// disagreeing GJK (which can then only be rounding).
CollideOutput refineBoxState(CollideOutput convex, const BoxSatMeasure& sat, Real tolerance);

}  // namespace collide_pairs
}  // namespace collision
