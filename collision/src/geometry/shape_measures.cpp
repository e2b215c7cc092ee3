// collision/src/geometry/shape_measures.cpp -- see shape_measures.h.
#include "geometry/shape_measures.h"

#include <array>
#include <cmath>
#include <functional>

#include "narrowphase/gjk.h"

namespace collision {

Real boundingRadius(const Shape& shape) {
    switch (shape.type) {
        case ShapeType::Sphere:
            return shape.radius;
        case ShapeType::Box:
            return shape.half_extents.norm();
        case ShapeType::Capsule:
            return shape.half_height + shape.radius;
        case ShapeType::ConvexHull:
        case ShapeType::Mesh:
            return ConvexCore::fromShape(shape).boundingRadius();
    }
    return 0;
}

bool isFinite(const Shape& shape, const Pose& pose) {
    return std::isfinite(shape.radius) && std::isfinite(shape.half_height) &&
           shape.half_extents.allFinite() && pose.position.allFinite() &&
           pose.orientation.coeffs().allFinite();
}

bool canonicalLess(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b) {
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
