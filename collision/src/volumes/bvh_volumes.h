// collision/src/volumes/bvh_volumes.h -- the traits of every BVH node volume (private to
// collision): fit from triangle corners, overlap under the relative pose of B in A's frame,
// containment (for validate), and cost (the volume, used for tightness and to pick the node to
// descend). Overlap tests are conservative: they may report overlap for volumes that are a
// tolerance apart, never separation for volumes that share a point.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <numbers>
#include <type_traits>
#include <vector>

#include "collision/bvh/bvh.h"
#include "collision/math.h"
#include "volumes/box_sat.h"

namespace collision {

/// Relative slack of the overlap tests, times the scene scale: covers the rounding of moving a
/// volume into A's frame and of the projections, so rounding never separates touching volumes.
inline constexpr Real kBvhOverlapSlack = Real(256) * kEpsilon;

/// The 13 k-DOP directions (unnormalised): axes, cube diagonals, face diagonals.
inline constexpr int kKdopDirectionCount = 13;
inline constexpr std::array<std::array<int, 3>, kKdopDirectionCount> kKdopDirections = {{
    {1, 0, 0},
    {0, 1, 0},
    {0, 0, 1},  // k = 6
    {1, 1, 1},
    {1, 1, -1},
    {1, -1, 1},
    {-1, 1, 1},  // + cube diagonals (14, 26)
    {1, 1, 0},
    {1, 0, 1},
    {0, 1, 1},
    {1, -1, 0},
    {1, 0, -1},
    {0, 1, -1},  // + edges (18, 26)
}};

/// Index into kKdopDirections of slab `i` of a Kdop<K>.
template <int K>
constexpr int kdopDirectionIndex(int i) {
    if constexpr (K == 18) return i < 3 ? i : i + 4;  // axes then the 6 face diagonals
    return i;                                         // 6, 14, 26 take a prefix
}

inline Vec3 kdopDirection(int index) {
    const auto& d = kKdopDirections[static_cast<std::size_t>(index)];
    return Vec3(Real(d[0]), Real(d[1]), Real(d[2]));
}

/// The relative pose of B in A's frame as the traversal uses it, with per-query precomputation:
/// p_a = r p_b + t. Built once per query (never per node pair).
struct BvhTransform {
    Mat3 r = Mat3::Identity();
    Vec3 t = Vec3::Zero();
    bool identity = true;  ///< r is exactly the identity: same-orientation fast paths
    Real tol = 0;          ///< absolute overlap slack (kBvhOverlapSlack times the scene scale)
    // k-DOP support: for each direction n, r^T n and n.t (A's slabs against B's box), and r n and
    // (r n).t (B's slabs against A's box, in B's frame).
    std::array<Vec3, kKdopDirectionCount> rt_dir;
    std::array<Real, kKdopDirectionCount> dir_dot_t;
    std::array<Vec3, kKdopDirectionCount> r_dir;
    std::array<Real, kKdopDirectionCount> r_dir_dot_t;

    /// A point of B's frame in A's frame. The one transform used by both the BVH queries and the
    /// brute-force reference, so both test bit-identical triangles.
    Vec3 apply(const Vec3& p) const { return r * p + t; }
};

/// `scale_a`, `scale_b`: the meshes' length scales (Bvh::scale()).
BvhTransform makeBvhTransform(const Pose& b_in_a, Real scale_a, Real scale_b);
/// The same from a rotation matrix (orthonormal) and a translation: p_a = rotation p_b + t.
BvhTransform makeBvhTransform(const Mat3& rotation, const Vec3& translation, Real scale_a,
                              Real scale_b);

/// Area-weighted moments of triangles about a fixed origin (Gottschalk 1996 §3): additive, so a
/// node's moments are the sum of its triangles'.
struct TriangleMoments {
    Real area = 0;
    Vec3 first = Vec3::Zero();   ///< sum of area * centroid
    Mat3 second = Mat3::Zero();  ///< sum of area/12 (9 m m^T + p p^T + q q^T + r r^T)
    void add(const TriangleMoments& o) {
        area += o.area;
        first += o.first;
        second += o.second;
    }
};
TriangleMoments triangleMoments(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& origin);
/// Principal axes of summed moments (largest variance first, right-handed); false for zero area.
/// Cancellation far from `origin` only loosens the fit: extents are measured along the axes.
bool momentAxes(const TriangleMoments& m, Mat3* axes);
/// Principal axes of triangles given as consecutive corner triples (covariance of the corners
/// when their total area is zero).
Mat3 principalAxes(const std::vector<Vec3>& corners);
/// Eigenvectors of a covariance, largest first, as a right-handed orthonormal frame.
Mat3 axesOfCovariance(const Mat3& cov);
/// The tight frame of one triangle: its longest edge, the in-plane perpendicular, the normal.
/// False for a sliver whose normal is lost in rounding.
bool triangleAxes(const Vec3& p, const Vec3& q, const Vec3& r, Mat3* axes);

template <class BV>
struct BvTraits;

/// Volume types whose traits can move B's volume into A's frame once (move) and test against
/// the moved copy (overlapsMoved); the traversals cache the moved copy of the current B node.
template <class BV>
concept MovableVolume = requires(const BV& v, const BvhTransform& x) {
    { BvTraits<BV>::move(v, x) } -> std::same_as<BV>;
    { BvTraits<BV>::overlapsMoved(v, v, x) } -> std::same_as<bool>;
};

// ---- Sphere: smallest enclosing sphere (Welzl), exact test. ----
template <>
struct BvTraits<BoundingSphere> {
    static BoundingSphere fit(const std::vector<Vec3>& corners);
    static bool overlaps(const BoundingSphere& a, const BoundingSphere& b, const BvhTransform& x) {
        const Real r = a.radius + b.radius + x.tol;
        return (x.apply(b.center) - a.center).squaredNorm() <= r * r;
    }
    static bool contains(const BoundingSphere& s, const Vec3& p, Real tol) {
        return (p - s.center).norm() <= s.radius + tol;
    }
    static Real cost(const BoundingSphere& s) {
        return Real(4) / Real(3) * std::numbers::pi_v<Real> * s.radius * s.radius * s.radius;
    }
};

// ---- AABB in the mesh frame. Under a rotation B's box is an OBB in A's frame: the exact 15-axis
// box test (no enclosing-box growth); with identical orientations the 3-axis interval test. ----
template <>
struct BvTraits<Aabb> {
    static Aabb fit(const std::vector<Vec3>& corners);
    /// The fit in mergeable parts (see MergeableFit): the box of the points is its own bounds.
    using Bounds = Aabb;
    static Bounds bounds(const Vec3* points, std::size_t count);
    static Bounds merge(const Bounds& a, const Bounds& b) {
        return Aabb{a.min.cwiseMin(b.min), a.max.cwiseMax(b.max)};
    }
    static Aabb finish(const Bounds& b) { return b; }
    static bool overlaps(const Aabb& a, const Aabb& b, const BvhTransform& x) {
        if (x.identity) {
            const Vec3 lo = b.min + x.t;
            const Vec3 hi = b.max + x.t;
            return (lo.array() <= a.max.array() + x.tol).all() &&
                   (a.min.array() <= hi.array() + x.tol).all();
        }
        const Vec3 ha = (a.max - a.min) * Real(0.5);
        const Vec3 hb = (b.max - b.min) * Real(0.5);
        const Vec3 t = x.apply((b.min + b.max) * Real(0.5)) - (a.min + a.max) * Real(0.5);
        return testSat15<false>(ha, x.r, t, hb, x.tol, 0);
    }
    static bool contains(const Aabb& box, const Vec3& p, Real tol) {
        return (p.array() >= box.min.array() - tol).all() &&
               (p.array() <= box.max.array() + tol).all();
    }
    static Real cost(const Aabb& box) { return box.extents().prod(); }
};

// ---- OBB (Gottschalk's OBBTree): area-weighted covariance of the node's triangles. ----
template <>
struct BvTraits<Obb> {
    static Obb fit(const std::vector<Vec3>& corners);
    /// The box along given orthonormal axes: exact projections plus slack.
    static Obb fitWithAxes(const std::vector<Vec3>& corners, const Mat3& axes);
    /// fitWithAxes in parts, for a build that measures the points' box separately: the box of
    /// the projection range [lo, hi] of the points about `origin` on `axes` (projectionRange),
    /// then widen() by the slack relative to the points' coordinate box. The same operations, so
    /// the same box.
    static Obb boxOfRange(const Mat3& axes, const Vec3& origin, const Vec3& lo, const Vec3& hi) {
        Obb box;
        box.axes = axes;
        box.center = origin + axes * ((lo + hi) * Real(0.5));
        box.half_extents = (hi - lo) * Real(0.5);
        return box;
    }
    static void widen(Obb& box, const Aabb& points_box);
    static bool overlaps(const Obb& a, const Obb& b, const BvhTransform& x) {
        return overlapsMoved(a, move(b, x), x);
    }
    /// B's box in A's frame: computed once per B node while the traversal descends A under it.
    static Obb move(const Obb& b, const BvhTransform& x) {
        return Obb{x.apply(b.center), x.r * b.axes, b.half_extents};
    }
    /// overlaps() with B already moved (the same products in the same order: the same answer).
    [[gnu::always_inline]] static bool overlapsMoved(const Obb& a, const Obb& moved,
                                                     const BvhTransform& x) {
        const Mat3 rot = a.axes.transpose() * moved.axes;
        const Vec3 t = a.axes.transpose() * (moved.center - a.center);
        return testSat15<false>(a.half_extents, rot, t, moved.half_extents, x.tol, 0);
    }
    static bool contains(const Obb& box, const Vec3& p, Real tol) {
        const Vec3 local = box.axes.transpose() * (p - box.center);
        return (local.cwiseAbs().array() <= box.half_extents.array() + tol).all();
    }
    static Real cost(const Obb& box) { return Real(8) * box.half_extents.prod(); }
};

// ---- k-DOP. Same orientation: exact slab-against-slab test. Under a rotation the slab
// directions no longer match, so the test is conservative: A's slabs against B's box (its first
// three slabs, an OBB in A's frame), then B's slabs against A's box in B's frame. Each slab is a
// true separating plane of the two sets, so a rejection is always right. ----
template <int K>
struct BvTraits<Kdop<K>> {
    static Kdop<K> fit(const std::vector<Vec3>& corners);
    /// The fit in mergeable parts (see MergeableFit): the exact slab ranges before the slack,
    /// and the points' coordinate box (the magnitude the slack is relative to; unused, and left
    /// at the first point, for K = 6, which has no slack).
    static constexpr bool kNeedsBox = Kdop<K>::kSlabs > 3;
    struct Bounds {
        Kdop<K> slabs;
        Vec3 lo;
        Vec3 hi;
    };
    static Bounds bounds(const Vec3* points, std::size_t count);
    static Bounds merge(const Bounds& a, const Bounds& b) {
        Bounds out;
        for (int i = 0; i < Kdop<K>::kSlabs; ++i) {
            out.slabs.min[i] = std::min(a.slabs.min[i], b.slabs.min[i]);
            out.slabs.max[i] = std::max(a.slabs.max[i], b.slabs.max[i]);
        }
        if constexpr (kNeedsBox) {
            out.lo = a.lo.cwiseMin(b.lo);
            out.hi = a.hi.cwiseMax(b.hi);
        } else {
            out.lo = a.lo;
            out.hi = a.hi;
        }
        return out;
    }
    static Kdop<K> finish(const Bounds& b);
    static bool overlaps(const Kdop<K>& a, const Kdop<K>& b, const BvhTransform& x) {
        constexpr int n = Kdop<K>::kSlabs;
        if (x.identity) {
            for (int i = 0; i < n; ++i) {
                const Real d = x.dir_dot_t[static_cast<std::size_t>(kdopDirectionIndex<K>(i))];
                if (b.min[i] + d > a.max[i] + x.tol || b.max[i] + d < a.min[i] - x.tol) {
                    return false;
                }
            }
            return true;
        }
        const Vec3 cb((b.min[0] + b.max[0]) * Real(0.5), (b.min[1] + b.max[1]) * Real(0.5),
                      (b.min[2] + b.max[2]) * Real(0.5));
        const Vec3 hb((b.max[0] - b.min[0]) * Real(0.5), (b.max[1] - b.min[1]) * Real(0.5),
                      (b.max[2] - b.min[2]) * Real(0.5));
        const Vec3 ca((a.min[0] + a.max[0]) * Real(0.5), (a.min[1] + a.max[1]) * Real(0.5),
                      (a.min[2] + a.max[2]) * Real(0.5));
        const Vec3 ha((a.max[0] - a.min[0]) * Real(0.5), (a.max[1] - a.min[1]) * Real(0.5),
                      (a.max[2] - a.min[2]) * Real(0.5));
        for (int i = 0; i < n; ++i) {
            const auto k = static_cast<std::size_t>(kdopDirectionIndex<K>(i));
            // n.(r cb + t) and the box's half projection sum_j |n.r_j| hb_j = |r^T n|.hb.
            const Real centre = x.rt_dir[k].dot(cb) + x.dir_dot_t[k];
            const Real radius = x.rt_dir[k].cwiseAbs().dot(hb);
            if (centre - radius > a.max[i] + x.tol || centre + radius < a.min[i] - x.tol) {
                return false;
            }
        }
        for (int i = 0; i < n; ++i) {
            const auto k = static_cast<std::size_t>(kdopDirectionIndex<K>(i));
            // A's box in B's frame: centre r^T (ca - t); m.(r^T (ca - t)) = (r m).ca - (r m).t.
            const Real centre = x.r_dir[k].dot(ca) - x.r_dir_dot_t[k];
            const Real radius = x.r_dir[k].cwiseAbs().dot(ha);
            if (centre - radius > b.max[i] + x.tol || centre + radius < b.min[i] - x.tol) {
                return false;
            }
        }
        return true;
    }
    static bool contains(const Kdop<K>& d, const Vec3& p, Real tol) {
        for (int i = 0; i < Kdop<K>::kSlabs; ++i) {
            const Real s = kdopDirection(kdopDirectionIndex<K>(i)).dot(p);
            if (s < d.min[i] - tol || s > d.max[i] + tol) return false;
        }
        return true;
    }
    static Real cost(const Kdop<K>& d) {
        // The volume of the axis slabs (an upper bound of the k-DOP's volume).
        return (d.max[0] - d.min[0]) * (d.max[1] - d.min[1]) * (d.max[2] - d.min[2]);
    }
};

// ---- RSS (Larsen et al. 2000): rectangle in the plane of the two largest principal axes. ----
template <>
struct BvTraits<Rss> {
    static Rss fit(const std::vector<Vec3>& corners);
    /// The RSS whose rectangle spans axes.col(0), axes.col(1) (orthonormal, right-handed).
    static Rss fitWithAxes(const std::vector<Vec3>& corners, const Mat3& axes);
    static bool overlaps(const Rss& a, const Rss& b, const BvhTransform& x) {
        return overlapsMoved(a, move(b, x), x);
    }
    /// B's volume in A's frame: computed once per B node while the traversal descends A under it.
    static Rss move(const Rss& b, const BvhTransform& x) {
        return Rss{x.apply(b.center), x.r * b.axes, b.half_lengths, b.radius};
    }
    /// overlaps() with B already moved (the same products in the same order: the same answer).
    static bool overlapsMoved(const Rss& a, const Rss& moved, const BvhTransform& x) {
        const Mat3 rot = a.axes.transpose() * moved.axes;
        const Vec3 t = a.axes.transpose() * (moved.center - a.center);
        const Vec3 ha(a.half_lengths[0], a.half_lengths[1], 0);
        const Vec3 hb(moved.half_lengths[0], moved.half_lengths[1], 0);
        return testSat15<true>(ha, rot, t, hb, x.tol, a.radius + moved.radius);
    }
    static bool contains(const Rss& s, const Vec3& p, Real tol) {
        const Vec3 local = s.axes.transpose() * (p - s.center);
        const Real dx = std::max(Real(0), std::abs(local.x()) - s.half_lengths[0]);
        const Real dy = std::max(Real(0), std::abs(local.y()) - s.half_lengths[1]);
        return std::sqrt(dx * dx + dy * dy + local.z() * local.z()) <= s.radius + tol;
    }
    static Real cost(const Rss& s) {
        // Box part + four half-cylinders along the edges + the sphere at the corners.
        const Real pi = std::numbers::pi_v<Real>;
        const Real lx = 2 * s.half_lengths[0];
        const Real ly = 2 * s.half_lengths[1];
        const Real r = s.radius;
        return lx * ly * 2 * r + (lx + ly) * pi * r * r + Real(4) / Real(3) * pi * r * r * r;
    }
};

// ---- LSS (Larsen et al. 2000): a segment along the largest principal axis swept by a sphere.
// The overlap test is the exact segment-segment distance against the sum of the radii. ----

/// Distance between the segments { ca + s ua : |s| <= ha } and { cb + t ub : |t| <= hb } (ua, ub
/// unit to rounding; ha, hb >= 0, zero for a point): RTCD 5.1.9 with centred parameters (a = e =
/// 1), so a zero-length segment needs no branch. The value is the distance of a pair of points
/// of the two segments (up to rounding), so it never undercuts the true distance by more than
/// rounding; it can exceed it where the parameters are ill-conditioned (near-parallel segments):
/// by at most segmentDistanceSlack(ha, hb, ca, cb).
inline Real distanceSegmentSegment(const Vec3& ca, const Vec3& ua, Real ha, const Vec3& cb,
                                   const Vec3& ub, Real hb) {
    const Vec3 r = ca - cb;
    const Real b = ua.dot(ub);
    const Real c = ua.dot(r);
    const Real f = ub.dot(r);
    const Real denom = Real(1) - b * b;  // sin^2 of the angle between the segments
    // Minimise |r + s ua - t ub|^2: s = (b f - c) / denom on the lines. Parallel up to rounding
    // (denom <= 16 eps): any s is a minimiser of the lines; take the centre, and the clamps below
    // find the right pair (RTCD 5.1.9's s = 0 branch).
    Real s = 0;
    if (denom > Real(16) * kEpsilon) s = std::clamp((b * f - c) / denom, -ha, ha);
    Real t = b * s + f;  // closest point of B's line to A's point s
    if (t < -hb) {
        t = -hb;
        s = std::clamp(t * b - c, -ha, ha);
    } else if (t > hb) {
        t = hb;
        s = std::clamp(t * b - c, -ha, ha);
    }
    return (r + ua * s - ub * t).norm();
}

/// How much distanceSegmentSegment can overestimate, relative to ha + hb + |ca - cb|: above the
/// parallel threshold the error of s is ~2 eps (|r| + ha) / denom and moves the distance by
/// sqrt(denom) times that, <= eps^(1/2) (|r| + ha) / 2 for denom > 16 eps; below it, treating
/// the segments as parallel costs at most ~sin(angle) (ha + hb) <= 4 eps^(1/2) (ha + hb).
/// 16 eps^(1/2) covers both with margin (2.4e-7 in double: a negligible loss of pruning).
inline const Real kSegmentDistanceSlack = Real(16) * std::sqrt(kEpsilon);
inline Real segmentDistanceSlack(Real ha, Real hb, const Vec3& ca, const Vec3& cb) {
    return kSegmentDistanceSlack * (ha + hb + (ca - cb).norm());
}

template <>
struct BvTraits<Lss> {
    static Lss fit(const std::vector<Vec3>& corners);
    /// The LSS whose segment runs along axes.col(0) (axes orthonormal).
    static Lss fitWithAxes(const std::vector<Vec3>& corners, const Mat3& axes);
    static bool overlaps(const Lss& a, const Lss& b, const BvhTransform& x) {
        return overlapsMoved(a, move(b, x), x);
    }
    /// B's volume in A's frame: computed once per B node while the traversal descends A under it.
    static Lss move(const Lss& b, const BvhTransform& x) {
        return Lss{x.apply(b.center), x.r * b.axis, b.half_length, b.radius};
    }
    /// Touching counts: distance of the segments <= r_a + r_b, the distance's possible
    /// overestimate and the transform's rounding slack added, so never a false separation.
    static bool overlapsMoved(const Lss& a, const Lss& moved, const BvhTransform& x) {
        const Real d = distanceSegmentSegment(a.center, a.axis, a.half_length, moved.center,
                                              moved.axis, moved.half_length);
        return d <=
               a.radius + moved.radius + x.tol +
                   segmentDistanceSlack(a.half_length, moved.half_length, a.center, moved.center);
    }
    /// A lower bound of the distance between the two volumes (B's moved by x): the segments'
    /// distance minus the radii and the slacks. May be negative.
    static Real distanceLowerBound(const Lss& a, const Lss& b, const BvhTransform& x) {
        const Lss moved = move(b, x);
        const Real d = distanceSegmentSegment(a.center, a.axis, a.half_length, moved.center,
                                              moved.axis, moved.half_length);
        return d - a.radius - moved.radius - x.tol -
               segmentDistanceSlack(a.half_length, moved.half_length, a.center, moved.center);
    }
    static bool contains(const Lss& s, const Vec3& p, Real tol) {
        const Vec3 d = p - s.center;
        const Real t = std::clamp(d.dot(s.axis), -s.half_length, s.half_length);
        return (d - s.axis * t).norm() <= s.radius + tol;
    }
    static Real cost(const Lss& s) {
        // Cylinder + the two half-balls at its ends.
        const Real pi = std::numbers::pi_v<Real>;
        const Real r = s.radius;
        return pi * r * r * (2 * s.half_length) + Real(4) / Real(3) * pi * r * r * r;
    }
};

/// Volume types whose fit of a point set is finish(bounds(points)), where bounds are per-direction
/// minima and maxima: the bounds of a union are merge() of the parts' bounds, equal to the bounds
/// of the whole whatever the split (min and max are exact; on a tie the left operand is kept, as
/// a scan keeps the earlier point, so only the sign of a zero bound can depend on the order). The
/// build fits leaves from their corners and every other node from its children's bounds.
template <class BV>
concept MergeableFit = requires(const typename BvTraits<BV>::Bounds& b, const Vec3* p) {
    { BvTraits<BV>::bounds(p, std::size_t{1}) } -> std::same_as<typename BvTraits<BV>::Bounds>;
    { BvTraits<BV>::merge(b, b) } -> std::same_as<typename BvTraits<BV>::Bounds>;
    { BvTraits<BV>::finish(b) } -> std::same_as<BV>;
};

/// Volume types fitted along given axes (fitWithAxes): the build takes their axes from summed
/// triangle moments, or a one-triangle leaf's own frame.
template <class BV>
inline constexpr bool kFitsWithAxes =
    std::is_same_v<BV, Obb> || std::is_same_v<BV, Rss> || std::is_same_v<BV, Lss>;

}  // namespace collision
