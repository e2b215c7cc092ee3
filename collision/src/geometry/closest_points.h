// collision/src/geometry/closest_points.h -- closest points, one implementation each: between two
// segments (RTCD 5.1.9: capsule pairs, triangle distance) and from the origin to a segment,
// triangle or tetrahedron with barycentric weights (RTCD 5.1.2, 5.1.5, 5.1.6: the GJK simplex
// step). Private to collision; inline because every caller sits in a hot loop.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "collision/math.h"

namespace collision {

/// Below this multiple of kEpsilon times the squared edge lengths a triangle's (or a
/// tetrahedron face's) signed area is rounding noise: it is treated as degenerate.
inline constexpr Real kDegenerateRelative = Real(1e3) * kEpsilon;

/// Parameters of the closest points p1 + s (q1 - p1) and p2 + t (q2 - p2), s, t in [0, 1].
struct SegmentParameters {
    Real s = 0;
    Real t = 0;
};

/// Closest points of segments p1q1 and p2q2 (RTCD 5.1.9). A segment whose squared length is at
/// most `length_epsilon`^2 is taken as its first point (0 treats only exact points so).
/// Near-parallel segments (a e - b^2 = a e sin^2 below 16 eps a e) take s = 0 and clamp from
/// there, which still gives a closest pair. Approximate: the parameters carry the rounding of a
/// few dot products; never NaN for finite input.
inline SegmentParameters closestSegmentSegment(const Vec3& p1, const Vec3& q1, const Vec3& p2,
                                               const Vec3& q2, Real length_epsilon) {
    const Vec3 d1 = q1 - p1;
    const Vec3 d2 = q2 - p2;
    const Vec3 r = p1 - p2;
    const Real a = d1.squaredNorm();
    const Real e = d2.squaredNorm();
    const Real f = d2.dot(r);
    const Real eps2 = length_epsilon * length_epsilon;
    SegmentParameters out;
    Real& s = out.s;
    Real& t = out.t;
    if (a <= eps2 && e <= eps2) return out;
    if (a <= eps2) {
        t = std::clamp(f / e, Real(0), Real(1));
        return out;
    }
    const Real c = d1.dot(r);
    if (e <= eps2) {
        s = std::clamp(-c / a, Real(0), Real(1));
        return out;
    }
    const Real b = d1.dot(d2);
    const Real denom = a * e - b * b;
    if (denom > Real(16) * kEpsilon * a * e) {
        s = std::clamp((b * f - c * e) / denom, Real(0), Real(1));
    }
    t = (b * s + f) / e;
    if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, Real(0), Real(1));
    } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, Real(0), Real(1));
    }
    return out;
}

/// Closest point to the origin on segment ab (RTCD 5.1.2), with its weights: the point is
/// wa a + wb b, computed as a + t ab inside the segment and exactly a or b at its ends.
inline Vec3 closestOnSegment(const Vec3& a, const Vec3& b, Real& wa, Real& wb) {
    const Vec3 ab = b - a;
    const Real len2 = ab.squaredNorm();
    const Real t_num = -a.dot(ab);
    if (t_num <= 0 || !(len2 > 0)) {
        wa = 1;
        wb = 0;
        return a;
    }
    if (t_num >= len2) {
        wa = 0;
        wb = 1;
        return b;
    }
    const Real t = t_num / len2;
    wa = 1 - t;
    wb = t;
    return a + t * ab;
}

/// Closest point to the origin on triangle abc (RTCD 5.1.5, Voronoi regions), with barycentric
/// weights w. A sliver (signed area below kDegenerateRelative of |ab|^2 |ac|^2) is taken as its
/// nearest edge. In the face region the point is the plane projection n (n.a) / |n|^2.
inline Vec3 closestOnTriangle(const Vec3& a, const Vec3& b, const Vec3& c,
                              std::array<Real, 3>& w) {
    const Vec3 ab = b - a;
    const Vec3 ac = c - a;
    const Real d1 = -ab.dot(a);
    const Real d2 = -ac.dot(a);
    if (d1 <= 0 && d2 <= 0) {
        w = {1, 0, 0};
        return a;
    }
    const Real d3 = -ab.dot(b);
    const Real d4 = -ac.dot(b);
    if (d3 >= 0 && d4 <= d3) {
        w = {0, 1, 0};
        return b;
    }
    const Real vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const Real t = d1 / (d1 - d3);  // d1 >= 0 >= d3 and not both zero here
        w = {1 - t, t, 0};
        return a + t * ab;
    }
    const Real d5 = -ab.dot(c);
    const Real d6 = -ac.dot(c);
    if (d6 >= 0 && d5 <= d6) {
        w = {0, 0, 1};
        return c;
    }
    const Real vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const Real t = d2 / (d2 - d6);
        w = {1 - t, 0, t};
        return a + t * ac;
    }
    const Real va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const Real t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        w = {0, 1 - t, t};
        return b + t * (c - b);
    }
    const Real denom = va + vb + vc;
    const Real area_scale = ab.squaredNorm() * ac.squaredNorm();
    if (!(denom > kDegenerateRelative * area_scale)) {
        // Sliver triangle: the regions above are unreliable; take the best edge.
        std::array<Real, 3> best{1, 0, 0};
        Vec3 best_p = a;
        Real wa = 0;
        Real wb = 0;
        const Vec3 p_ab = closestOnSegment(a, b, wa, wb);
        best = {wa, wb, 0};
        best_p = p_ab;
        const Vec3 p_bc = closestOnSegment(b, c, wa, wb);
        if (p_bc.squaredNorm() < best_p.squaredNorm()) {
            best = {0, wa, wb};
            best_p = p_bc;
        }
        const Vec3 p_ca = closestOnSegment(c, a, wa, wb);
        if (p_ca.squaredNorm() < best_p.squaredNorm()) {
            best = {wb, 0, wa};
            best_p = p_ca;
        }
        w = best;
        return best_p;
    }
    // Face region: the origin's projection onto the plane, x = n (n.a) / |n|^2, with its
    // signed-area coordinates as weights. For slivers far from the origin this is much more
    // accurate than a + v ab + t ac, whose error grows like |a|^2 / area and can stall GJK at a
    // wrong distance (a 3e-5-thin box touching a 5-unit box came out 6e-6 apart).
    const Vec3 n = ab.cross(ac);
    const Real nn = n.squaredNorm();
    if (nn > 0) {
        const Vec3 x = n * (n.dot(a) / nn);
        const Real wa = n.dot((b - x).cross(c - x)) / nn;
        const Real wb = n.dot((c - x).cross(a - x)) / nn;
        w = {wa, wb, 1 - wa - wb};
        return x;
    }
    const Real v = vb / denom;
    const Real t = vc / denom;
    w = {1 - v - t, v, t};
    return a + ab * v + ac * t;
}

/// Closest point to the origin of tetrahedron w[0..3] (RTCD 5.1.6): the nearest of the faces
/// whose plane separates the origin from the opposite vertex (a face of a flat tetrahedron
/// counts as separating), with the weights of all four vertices. `enclosed` (and the origin
/// returned) when no face separates: the origin is inside up to rounding.
inline Vec3 closestOnTetrahedron(const std::array<Vec3, 4>& w, std::array<Real, 4>& weight,
                                 bool& enclosed) {
    static constexpr int kFaces[4][4] = {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 3, 2, 0}};
    enclosed = false;
    weight = {0, 0, 0, 0};
    Vec3 p = w[0];
    Real best = std::numeric_limits<Real>::infinity();
    bool any_outside = false;
    for (const auto& f : kFaces) {
        const Vec3& a = w[f[0]];
        const Vec3& b = w[f[1]];
        const Vec3& c = w[f[2]];
        const Vec3& d = w[f[3]];
        const Vec3 n = (b - a).cross(c - a);
        const Real sign_p = -a.dot(n);
        const Real sign_d = (d - a).dot(n);
        const bool degenerate =
            std::abs(sign_d) <= kDegenerateRelative * n.norm() * (d - a).norm();
        if (!degenerate && sign_p * sign_d >= 0) continue;  // origin on d's side
        any_outside = true;
        std::array<Real, 3> w3{};
        const Vec3 q = closestOnTriangle(a, b, c, w3);
        const Real q2 = q.squaredNorm();
        if (q2 < best) {
            best = q2;
            p = q;
            weight = {0, 0, 0, 0};
            weight[f[0]] = w3[0];
            weight[f[1]] = w3[1];
            weight[f[2]] = w3[2];
        }
    }
    if (!any_outside) {
        enclosed = true;
        return Vec3::Zero();
    }
    return p;
}

}  // namespace collision
