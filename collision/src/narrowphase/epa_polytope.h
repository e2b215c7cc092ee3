// collision/src/narrowphase/epa_polytope.h -- the expanding polytope of EPA (van den Bergen 2001
// §4), one structure for both EPAs: the bounded decision in gjk.cpp (vertices w = a - b) and the
// full depth with witnesses in epa.cpp (SupportVertex). Private to collision.
#pragma once

#include <array>
#include <utility>
#include <cstddef>
#include <limits>

#include "narrowphase/gjk.h"

namespace collision {

template <class Vertex, int kMaxVerticesIn>
struct EpaPolytope {
    static constexpr int kMaxVertices = kMaxVerticesIn;
    static constexpr int kMaxFaces = 2 * kMaxVertices;

    /// Set entirely by addFace; no default values, so the face array costs no zeroing.
    struct Face {
        std::array<int, 3> v;
        Vec3 normal;  ///< unit, outward; zero for a degenerate face
        Real dist;    ///< normal . vertex: signed distance of the plane from the origin
        bool valid;
    };

    // Only the first vertex_count / face_count entries are set.
    std::array<Vertex, kMaxVertices> vert;
    int vertex_count = 0;
    std::array<Face, kMaxFaces> faces;
    int face_count = 0;
    Real eps = 0;  ///< lengths below this (areas below eps^2) are degenerate

    const Vec3& point(int i) const { return pointOf(vert[static_cast<std::size_t>(i)]); }

    /// Appends face (i, j, k), counter-clockwise seen from outside; false when full.
    bool addFace(int i, int j, int k) {
        if (face_count >= kMaxFaces) return false;
        Face& f = faces[static_cast<std::size_t>(face_count++)];
        f.v = {i, j, k};
        f.valid = true;
        const Vec3& p = point(i);
        const Vec3 n = (point(j) - p).cross(point(k) - p);
        const Real len = n.norm();
        if (len > eps * eps) {
            f.normal = n / len;
            f.dist = f.normal.dot(p);
        } else {
            f.normal.setZero();
            f.dist = std::numeric_limits<Real>::infinity();
        }
        return true;
    }

    /// Closes the first four vertices (a tetrahedron) into four outward faces (RTCD 5.1.6 face
    /// order), swapping vertices 1 and 2 when they are wound inwards.
    void closeTetrahedron() {
        const Vec3& p0 = point(0);
        if ((point(1) - p0).cross(point(2) - p0).dot(point(3) - p0) > 0) {
            std::swap(vert[1], vert[2]);
        }
        addFace(0, 1, 2);
        addFace(0, 3, 1);
        addFace(0, 2, 3);
        addFace(1, 3, 2);
    }

    /// The valid, non-degenerate face nearest the origin (lowest index among equals), or -1.
    int closestFace() const {
        int best = -1;
        for (int f = 0; f < face_count; ++f) {
            const Face& face = faces[static_cast<std::size_t>(f)];
            if (!face.valid || face.normal.isZero()) continue;
            if (best < 0 || face.dist < faces[static_cast<std::size_t>(best)].dist) best = f;
        }
        return best;
    }
};

}  // namespace collision
