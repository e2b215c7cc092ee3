// tests/collision/test_meshes.h -- procedural meshes shared by the mesh tests: a torus and a cube
// whose faces are grids (exact coordinates, so translated copies touch exactly).
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

#include "collision/geometry/shape.h"

namespace cdlab_test {

/// A torus around local z: `nu` segments around the ring, `nv` around the tube, 2 nu nv triangles.
inline collision::TriangleMesh makeTorusMesh(collision::Real ring, collision::Real tube, int nu,
                                             int nv) {
    using collision::Real;
    collision::TriangleMesh m;
    for (int i = 0; i < nu; ++i) {
        const Real u = 2 * std::numbers::pi_v<Real> * i / nu;
        for (int j = 0; j < nv; ++j) {
            const Real v = 2 * std::numbers::pi_v<Real> * j / nv;
            const Real w = ring + tube * std::cos(v);
            m.vertices.emplace_back(w * std::cos(u), w * std::sin(u), tube * std::sin(v));
        }
    }
    auto id = [&](int i, int j) { return static_cast<std::int32_t>((i % nu) * nv + (j % nv)); };
    for (int i = 0; i < nu; ++i) {
        for (int j = 0; j < nv; ++j) {
            m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    }
    return m;
}

/// The cube [-1, 1]^3, each face an n x n grid of squares split in two triangles (12 n^2). With n
/// a power of two every coordinate is exact, so translated copies touch exactly.
inline collision::TriangleMesh makeGridCubeMesh(int n) {
    using collision::Real;
    collision::TriangleMesh m;
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = -1; side <= 1; side += 2) {
            const int u_axis = (axis + 1) % 3;
            const int v_axis = (axis + 2) % 3;
            const auto base = static_cast<std::int32_t>(m.vertices.size());
            for (int i = 0; i <= n; ++i) {
                for (int j = 0; j <= n; ++j) {
                    collision::Vec3 p;
                    p[axis] = side;
                    p[u_axis] = -1 + Real(2) * i / n;
                    p[v_axis] = -1 + Real(2) * j / n;
                    m.vertices.push_back(p);
                }
            }
            auto id = [&](int i, int j) {
                return base + static_cast<std::int32_t>(i * (n + 1) + j);
            };
            for (int i = 0; i < n; ++i) {
                for (int j = 0; j < n; ++j) {
                    m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
                    m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
                }
            }
        }
    }
    return m;
}

/// The two tori the hierarchy tests pose against each other (1,536 and 1,200 triangles), built
/// once per test executable.
inline const collision::TriangleMesh& torusA() {
    static const collision::TriangleMesh m = makeTorusMesh(1.0, 0.35, 48, 16);
    return m;
}
inline const collision::TriangleMesh& torusB() {
    static const collision::TriangleMesh m = makeTorusMesh(0.8, 0.3, 40, 15);
    return m;
}

}  // namespace cdlab_test
