// collision/volumes/bounding_volumes.h -- the per-body bounding volumes: sphere, AABB, OBB.
// Every overlap test here counts touching (distance exactly zero) as overlapping, so all broad
// phases agree on the boundary case.
#pragma once

#include <vector>

#include "collision/math.h"

namespace collision {

struct Shape;
struct ConvexPolytope;

/// Axis-aligned box, closed: [min, max] per axis. A point box (min == max) is valid.
struct Aabb {
    Vec3 min = Vec3::Zero();
    Vec3 max = Vec3::Zero();

    /// Closed-interval test on all three axes: touching faces overlap.
    bool overlaps(const Aabb& o) const {
        return min.x() <= o.max.x() && o.min.x() <= max.x() && min.y() <= o.max.y() &&
               o.min.y() <= max.y() && min.z() <= o.max.z() && o.min.z() <= max.z();
    }
    bool contains(const Vec3& p) const {
        return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
    }
    Vec3 center() const { return (min + max) * Real(0.5); }
    Vec3 extents() const { return max - min; }
};

/// Bounding sphere. Closed ball. As a mesh-BVH node volume (`sphere`) it is the point swept
/// sphere (PSS) of Larsen, Gottschalk, Lin, Manocha 2000, the simplest of their swept sphere
/// volumes beside the line (Lss) and rectangle (Rss) swept spheres in collision/bvh.h.
struct BoundingSphere {
    Vec3 center = Vec3::Zero();
    Real radius = 0;

    /// |c_a - c_b|^2 <= (r_a + r_b)^2: touching spheres overlap.
    bool overlaps(const BoundingSphere& o) const {
        const Real r = radius + o.radius;
        return (center - o.center).squaredNorm() <= r * r;
    }
};

/// Oriented box: centre, orthonormal axes (columns of `axes`, right-handed), half extents >= 0.
struct Obb {
    Vec3 center = Vec3::Zero();
    Mat3 axes = Mat3::Identity();
    Vec3 half_extents = Vec3::Zero();

    /// 15-axis separating-axis test (Gottschalk, Lin, Manocha 1996 §4; RTCD 4.4.1), with an
    /// epsilon on the cross-product axes so near-parallel edges never produce a false separation.
    /// Touching boxes overlap. Conservative: may report overlap for boxes a rounding error apart.
    bool overlaps(const Obb& o) const;
    /// The eight corners (for drawing and containment tests).
    void corners(Vec3 out[8]) const;
};

/// Local-frame bounding volumes of a shape, computed once per shape.
struct LocalBounds {
    BoundingSphere sphere;  ///< minimal enclosing sphere of the shape (Welzl for point sets)
    Obb obb;                ///< exact for primitives; fitObbTight of the hull for hulls and meshes
};

/// Fits the local volumes for `shape`: analytic for spheres, boxes and capsules; for hulls and
/// meshes the minimal sphere of the hull's vertices (expected O(V)) and fitObbTight.
LocalBounds fitLocalBounds(const Shape& shape);

/// The shape's exact world AABB at `pose` (the tightest axis-aligned box of the rotated shape).
/// Hull and mesh shapes cost O(number of hull vertices).
Aabb computeWorldAabb(const Shape& shape, const Pose& pose);

/// The local sphere moved to `pose`.
BoundingSphere transformSphere(const BoundingSphere& local, const Pose& pose);
/// The local OBB moved to `pose`.
Obb transformObb(const Obb& local, const Pose& pose);

/// Minimal enclosing sphere of a point set (Welzl 1991, move-to-front; RTCD 4.3.5).
/// Expected O(n); deterministic (no random shuffle). Empty input gives radius 0 at the origin.
BoundingSphere minimalEnclosingSphere(const std::vector<Vec3>& points);

/// An OBB from the principal axes of the covariance of the hull's surface (area-weighted
/// triangles, Gottschalk 1996 §3), so that dense clusters of vertices do not bias the axes; the
/// extents are the exact projections of the hull's vertices on those axes. A hull without faces
/// (fewer than 4 non-coplanar points) falls back to the vertex covariance.
Obb fitObbPrincipal(const ConvexPolytope& hull);

/// The smallest-volume box among candidate frames, each box the exact projection range of every
/// hull vertex (plus a relative slack of a few ulps of the hull's size, so containment holds
/// after rounding). Candidates: the principal frame above (so never larger than it), then for
/// each candidate axis the minimum-area rectangle of the hull projected along it (exact for that
/// axis: Freeman & Shapira 1975) -- axes: the principal and coordinate axes, the normals of the
/// hull's planar faces (the 128 largest), DiTO's triangle normals (Larsson & Källberg 2011), the
/// hull's edge directions (the 64 longest), and finally each axis of the best box so far (a few
/// rounds of coordinate descent).
/// Exact when some minimum-volume box has a face flush with a hull face (boxes, prisms, the
/// cube whatever its triangulation and vertex order); otherwise a heuristic: O'Rourke 1985 only
/// guarantees two adjacent box faces each flush with a hull edge, which is not searched.
/// Deterministic. Cost O(k (F + V + s log s)) for k <= 128 + 64 + 25 axes, F faces, V vertices
/// and s silhouette vertices per axis (measured: 2 ms for a 2,000-triangle torus, 30 ms for a
/// hull of 10,000 vertices; tests/bench/obb_fit_bench.cpp).
Obb fitObbTight(const ConvexPolytope& hull);

}  // namespace collision
