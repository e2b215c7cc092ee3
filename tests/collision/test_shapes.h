// tests/collision/test_shapes.h -- shape helpers shared by the collision tests and the benches
// (app/bench_*.cpp), written independently of the library's own shape measures.
#pragma once

#include <algorithm>
#include <memory>

#include "collision/bvh/bvh.h"
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

/// The shape scaled by `k` about its local origin: dimensions, hull and mesh vertices; a mesh's
/// hierarchy is rebuilt (with the same volume type) for the scaled copy.
inline collision::Shape scaledShape(const collision::Shape& s, collision::Real k) {
    collision::Shape out = s;
    out.radius *= k;
    out.half_height *= k;
    out.half_extents *= k;
    if (s.hull) {
        auto hull = std::make_shared<collision::ConvexPolytope>(*s.hull);
        for (collision::Vec3& v : hull->vertices) v *= k;
        out.hull = hull;
    }
    if (s.mesh) {
        auto mesh = std::make_shared<collision::TriangleMesh>(*s.mesh);
        for (collision::Vec3& v : mesh->vertices) v *= k;
        out.mesh = mesh;
        if (s.bvh) out.bvh = collision::buildMeshBvh(s.bvh->volumeName(), *mesh);
    }
    return out;
}

}  // namespace cdlab_test
