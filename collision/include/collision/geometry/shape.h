// collision/geometry/shape.h -- the shapes cdlab collides, in their local (body) frame.
// Bodies place a shape with a Pose; the shape's local origin is the body's reference point
// (the engine puts it at the centre of mass).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "collision/math.h"

namespace collision {

enum class ShapeType : std::uint8_t { Sphere, Box, Capsule, ConvexHull, Mesh };
inline constexpr int kShapeTypeCount = 5;

/// Lower-case name as used in scene files: "sphere", "box", "capsule", "hull", "mesh".
std::string_view shapeTypeName(ShapeType type);

/// An indexed triangle soup (counter-clockwise seen from outside when the mesh is closed).
class MeshBvh;

struct TriangleMesh {
    std::vector<Vec3> vertices;
    std::vector<std::array<std::int32_t, 3>> triangles;
};

/// A convex polytope: its vertices and its boundary triangulated (outward, counter-clockwise).
/// Built by `computeConvexHull` (convex_hull.h); vertices are exactly the hull's extreme points.
struct ConvexPolytope {
    std::vector<Vec3> vertices;
    std::vector<std::array<std::int32_t, 3>> faces;
};

/// A shape by value; meshes and hulls are shared and immutable. Build with the factories.
struct Shape {
    ShapeType type = ShapeType::Sphere;
    Real radius = 0;                    ///< sphere and capsule radius
    Real half_height = 0;               ///< capsule: segment from (0,-h,0) to (0,h,0)
    Vec3 half_extents = Vec3::Zero();   ///< box
    std::shared_ptr<const ConvexPolytope> hull;  ///< hull: the shape; mesh: its convex hull
    std::shared_ptr<const TriangleMesh> mesh;    ///< mesh only
    /// Mesh only: the hierarchy over `mesh`'s triangles, built once, shared and never changed
    /// (queries take the relative pose). Null: the narrow phase tests triangles by brute force.
    std::shared_ptr<const MeshBvh> bvh;

    static Shape sphere(Real radius);
    static Shape box(const Vec3& half_extents);
    /// A capsule along local y: the segment (0,-half_height,0)-(0,half_height,0) swept by radius.
    static Shape capsule(Real radius, Real half_height);
    static Shape convexHull(std::shared_ptr<const ConvexPolytope> hull);
    /// `hull` must be the convex hull of `mesh`'s vertices. Builds the mesh's hierarchy with the
    /// default volume type (kDefaultMeshBvh in bvh.h), O(n log n) in the triangle count.
    static Shape triangleMesh(std::shared_ptr<const TriangleMesh> mesh,
                              std::shared_ptr<const ConvexPolytope> hull);
    /// The same with a hierarchy built beforehand from `mesh` (buildMeshBvh), or null for none
    /// (the narrow phase then tests every triangle: the brute-force reference).
    static Shape triangleMesh(std::shared_ptr<const TriangleMesh> mesh,
                              std::shared_ptr<const ConvexPolytope> hull,
                              std::shared_ptr<const MeshBvh> bvh);

    bool isConvex() const { return type != ShapeType::Mesh; }
};

/// Support point of the shape in local direction `dir` (any length, may be zero): a point of the
/// shape maximising dot(p, dir). For meshes, the support of the convex hull.
Vec3 supportPoint(const Shape& shape, const Vec3& dir);

}  // namespace collision
