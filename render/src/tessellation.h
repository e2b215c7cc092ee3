// render/src/tessellation.h -- bodies as triangles: capsules and spheres on a latitude-longitude
// grid, boxes, hull faces and mesh triangles. Local frame first, then the body pose; positions go
// eye-relative into the frame's TriangleBuffer, normals to world space. Private to render.
#pragma once

#include <cstdint>
#include <vector>

#include "camera.h"
#include "gl_debug_draw.h"

namespace render {


/// Unit-sphere directions on a latitude-longitude grid, y up: (stacks + 1) rings of
/// (slices + 1) points, ring 0 at +y. Cached per slice count.
struct UnitSphereGrid {
    int slices = 0;
    int stacks = 0;
    std::vector<Vec3> dirs;
    const Vec3& at(int ring, int j) const { return dirs[std::size_t(ring) * (slices + 1) + j]; }
};

/// The grid for `slices` longitudes (slices / 2 latitude bands).
UnitSphereGrid makeUnitSphereGrid(int slices);

/// A capsule of radius r around the segment (0,-h,0)-(0,h,0); h = 0 gives a sphere. Smooth
/// normals: the upper hemisphere is shifted by +h, the lower by -h, and the band between the
/// two copies of the equator is the cylinder (its normals are the equator's, radial).
void tessellateCapsule(const UnitSphereGrid& grid, Real radius, Real half_height, const Pose& pose,
                       const CameraFrame& cam, TriangleBuffer& out);

/// The six faces of a box of half extents `half`, two triangles each, flat normals.
void tessellateBox(const Vec3& half, const Pose& pose, const CameraFrame& cam,
                   TriangleBuffer& out);

/// Flat-shaded triangles (hull faces, mesh triangles). The normal is turned toward the camera,
/// so open meshes and inconsistent winding still shade as seen; degenerate triangles are skipped.
template <typename Triangles>
void tessellateTriangles(const std::vector<Vec3>& vertices, const Triangles& triangles,
                         const Pose& pose, const CameraFrame& cam, TriangleBuffer& out) {
    const Mat3 rot = pose.rotation();
    const Vec3 eye_pos = cam.toEye(pose.position);
    const auto n_vertices = static_cast<std::int64_t>(vertices.size());
    for (const auto& tri : triangles) {
        if (tri[0] < 0 || tri[1] < 0 || tri[2] < 0 || tri[0] >= n_vertices ||
            tri[1] >= n_vertices || tri[2] >= n_vertices) {
            continue;
        }
        const Vec3 a = eye_pos + rot * vertices[std::size_t(tri[0])];
        const Vec3 b = eye_pos + rot * vertices[std::size_t(tri[1])];
        const Vec3 c = eye_pos + rot * vertices[std::size_t(tri[2])];
        const Vec3 e1 = b - a;
        const Vec3 e2 = c - a;
        const Vec3 cross = e1.cross(e2);
        const Real len = cross.norm();
        // Area relative to the edge lengths: a sliver this thin has no meaningful normal.
        if (!(len > 16 * collision::kEpsilon * (e1.squaredNorm() + e2.squaredNorm()))) continue;
        Vec3 n = cross / len;
        if (n.dot(a) > 0) n = -n;  // eye at the origin: face the viewer
        out.add(a, n);
        out.add(b, n);
        out.add(c, n);
    }
}

}  // namespace render
