// collision/src/geometry/triangle_distance.cpp -- closest points between two triangles (RTCD 5.1.5,
// 5.1.9, 5.1.10). Every candidate pair is a pair of actual points of the two triangles, so the
// reported distance is never below the true one by more than the rounding of those points.
#include "geometry/triangle_distance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "geometry/closest_points.h"
#include "geometry/triangle_triangle.h"

namespace collision {

namespace {

// RTCD 5.1.5: the point of triangle abc closest to p, by Voronoi regions. A degenerate triangle
// falls through to an edge or vertex region (its barycentric denominators are then not used
// unless positive).
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 ab = b - a;
    const Vec3 ac = c - a;
    const Vec3 ap = p - a;
    const Real d1 = ab.dot(ap);
    const Real d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const Vec3 bp = p - b;
    const Real d3 = ab.dot(bp);
    const Real d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const Real vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0 && d1 - d3 > 0) return a + ab * (d1 / (d1 - d3));
    const Vec3 cp = p - c;
    const Real d5 = ab.dot(cp);
    const Real d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const Real vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0 && d2 - d6 > 0) return a + ac * (d2 / (d2 - d6));
    const Real va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0 && (d4 - d3) + (d5 - d6) > 0) {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    const Real sum = va + vb + vc;
    if (!(sum > 0)) {
        // Degenerate (collinear corners): the closest of the three edges.
        Vec3 best = a;
        Real best_d = (p - a).squaredNorm();
        for (const auto& [u, v] : std::array<std::pair<Vec3, Vec3>, 3>{{{a, b}, {b, c}, {c, a}}}) {
            const Vec3 e = v - u;
            const Real len2 = e.squaredNorm();
            const Real t = len2 > 0 ? std::clamp((p - u).dot(e) / len2, Real(0), Real(1)) : 0;
            const Vec3 q = u + e * t;
            const Real d = (p - q).squaredNorm();
            if (d < best_d) {
                best_d = d;
                best = q;
            }
        }
        return best;
    }
    const Real denom = Real(1) / sum;
    return a + ab * (vb * denom) + ac * (vc * denom);
}

// RTCD 5.1.9: closest points of segments p1q1 and p2q2 (points allowed).
void closestPointsSegmentSegment(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2,
                                 Vec3* c1, Vec3* c2) {
    const SegmentParameters st = closestSegmentSegment(p1, q1, p2, q2, 0);
    *c1 = p1 + (q1 - p1) * st.s;
    *c2 = p2 + (q2 - p2) * st.t;
}

}  // namespace

TriangleDistance distanceTriangleTriangle(const Vec3& p1, const Vec3& q1, const Vec3& r1,
                                          const Vec3& p2, const Vec3& q2, const Vec3& r2) {
    TriangleDistance out;
    const std::array<Vec3, 3> t1{p1, q1, r1};
    const std::array<Vec3, 3> t2{p2, q2, r2};
    Real best = std::numeric_limits<Real>::infinity();
    auto consider = [&](const Vec3& x1, const Vec3& x2) {
        const Real d = (x1 - x2).squaredNorm();
        if (d < best) {
            best = d;
            out.point_on_1 = x1;
            out.point_on_2 = x2;
        }
    };
    for (int k = 0; k < 3; ++k) {
        const auto i = static_cast<std::size_t>(k);
        consider(t1[i], closestPointOnTriangle(t1[i], p2, q2, r2));
        consider(closestPointOnTriangle(t2[i], p1, q1, r1), t2[i]);
    }
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            Vec3 c1;
            Vec3 c2;
            closestPointsSegmentSegment(t1[static_cast<std::size_t>(i)],
                                        t1[static_cast<std::size_t>((i + 1) % 3)],
                                        t2[static_cast<std::size_t>(j)],
                                        t2[static_cast<std::size_t>((j + 1) % 3)], &c1, &c2);
            consider(c1, c2);
        }
    }
    if (testTriangleTriangle(p1, q1, r1, p2, q2, r2)) {
        // Touching or crossing: distance 0. Crossing triangles share a segment along which an
        // edge of one pierces the other: where each edge meets the other's plane, paired with
        // the closest point of that triangle, is a candidate (~0 apart for the piercing edge).
        auto pierce = [&](const std::array<Vec3, 3>& edges_of, const std::array<Vec3, 3>& tri,
                          bool first) {
            const Vec3 n = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
            for (std::size_t k = 0; k < 3; ++k) {
                const Vec3& u = edges_of[k];
                const Vec3& v = edges_of[(k + 1) % 3];
                const Real du = n.dot(u - tri[0]);
                const Real dv = n.dot(v - tri[0]);
                if (du * dv > 0 || du == dv) continue;
                const Vec3 x = u + (v - u) * (du / (du - dv));
                const Vec3 y = closestPointOnTriangle(x, tri[0], tri[1], tri[2]);
                if (first) {
                    consider(x, y);
                } else {
                    consider(y, x);
                }
            }
        };
        pierce(t1, t2, true);
        pierce(t2, t1, false);
        out.distance = 0;
        return out;
    }
    out.distance = std::sqrt(best);
    return out;
}

}  // namespace collision
