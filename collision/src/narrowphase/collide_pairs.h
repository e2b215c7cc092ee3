// collision/src/narrowphase/collide_pairs.h -- the routines that decide the state of a convex
// pair (collide.cpp), private to collision. collide() dispatches to them; contact() takes its
// state from the same routines on the same arguments (the closed forms), or from the same
// decision on bit-identical GJK runs and the same box SAT measure (decideConvexCores in gjk.h,
// satBoxState and refineBoxState here), so the two agree by construction.
#pragma once

#include <optional>

#include "collision/geometry/shape.h"
#include "collision/narrowphase/narrow_phase.h"
#include "narrowphase/gjk.h"
#include "volumes/box_sat.h"

namespace collision {

/// What every pair routine of collide() and contact() gets: the touching tolerance and the scale
/// it is relative to.
struct PairContext {
    Real scale = 0;      ///< larger bounding radius of the two shapes
    Real tolerance = 0;  ///< absolute touching tolerance, kTouchRelativeTolerance * scale
};

PairContext pairContext(const Shape& a, const Shape& b);

namespace collide_pairs {

// Closed forms, in A's frame (A the canonically-first shape). Signed distance: positive gap, or
// minus the penetration depth.
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
