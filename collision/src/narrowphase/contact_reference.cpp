// collision/src/narrowphase/contact_reference.cpp -- minimumOverlapReference(): the brute-force
// ground truth for contact() (contact_reference.h). Invariant: every candidate direction is
// normalised and its overlap is computed from the shapes' own support mappings (shape.h), never
// from GJK, EPA or SAT.
#include "collision/narrowphase/contact_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>
#include <vector>

namespace collision {

namespace {

// Directions shorter than this (relative) are parallel edges: their cross product is no axis.
constexpr Real kParallelRelative = Real(1e-9);

bool isPolytope(const Shape& s) {
    return s.type == ShapeType::Box || s.type == ShapeType::ConvexHull || s.type == ShapeType::Mesh;
}

// Face normals and edge directions of a shape in its local frame (round shapes: none, except a
// capsule's axis as an edge).
void localAxes(const Shape& s, std::vector<Vec3>& normals, std::vector<Vec3>& edges) {
    switch (s.type) {
        case ShapeType::Sphere:
            return;
        case ShapeType::Capsule:
            edges.push_back(Vec3::UnitY());
            return;
        case ShapeType::Box:
            for (int k = 0; k < 3; ++k) {
                normals.push_back(Vec3::Unit(k));
                edges.push_back(Vec3::Unit(k));
            }
            return;
        case ShapeType::ConvexHull:
        case ShapeType::Mesh: {
            const ConvexPolytope& h = *s.hull;
            std::set<std::pair<int, int>> seen;
            for (const auto& f : h.faces) {
                const Vec3& p = h.vertices[static_cast<std::size_t>(f[0])];
                const Vec3 n = (h.vertices[static_cast<std::size_t>(f[1])] - p)
                                   .cross(h.vertices[static_cast<std::size_t>(f[2])] - p);
                if (n.norm() > 0) normals.push_back(n.normalized());
                for (int e = 0; e < 3; ++e) {
                    const int i = f[static_cast<std::size_t>(e)];
                    const int j = f[static_cast<std::size_t>((e + 1) % 3)];
                    if (!seen.insert({std::min(i, j), std::max(i, j)}).second) continue;
                    const Vec3 d = h.vertices[static_cast<std::size_t>(j)] -
                                   h.vertices[static_cast<std::size_t>(i)];
                    if (d.norm() > 0) edges.push_back(d.normalized());
                }
            }
            return;
        }
    }
}

Real pointSegmentDistance(const Vec3& p, const Vec3& s0, const Vec3& s1) {
    const Vec3 d = s1 - s0;
    const Real len2 = d.squaredNorm();
    const Real t = len2 > 0 ? std::clamp((p - s0).dot(d) / len2, Real(0), Real(1)) : Real(0);
    return (p - (s0 + t * d)).norm();
}

// The distance from a point moving along p0p1 to segment q0q1 is convex in the parameter, so a
// ternary search finds the minimum (to ~kEpsilon of the parameter after 200 steps).
Real segmentSegmentDistance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
    Real lo = 0;
    Real hi = 1;
    for (int i = 0; i < 200; ++i) {
        const Real m1 = lo + (hi - lo) / 3;
        const Real m2 = hi - (hi - lo) / 3;
        if (pointSegmentDistance(p0 + m1 * (p1 - p0), q0, q1) <
            pointSegmentDistance(p0 + m2 * (p1 - p0), q0, q1)) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    return pointSegmentDistance(p0 + (lo + hi) / 2 * (p1 - p0), q0, q1);
}

// Capsule axis end points in the world frame (a sphere is a zero-length segment).
void worldSegment(const Shape& s, const Pose& pose, Vec3& s0, Vec3& s1) {
    const Vec3 half = pose.orientation * Vec3(0, s.half_height, 0);
    s0 = pose.position - half;
    s1 = pose.position + half;
}

}  // namespace

Real projectionOverlap(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                       const Vec3& u) {
    const Vec3 u_in_a = pose_a.orientation.conjugate() * u;
    const Vec3 u_in_b = pose_b.orientation.conjugate() * u;
    const Real max_a = u_in_a.dot(supportPoint(a, u_in_a));
    const Real min_b = u_in_b.dot(supportPoint(b, -u_in_b));
    return max_a - min_b + u.dot(pose_a.position - pose_b.position);
}

OverlapReference minimumOverlapReference(const Shape& a, const Pose& pose_a, const Shape& b,
                                         const Pose& pose_b, int sampled_directions) {
    // Everything in A's frame; B placed by (rot, pos). Subtracting positions first keeps far
    // poses exact enough.
    const Mat3 rot_a = pose_a.rotation();
    const Mat3 rot = rot_a.transpose() * pose_b.rotation();
    const Vec3 pos = rot_a.transpose() * (pose_b.position - pose_a.position);
    OverlapReference best;
    best.overlap = std::numeric_limits<Real>::infinity();
    best.exact = isPolytope(a) && isPolytope(b);
    auto consider = [&](const Vec3& u) {
        // overlap(u) = h_A(u) + h_B(-u), h the support function (max of u.x over the shape).
        const Real max_a = u.dot(supportPoint(a, u));
        const Vec3 u_in_b = rot.transpose() * u;
        const Real min_b = u.dot(pos) + u_in_b.dot(supportPoint(b, -u_in_b));
        const Real overlap = max_a - min_b;
        if (overlap < best.overlap) {
            best.overlap = overlap;
            best.axis = u;
        }
    };
    // Fibonacci sphere: n nearly uniform directions (both hemispheres).
    const int n = std::max(sampled_directions, 0);
    const Real golden = Real(M_PI) * (Real(3) - std::sqrt(Real(5)));
    for (int i = 0; i < n; ++i) {
        const Real z = Real(1) - (Real(2) * Real(i) + Real(1)) / Real(n);
        const Real r = std::sqrt(std::max(Real(0), Real(1) - z * z));
        const Real phi = golden * Real(i);
        consider(Vec3(r * std::cos(phi), r * std::sin(phi), z));
    }
    std::vector<Vec3> normals_a;
    std::vector<Vec3> edges_a;
    std::vector<Vec3> normals_b;
    std::vector<Vec3> edges_b;
    localAxes(a, normals_a, edges_a);
    localAxes(b, normals_b, edges_b);
    for (Vec3& v : normals_b) v = rot * v;
    for (Vec3& v : edges_b) v = rot * v;
    // Both signs: overlap(u) and overlap(-u) differ.
    for (const std::vector<Vec3>* set : {&normals_a, &normals_b}) {
        for (const Vec3& u : *set) {
            consider(u);
            consider(-u);
        }
    }
    for (const Vec3& ea : edges_a) {
        for (const Vec3& eb : edges_b) {
            const Vec3 c = ea.cross(eb);
            const Real len = c.norm();
            if (!(len > kParallelRelative)) continue;
            consider(c / len);
            consider(-c / len);
        }
    }
    best.axis = rot_a * best.axis;
    return best;
}

SignedDistanceBounds signedDistanceReference(const Shape& a, const Pose& pose_a, const Shape& b,
                                             const Pose& pose_b, int sampled_directions) {
    const bool round_a = a.type == ShapeType::Sphere || a.type == ShapeType::Capsule;
    const bool round_b = b.type == ShapeType::Sphere || b.type == ShapeType::Capsule;
    SignedDistanceBounds out;
    if (round_a && round_b) {
        Vec3 a0;
        Vec3 a1;
        Vec3 b0;
        Vec3 b1;
        worldSegment(a, pose_a, a0, a1);
        worldSegment(b, pose_b, b0, b1);
        const Real d = segmentSegmentDistance(a0, a1, b0, b1) - a.radius - b.radius;
        return {d, d};
    }
    const bool sphere_box = (a.type == ShapeType::Sphere && b.type == ShapeType::Box) ||
                            (a.type == ShapeType::Box && b.type == ShapeType::Sphere);
    if (sphere_box) {
        const Shape& sphere = a.type == ShapeType::Sphere ? a : b;
        const Shape& box = a.type == ShapeType::Sphere ? b : a;
        const Pose& pose_s = a.type == ShapeType::Sphere ? pose_a : pose_b;
        const Pose& pose_box = a.type == ShapeType::Sphere ? pose_b : pose_a;
        // Signed distance of the centre from the box (RTCD 5.1.3; inside: minus the face gap).
        const Vec3 q = pose_box.applyInverse(pose_s.position).cwiseAbs() - box.half_extents;
        const Real d = q.cwiseMax(0).norm() + std::min(q.maxCoeff(), Real(0)) - sphere.radius;
        return {d, d};
    }
    const OverlapReference ref = minimumOverlapReference(a, pose_a, b, pose_b, sampled_directions);
    out.lower = -ref.overlap;
    out.upper = ref.exact && ref.overlap > 0 ? -ref.overlap : std::numeric_limits<Real>::infinity();
    return out;
}

}  // namespace collision
