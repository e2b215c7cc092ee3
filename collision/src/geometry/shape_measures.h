// collision/src/geometry/shape_measures.h -- what the narrow phase, contact() and the half-space
// queries share about shapes: their length scale, whether an input is usable at all, and the
// canonical order in which a pair is computed.
#pragma once

#include <array>
#include <cstddef>
#include <functional>

#include "collision/geometry/shape.h"

namespace collision {

/// Hulls' and meshes' boundingRadius: their hull's farthest vertex from the origin.
Real hullBoundingRadius(const Shape& shape);

/// Largest distance of the shape from its local origin: the length scale of its coordinates
/// (tolerances are relative to it). Hulls and meshes use their hull's farthest vertex.
inline Real boundingRadius(const Shape& shape) {
    switch (shape.type) {
        case ShapeType::Sphere:
            return shape.radius;
        case ShapeType::Box:
            return shape.half_extents.norm();
        case ShapeType::Capsule:
            return shape.half_height + shape.radius;
        case ShapeType::ConvexHull:
        case ShapeType::Mesh:
            return hullBoundingRadius(shape);
    }
    return 0;
}

/// True when the shape's dimensions and the pose are finite (NaN or inf anywhere makes the
/// query's answer Failed).
inline bool isFinite(const Shape& shape, const Pose& pose) {
    // x - x is +0 for finite x and NaN otherwise, and a NaN term makes the sum NaN: one
    // comparison instead of a branch per number.
    const auto zero = [](Real x) { return x - x; };
    const Vec3& h = shape.half_extents;
    const Vec3& p = pose.position;
    const Quat& q = pose.orientation;
    const Real sum = ((zero(shape.radius) + zero(shape.half_height)) +
                      (zero(h.x()) + zero(h.y()) + zero(h.z()))) +
                     ((zero(p.x()) + zero(p.y()) + zero(p.z())) +
                      ((zero(q.w()) + zero(q.x())) + (zero(q.y()) + zero(q.z()))));
    return sum == 0;
}

/// A strict order on (shape, pose): by type, then by a key of pose and dimensions, then by the
/// hull's and the mesh's addresses (equal keys and addresses mean identical inputs, where the
/// order does not matter; finite inputs, see isFinite). collide() and contact() compute every
/// pair with the lesser first, so (a, b) and (b, a) are the same computation mirrored.
inline bool canonicalLess(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b) {
    if (a.type != b.type) return a.type < b.type;
    // Lexicographic on the key; the first entry that differs decides.
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
    for (std::size_t k = 0; k < ka.size(); ++k) {
        if (ka[k] != kb[k]) return ka[k] < kb[k];
    }
    if (a.hull != b.hull) return std::less<const ConvexPolytope*>()(a.hull.get(), b.hull.get());
    return std::less<const TriangleMesh*>()(a.mesh.get(), b.mesh.get());
}

}  // namespace collision
