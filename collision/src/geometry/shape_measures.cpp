// collision/src/geometry/shape_measures.cpp -- see shape_measures.h.
#include "geometry/shape_measures.h"

#include <cmath>

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

}  // namespace collision
