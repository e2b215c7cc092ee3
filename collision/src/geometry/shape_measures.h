// collision/src/geometry/shape_measures.h -- what the narrow phase, contact() and the half-space
// queries share about shapes: their length scale, whether an input is usable at all, and the
// canonical order in which a pair is computed.
#pragma once

#include <array>
#include <functional>

#include "collision/geometry/shape.h"

namespace collision {

/// Largest distance of the shape from its local origin: the length scale of its coordinates
/// (tolerances are relative to it). Hulls and meshes use their hull's farthest vertex.
Real boundingRadius(const Shape& shape);

/// True when the shape's dimensions and the pose are finite (NaN or inf anywhere makes the
/// query's answer Failed).
bool isFinite(const Shape& shape, const Pose& pose);

/// A strict order on (shape, pose): by type, then by a key of pose and dimensions, then by the
/// hull's and the mesh's addresses (equal keys and addresses mean identical inputs, where the
/// order does not matter). collide() and contact() compute every pair with the lesser first,
/// so (a, b) and (b, a) are the same computation mirrored.
inline bool canonicalLess(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b) {
    if (a.type != b.type) return a.type < b.type;
    const std::array<Real, 12> ka{
        pose_a.position.x(),    pose_a.position.y(),    pose_a.position.z(),
        pose_a.orientation.w(), pose_a.orientation.x(), pose_a.orientation.y(),
        pose_a.orientation.z(), a.radius,               a.half_height,
        a.half_extents.x(),     a.half_extents.y(),     a.half_extents.z()};
    const std::array<Real, 12> kb{
        pose_b.position.x(),    pose_b.position.y(),    pose_b.position.z(),
        pose_b.orientation.w(), pose_b.orientation.x(), pose_b.orientation.y(),
        pose_b.orientation.z(), b.radius,               b.half_height,
        b.half_extents.x(),     b.half_extents.y(),     b.half_extents.z()};
    if (ka != kb) return ka < kb;
    if (a.hull != b.hull) return std::less<const ConvexPolytope*>()(a.hull.get(), b.hull.get());
    return std::less<const TriangleMesh*>()(a.mesh.get(), b.mesh.get());
}

}  // namespace collision
