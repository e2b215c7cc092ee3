// collision/src/narrowphase/epa_polytope.h -- the expanding polytope of EPA (van den Bergen 2001
// §4), one structure for both EPAs: the bounded decision in gjk.cpp (vertices w = a - b) and the
// full depth with witnesses in epa.cpp (SupportVertex). Private to collision.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
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

    /// Directions to probe for a support point off the span of a start simplex of 1 to 3
    /// vertices (GJK's final simplex when it is not a tetrahedron): the six axis directions
    /// from a point, four normals of a segment, the two normals of a triangle. 0 when the
    /// simplex is degenerate: a segment shorter than eps, a triangle of area below eps^2.
    int blowUpDirections(std::array<Vec3, 6>& dirs) const {
        const Vec3& w0 = point(0);
        if (vertex_count == 1) {
            dirs = {Vec3::UnitX(),  -Vec3::UnitX(), Vec3::UnitY(),
                    -Vec3::UnitY(), Vec3::UnitZ(),  -Vec3::UnitZ()};
            return 6;
        }
        if (vertex_count == 2) {
            const Vec3 e = point(1) - w0;
            const Real e_len = e.norm();
            if (!(e_len > eps)) return 0;
            int axis = 0;
            e.cwiseAbs().minCoeff(&axis);
            const Vec3 d1 = e.cross(Vec3::Unit(axis)).normalized();
            const Vec3 d2 = (e / e_len).cross(d1);
            dirs = {d1, -d1, d2, -d2, Vec3::Zero(), Vec3::Zero()};
            return 4;
        }
        const Vec3 n = (point(1) - w0).cross(point(2) - w0);
        const Real len = n.norm();
        if (!(len > eps * eps)) return 0;
        dirs = {n / len, -n / len, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
        return 2;
    }

    /// How far `w`, found along probe direction `dir`, lies off the span of the start simplex
    /// (distance from the point, from the segment's line, from the triangle's plane): above eps,
    /// it is the next vertex.
    Real offSpan(const Vec3& dir, const Vec3& w) const {
        const Vec3& w0 = point(0);
        if (vertex_count == 1) return (w - w0).norm();
        if (vertex_count == 2) {
            const Vec3 e = point(1) - w0;
            return e.cross(w - w0).norm() / e.norm();
        }
        return std::abs(dir.dot(w - w0));
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

    /// Adds `v`, a support point beyond the face nearest the origin, removes the faces that see
    /// it (it lies more than eps / 2 above their plane) and closes the hole with a fan of faces
    /// from the horizon (the removed faces' boundary) to it (van den Bergen 2001 §4). False when
    /// the polytope is full.
    bool expand(const Vertex& v) {
        if (vertex_count >= kMaxVertices) return false;
        const int new_index = vertex_count;
        vert[static_cast<std::size_t>(vertex_count++)] = v;
        const Vec3& w = pointOf(v);
        std::array<std::array<int, 2>, 3 * kMaxFaces> edges;  // the first edge_count are set
        int edge_count = 0;
        for (int f = 0; f < face_count; ++f) {
            Face& face = faces[static_cast<std::size_t>(f)];
            if (!face.valid) continue;
            const bool visible = face.normal.isZero() ||
                                 face.normal.dot(w - point(face.v[0])) > eps * Real(0.5);
            if (!visible) continue;
            face.valid = false;
            for (int e = 0; e < 3; ++e) {
                const int i = face.v[static_cast<std::size_t>(e)];
                const int j = face.v[static_cast<std::size_t>((e + 1) % 3)];
                // An edge shared by two removed faces appears in both directions: cancel it.
                bool cancelled = false;
                for (int k = 0; k < edge_count; ++k) {
                    auto& edge = edges[static_cast<std::size_t>(k)];
                    if (edge[0] == j && edge[1] == i) {
                        edge = edges[static_cast<std::size_t>(--edge_count)];
                        cancelled = true;
                        break;
                    }
                }
                if (!cancelled) edges[static_cast<std::size_t>(edge_count++)] = {i, j};
            }
        }
        int kept = 0;
        for (int f = 0; f < face_count; ++f) {
            if (faces[static_cast<std::size_t>(f)].valid) {
                faces[static_cast<std::size_t>(kept++)] = faces[static_cast<std::size_t>(f)];
            }
        }
        face_count = kept;
        for (int k = 0; k < edge_count; ++k) {
            const auto& edge = edges[static_cast<std::size_t>(k)];
            if (!addFace(edge[0], edge[1], new_index)) return false;
        }
        return true;
    }

    /// True when `w` is one of the vertices again, up to kDuplicateRelative * max(|w|, scale)
    /// (gjk.h): such a support point cannot grow the polytope.
    bool holdsPoint(const Vec3& w, Real scale) const {
        const Real dup = kDuplicateRelative * std::max(w.norm(), scale);
        for (int i = 0; i < vertex_count; ++i) {
            if ((point(i) - w).squaredNorm() <= dup * dup) return true;
        }
        return false;
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
