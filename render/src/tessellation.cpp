// render/src/tessellation.cpp -- see tessellation.h.
#include "tessellation.h"

#include <cmath>

namespace render {

UnitSphereGrid makeUnitSphereGrid(int slices) {
    UnitSphereGrid grid;
    grid.slices = slices;
    grid.stacks = slices / 2;
    grid.dirs.reserve(std::size_t(grid.stacks + 1) * (slices + 1));
    for (int i = 0; i <= grid.stacks; ++i) {
        const Real phi = kPi * Real(i) / Real(grid.stacks);
        const Real y = i == 0 ? Real(1) : i == grid.stacks ? Real(-1) : std::cos(phi);
        const Real r = i == 0 || i == grid.stacks ? Real(0) : std::sin(phi);
        for (int j = 0; j <= slices; ++j) {
            const Real theta = 2 * kPi * Real(j % slices) / Real(slices);
            grid.dirs.emplace_back(r * std::cos(theta), y, r * std::sin(theta));
        }
    }
    return grid;
}

void tessellateCapsule(const UnitSphereGrid& grid, Real radius, Real half_height, const Pose& pose,
                       const CameraFrame& cam, TriangleBuffer& out) {
    struct Ring {
        int index;
        Real offset;
    };
    std::vector<Ring> rings;
    rings.reserve(std::size_t(grid.stacks) + 2);
    const int equator = grid.stacks / 2;
    for (int i = 0; i <= equator; ++i) rings.push_back({i, half_height});
    for (int i = half_height > 0 ? equator : equator + 1; i <= grid.stacks; ++i) {
        rings.push_back({i, -half_height});
    }
    const Mat3 rot = pose.rotation();
    const Vec3 eye_pos = cam.toEye(pose.position);
    auto emit = [&](const Ring& ring, int j) {
        const Vec3& d = grid.at(ring.index, j);
        const Vec3 local(d.x() * radius, d.y() * radius + ring.offset, d.z() * radius);
        out.add(eye_pos + rot * local, rot * d);
    };
    for (std::size_t k = 0; k + 1 < rings.size(); ++k) {
        const Ring& a = rings[k];
        const Ring& b = rings[k + 1];
        for (int j = 0; j < grid.slices; ++j) {
            if (a.index != 0) {  // ring 0 is the pole: its quads are triangles
                emit(a, j);
                emit(b, j);
                emit(a, j + 1);
            }
            if (b.index != grid.stacks) {
                emit(a, j + 1);
                emit(b, j);
                emit(b, j + 1);
            }
        }
    }
}

void tessellateBox(const Vec3& half, const Pose& pose, const CameraFrame& cam,
                   TriangleBuffer& out) {
    const Mat3 rot = pose.rotation();
    const Vec3 eye_pos = cam.toEye(pose.position);
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3;
        const int v = (axis + 2) % 3;
        for (const Real sign : {Real(1), Real(-1)}) {
            const Vec3 n = Vec3::Unit(axis) * sign;
            Vec3 corner[4];
            const Real su[4] = {-1, 1, 1, -1};
            const Real sv[4] = {-1, -1, 1, 1};
            for (int k = 0; k < 4; ++k) {
                Vec3 c = Vec3::Zero();
                c[axis] = sign * half[axis];
                c[u] = su[k] * half[u];
                c[v] = sv[k] * half[v];
                corner[k] = eye_pos + rot * c;
            }
            const Vec3 nw = rot * n;
            for (const int k : {0, 1, 2, 0, 2, 3}) out.add(corner[k], nw);
        }
    }
}

}  // namespace render
