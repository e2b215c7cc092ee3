// app/lab/bench/convex_reference.h -- exact answers for `cdlab bench convex`, in long double and
// independent of every library under test: the signed distance of sphere, capsule and box pairs
// (closed forms; boxes: the 15-axis SAT depth when they overlap, the brute-force feature distance
// when apart), the projection overlap along a given normal and a point's distance from a surface,
// so each library's depth, normal and witness points get an error against the truth.
#pragma once

#include "collision/geometry/shape.h"
#include "collision/math.h"

namespace app {

/// Signed distance of `a` at `pose_a` and `b` at `pose_b` (negative: minus the penetration
/// depth), computed in long double and rounded once. Spheres, capsules and boxes (a box given as
/// its 8-point hull counts as the box); other shapes get NaN. Round pairs: the distance of the
/// cores (sphere centres, capsule segments: the smaller of the four end-point-to-segment
/// distances and the interior closest pair). Sphere-box: RTCD 5.1.3. Box-box: overlapping, the
/// least overlap over the 15 SAT axes (Gottschalk, Lin, Manocha 1996, "OBBTree" §4), which for
/// two boxes is the exact penetration depth; apart, the least of the vertex-box and edge-edge
/// distances (brute force over the 8 + 8 vertices and 12 x 12 edges).
collision::Real exactSignedDistance(const collision::Shape& a, const collision::Pose& pose_a,
                                    const collision::Shape& b, const collision::Pose& pose_b);

/// max over A of n.x minus min over B of n.x for the world unit direction `n` (A towards B), in
/// long double from the support functions. For a reported normal n and the exact signed distance
/// d, overlap(n) + d >= 0, with equality exactly when n is a valid contact normal (it separates
/// the shapes by the least move, or it is the direction of the closest points).
collision::Real exactOverlapAlong(const collision::Shape& a, const collision::Pose& pose_a,
                                  const collision::Shape& b, const collision::Pose& pose_b,
                                  const collision::Vec3& n);

/// Signed distance of the world point `p` from the surface of `s` at `pose` (negative inside),
/// in long double; a witness point on the surface gives 0. NaN for shapes other than spheres,
/// capsules and boxes (a box's 8-point hull counts as the box).
collision::Real surfaceDistance(const collision::Shape& s, const collision::Pose& pose,
                                const collision::Vec3& p);

}  // namespace app
