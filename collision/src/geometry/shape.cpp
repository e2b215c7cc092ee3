// collision/src/geometry/shape.cpp -- shape factories and support mappings (the GJK interface).
#include "collision/geometry/shape.h"

#include <utility>

#include "collision/assert.h"
#include "collision/bvh/bvh.h"

namespace collision {

std::string_view shapeTypeName(ShapeType type) {
    switch (type) {
        case ShapeType::Sphere: return "sphere";
        case ShapeType::Box: return "box";
        case ShapeType::Capsule: return "capsule";
        case ShapeType::ConvexHull: return "hull";
        case ShapeType::Mesh: return "mesh";
    }
    return "unknown";
}

Shape Shape::sphere(Real radius) {
    Shape s;
    s.type = ShapeType::Sphere;
    s.radius = radius;
    return s;
}

Shape Shape::box(const Vec3& half_extents) {
    Shape s;
    s.type = ShapeType::Box;
    s.half_extents = half_extents;
    return s;
}

Shape Shape::capsule(Real radius, Real half_height) {
    Shape s;
    s.type = ShapeType::Capsule;
    s.radius = radius;
    s.half_height = half_height;
    return s;
}

Shape Shape::convexHull(std::shared_ptr<const ConvexPolytope> hull) {
    CDLAB_ASSERT(hull && !hull->vertices.empty(), "hull needs vertices");
    Shape s;
    s.type = ShapeType::ConvexHull;
    s.hull = std::move(hull);
    return s;
}

Shape Shape::triangleMesh(std::shared_ptr<const TriangleMesh> mesh,
                          std::shared_ptr<const ConvexPolytope> hull) {
    CDLAB_ASSERT(mesh, "mesh shape without triangles");
    std::shared_ptr<const MeshBvh> bvh = buildMeshBvh(kDefaultMeshBvh, *mesh);
    return triangleMesh(std::move(mesh), std::move(hull), std::move(bvh));
}

Shape Shape::triangleMesh(std::shared_ptr<const TriangleMesh> mesh,
                          std::shared_ptr<const ConvexPolytope> hull,
                          std::shared_ptr<const MeshBvh> bvh) {
    CDLAB_ASSERT(mesh && hull && !hull->vertices.empty(), "mesh needs its hull");
    CDLAB_ASSERT(!bvh || bvh->triangleCount() == static_cast<std::int32_t>(mesh->triangles.size()),
                 "the hierarchy was built from another mesh");
    Shape s;
    s.type = ShapeType::Mesh;
    s.mesh = std::move(mesh);
    s.hull = std::move(hull);
    s.bvh = std::move(bvh);
    return s;
}

namespace {

// Ties break towards the lower index, so the support point is deterministic.
Vec3 supportOfPoints(const std::vector<Vec3>& points, const Vec3& dir) {
    std::size_t best = 0;
    Real best_dot = points[0].dot(dir);
    for (std::size_t i = 1; i < points.size(); ++i) {
        const Real d = points[i].dot(dir);
        if (d > best_dot) {
            best_dot = d;
            best = i;
        }
    }
    return points[best];
}

// Sign with sign(0) = +1, so a zero direction still yields a vertex of the shape.
Real signOrPlus(Real x) { return x < 0 ? Real(-1) : Real(1); }

}  // namespace

Vec3 supportPoint(const Shape& shape, const Vec3& dir) {
    switch (shape.type) {
        case ShapeType::Sphere: {
            const Real n = dir.norm();
            if (!(n > 0)) return Vec3(shape.radius, 0, 0);
            return dir * (shape.radius / n);
        }
        case ShapeType::Box:
            return Vec3(signOrPlus(dir.x()) * shape.half_extents.x(),
                        signOrPlus(dir.y()) * shape.half_extents.y(),
                        signOrPlus(dir.z()) * shape.half_extents.z());
        case ShapeType::Capsule: {
            const Vec3 tip(0, signOrPlus(dir.y()) * shape.half_height, 0);
            const Real n = dir.norm();
            if (!(n > 0)) return tip + Vec3(shape.radius, 0, 0);
            return tip + dir * (shape.radius / n);
        }
        case ShapeType::ConvexHull:
        case ShapeType::Mesh:
            return supportOfPoints(shape.hull->vertices, dir);
    }
    return Vec3::Zero();
}

}  // namespace collision
