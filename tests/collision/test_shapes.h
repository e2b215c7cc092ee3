// tests/collision/test_shapes.h -- shape helpers shared by the collision tests and the benches
// (app/bench_*.cpp), written independently of the library's own shape measures.
#pragma once

#include <algorithm>

#include "collision/geometry/shape.h"

namespace cdlab_test {

/// Largest distance of the shape from its local origin: the sphere's radius, the box's half
/// diagonal, half height plus radius for a capsule, the farthest hull vertex otherwise.
inline collision::Real boundingRadius(const collision::Shape& s) {
    using collision::ShapeType;
    switch (s.type) {
        case ShapeType::Sphere:
            return s.radius;
        case ShapeType::Box:
            return s.half_extents.norm();
        case ShapeType::Capsule:
            return s.half_height + s.radius;
        default: {
            collision::Real r = 0;
            for (const collision::Vec3& v : s.hull->vertices) r = std::max(r, v.norm());
            return r;
        }
    }
}

}  // namespace cdlab_test
