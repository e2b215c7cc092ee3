// collision/narrowphase/half_space.h -- a half-space (world bounds, a floor) against one convex
// shape: the contact query of contact.h in closed form, through the shape's support point along
// -normal.
//
// A query type of its own rather than a ShapeType: a half-space is unbounded, so it has no
// bounding sphere, AABB or OBB for the broad phases, no mass properties, no mesh for the
// renderer and no meaningful pair with a triangle mesh's BVH. As a Shape kind it would need a
// case in every one of those switches, each either meaningless or a rejection; as a separate
// type it is one struct and two functions, and callers that hold planes (the world's bounds)
// query them directly, outside the broad phase.
#pragma once

#include "collision/geometry/shape.h"
#include "collision/math.h"
#include "collision/narrowphase/contact.h"

namespace collision {

/// The closed half-space { x : dot(normal, x) <= offset }, world frame. `normal` is unit and
/// points out of the solid side; `offset` is in scene units (the plane's signed distance from
/// the origin along `normal`).
struct HalfSpace {
    Vec3 normal = Vec3::UnitY();
    Real offset = 0;
};

/// Contact of half-space `a` with convex shape `b` at `pose_b` (a Mesh counts as its convex
/// hull, as in contact()). Exact up to rounding: the signed distance is
/// min over b of dot(normal, x) - offset, reached at b's support point along -normal.
/// - state: the touching convention of narrow_phase.h with scale = b's bounding radius
///   (|signed distance| <= kTouchRelativeTolerance * scale is Touching). Far from the origin
///   the rounding of dot(normal, position) - offset (~kEpsilon * |offset|) can exceed that band.
/// - normal = a.normal (from A towards B); point_b: b's deepest (Touching/Penetrating) or
///   closest (Separated) point, point_a = point_b - signed_distance * normal, on the plane.
/// - feature_a = Face 0 (the plane); feature_b: b's support feature along -normal in contact.h's
///   numbering (a sphere: Face 0; a box: the vertex, edge or face whose vertices lie within
///   1e-9 * scale of the deepest; a capsule: Edge 0 when its axis is parallel to the plane to
///   that tolerance, else the lower cap, Vertex 0 or 1; a hull: vertex, edge (3 face + k) or
///   face by the same tolerance on its vertices).
/// - manifold (Touching/Penetrating): those of b's vertices (box, hull) within the touching band
///   of the plane or below it, at most four (the deepest, then the extremes along two directions
///   in the plane); a capsule's deepest point and the other end of its cylinder's lowest line
///   when that is in the band too; a sphere's one point. Each with its own depth (>= 0).
/// Failed, with every other field zero, for non-finite input or a normal whose length is not
/// within 1e-6 of 1. O(1), hulls O(vertices + faces).
ContactOutput contact(const HalfSpace& a, const Shape& b, const Pose& pose_b);

/// The same query with the shape first: the mirror of contact(b, a, pose_a) (normal negated,
/// points, features and manifold points swapped), bit for bit.
ContactOutput contact(const Shape& a, const Pose& pose_a, const HalfSpace& b);

}  // namespace collision
