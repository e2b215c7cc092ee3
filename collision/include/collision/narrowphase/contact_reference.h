// collision/narrowphase/contact_reference.h -- brute-force reference for contact(): the minimum
// overlap of the two shapes' projections over candidate directions (the separating axis theorem run
// over many axes). Slow on purpose and independent of GJK/EPA/SAT: tests and `cdlab bench convex`
// use it as ground truth.
#pragma once

#include "collision/geometry/shape.h"
#include "collision/math.h"

namespace collision {

struct OverlapReference {
    /// min over the candidate unit directions u of overlap(u) = max_{x in A} u.x - min_{x in B}
    /// u.x, world units. Every u gives overlap(u) >= penetration depth, so > 0: an upper bound on
    /// the depth (the depth itself when `exact`); <= 0: -overlap is a lower bound on the distance,
    /// and when `exact` the shapes are disjoint or touching.
    Real overlap = 0;
    /// Unit, world frame, from A towards B: moving B by overlap * axis makes the projections on
    /// the axis touch.
    Vec3 axis = Vec3::UnitX();
    /// Both shapes are polytopes (box, hull, or a mesh's hull): the candidates hold every face
    /// normal of A - B (faces of A and B, cross products of their edges), so a positive overlap is
    /// the exact penetration depth (up to rounding of the projections).
    bool exact = false;
};

/// overlap(u) of `a` at `pose_a` and `b` at `pose_b` along the world direction `u` (unit):
/// max over A of u.x minus min over B of u.x, from the support mappings (shape.h).
Real projectionOverlap(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                       const Vec3& u);

/// Minimum projection overlap of `a` at `pose_a` and `b` at `pose_b` over `sampled_directions`
/// Fibonacci-sphere directions plus every face normal and edge-edge cross product of polytopes
/// and capsule axes (crossed with the other shape's edges/axis). Convex shapes; a mesh is its
/// hull. O((sampled_directions + (edges_a * edges_b)) * (vertices_a + vertices_b)).
OverlapReference minimumOverlapReference(const Shape& a, const Pose& pose_a, const Shape& b,
                                         const Pose& pose_b, int sampled_directions = 2048);

/// Bounds on the signed distance (negative = penetration depth) known without contact(),
/// collide(), GJK or EPA: lower <= signed distance <= upper.
struct SignedDistanceBounds {
    Real lower = 0;
    Real upper = 0;  ///< +infinity when nothing better is known
};

/// Closed forms (both bounds equal, to rounding) for sphere-sphere, sphere-capsule, sphere-box
/// (RTCD 5.1.2, 5.1.3) and capsule-capsule (segment distance by ternary search over one segment's
/// parameter, independent of RTCD 5.1.9), in either order. Any other convex pair:
/// lower = -minimumOverlapReference(...).overlap, and upper = lower when the pair is two
/// penetrating polytopes (exact), else +infinity.
SignedDistanceBounds signedDistanceReference(const Shape& a, const Pose& pose_a, const Shape& b,
                                             const Pose& pose_b, int sampled_directions = 2048);

}  // namespace collision
