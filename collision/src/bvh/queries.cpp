// collision/src/bvh/queries.cpp -- the queries of two trees (first contact, every intersecting
// triangle pair, distance) and of one tree against itself (self-collision). Pair lists are
// sorted by (a, b) and free of duplicates, so any two implementations compare with ==.
#include <algorithm>
#include <limits>
#include <vector>

#include "bvh/traversal.h"
#include "collision/bvh/bvh.h"
#include "geometry/triangle_distance.h"

namespace collision {

template <class BV>
bool testBvhBvh(const Bvh<BV>& a, const Bvh<BV>& b, const Pose& b_in_a, BvhQueryStats* stats) {
    const BvhTransform x = makeBvhTransform(b_in_a, a.scale(), b.scale());
    return traverse(a, b, x, stats,
                    [](std::int32_t, std::int32_t, const std::array<Vec3, 3>&,
                       const std::array<Vec3, 3>&) { return true; });
}

template <class BV>
std::vector<TrianglePair> intersectBvhBvh(const Bvh<BV>& a, const Bvh<BV>& b, const Pose& b_in_a,
                                          BvhQueryStats* stats) {
    std::vector<TrianglePair> pairs;
    const BvhTransform x = makeBvhTransform(b_in_a, a.scale(), b.scale());
    traverse(a, b, x, stats,
             [&](std::int32_t i, std::int32_t j, const std::array<Vec3, 3>&,
                 const std::array<Vec3, 3>&) {
                 pairs.push_back({a.leafTriangleId(i), b.leafTriangleId(j)});
                 return false;
             });
    std::sort(pairs.begin(), pairs.end());  // each triangle is in one leaf: unique
    return pairs;
}

namespace {

// Every node volume seen as a box (centre, orthonormal axes, half extents) swept by a radius:
// what the distance lower bound needs. Each view contains the volume.
struct BoxView {
    Vec3 center = Vec3::Zero();
    Mat3 axes = Mat3::Identity();
    Vec3 half = Vec3::Zero();
    Real radius = 0;
};
BoxView boxView(const BoundingSphere& s) {
    return {s.center, Mat3::Identity(), Vec3::Zero(), s.radius};
}
BoxView boxView(const Aabb& b) {
    return {(b.min + b.max) * Real(0.5), Mat3::Identity(), (b.max - b.min) * Real(0.5), 0};
}
BoxView boxView(const Obb& b) { return {b.center, b.axes, b.half_extents, 0}; }
template <int K>
BoxView boxView(const Kdop<K>& d) {
    // The first three slabs are the axes: the k-DOP's bounding box.
    const Vec3 lo(d.min[0], d.min[1], d.min[2]);
    const Vec3 hi(d.max[0], d.max[1], d.max[2]);
    return {(lo + hi) * Real(0.5), Mat3::Identity(), (hi - lo) * Real(0.5), 0};
}
BoxView boxView(const Rss& s) {
    return {s.center, s.axes, Vec3(s.half_lengths[0], s.half_lengths[1], 0), s.radius};
}

// A lower bound on the distance between two volumes (B's moved by x): the largest gap of their
// projections on a unit axis (projection onto a unit axis shortens no distance) over A's axes,
// B's axes and the line of centres, minus the rounding slack x.tol. May be negative.
template <class BV>
Real projectedGapLowerBound(const BV& va, const BV& vb, const BvhTransform& x) {
    const BoxView a = boxView(va);
    BoxView b = boxView(vb);
    b.center = x.apply(b.center);
    b.axes = x.r * b.axes;
    const Vec3 d = b.center - a.center;
    auto gap = [&](const Vec3& unit) {
        return std::abs(unit.dot(d)) - (a.axes.transpose() * unit).cwiseAbs().dot(a.half) -
               (b.axes.transpose() * unit).cwiseAbs().dot(b.half) - a.radius - b.radius;
    };
    Real best = -std::numeric_limits<Real>::infinity();
    for (int i = 0; i < 3; ++i) {
        best = std::max(best, gap(a.axes.col(i)));
        best = std::max(best, gap(b.axes.col(i)));
    }
    const Real len = d.norm();
    if (len > 0) best = std::max(best, gap(d / len));
    return best - x.tol;
}

// The distance lower bound of the distance query: the volume's own when its traits give one
// (LSS: the segments' distance minus the radii), else the projected gap.
template <class BV>
Real distanceLowerBound(const BV& va, const BV& vb, const BvhTransform& x) {
    if constexpr (requires { BvTraits<BV>::distanceLowerBound(va, vb, x); }) {
        return BvTraits<BV>::distanceLowerBound(va, vb, x);
    } else {
        return projectedGapLowerBound(va, vb, x);
    }
}

}  // namespace

template <class BV>
MeshDistance distanceBvhBvh(const Bvh<BV>& a, const Bvh<BV>& b, const Pose& b_in_a,
                            BvhQueryStats* stats) {
    MeshDistance out;
    out.distance = std::numeric_limits<Real>::infinity();
    const auto& na = a.nodes();
    const auto& nb = b.nodes();
    if (na.empty() || nb.empty()) return out;
    const BvhTransform x = makeBvhTransform(b_in_a, a.scale(), b.scale());
    std::int64_t bv_tests = 1;
    std::int64_t tri_tests = 0;
    struct Item {
        std::int32_t ia;
        std::int32_t ib;
        Real bound;
    };
    std::vector<Item> stack{{0, 0, distanceLowerBound(na[0].volume, nb[0].volume, x)}};
    while (!stack.empty() && out.distance > 0) {
        const Item it = stack.back();
        stack.pop_back();
        if (it.bound > out.distance) continue;
        const auto& node_a = na[static_cast<std::size_t>(it.ia)];
        const auto& node_b = nb[static_cast<std::size_t>(it.ib)];
        if (node_a.isLeaf() && node_b.isLeaf()) {
            for (std::int32_t j = node_b.first; j < node_b.first + node_b.count; ++j) {
                const auto& tb = b.leafTriangle(j);
                const Vec3 p2 = x.apply(tb[0]);
                const Vec3 q2 = x.apply(tb[1]);
                const Vec3 r2 = x.apply(tb[2]);
                for (std::int32_t i = node_a.first; i < node_a.first + node_a.count; ++i) {
                    const auto& ta = a.leafTriangle(i);
                    ++tri_tests;
                    const TriangleDistance td =
                        distanceTriangleTriangle(ta[0], ta[1], ta[2], p2, q2, r2);
                    if (td.distance < out.distance) {
                        out.distance = td.distance;
                        out.a = a.leafTriangleId(i);
                        out.b = b.leafTriangleId(j);
                        out.point_on_a = td.point_on_1;
                        out.point_on_b = td.point_on_2;
                    }
                }
            }
            continue;
        }
        const bool descend_a = node_b.isLeaf() || (!node_a.isLeaf() && node_a.cost >= node_b.cost);
        Item first{it.ia, it.ib, 0};
        Item second{it.ia, it.ib, 0};
        if (descend_a) {
            first.ia = it.ia + 1;
            second.ia = node_a.right;
        } else {
            first.ib = it.ib + 1;
            second.ib = node_b.right;
        }
        first.bound = distanceLowerBound(na[static_cast<std::size_t>(first.ia)].volume,
                                         nb[static_cast<std::size_t>(first.ib)].volume, x);
        second.bound = distanceLowerBound(na[static_cast<std::size_t>(second.ia)].volume,
                                          nb[static_cast<std::size_t>(second.ib)].volume, x);
        bv_tests += 2;
        // The nearer pair is popped first, so the best distance shrinks early.
        if (first.bound < second.bound) std::swap(first, second);
        if (first.bound <= out.distance) stack.push_back(first);
        if (second.bound <= out.distance) stack.push_back(second);
    }
    if (stats) {
        stats->bv_tests += bv_tests;
        stats->triangle_tests += tri_tests;
    }
    return out;
}

template <class BV>
std::vector<TrianglePair> intersectSelf(const Bvh<BV>& tree, BvhQueryStats* stats) {
    std::vector<TrianglePair> pairs;
    const auto& nodes = tree.nodes();
    if (nodes.empty()) return pairs;
    // Same frame on both sides: the identity transform, and the corners as stored (the brute
    // force tests the same coordinates).
    const BvhTransform x =
        makeBvhTransform(Mat3::Identity(), Vec3::Zero(), tree.scale(), tree.scale());
    std::int64_t bv_tests = 0;
    std::int64_t tri_tests = 0;
    auto testLeafTriangles = [&](std::int32_t i, std::int32_t j) {
        if (shareVertex(tree.leafTriangleVertices(i), tree.leafTriangleVertices(j))) return;
        const auto& ta = tree.leafTriangle(i);
        const auto& tb = tree.leafTriangle(j);
        ++tri_tests;
        if (testTriangleTriangle(ta[0], ta[1], ta[2], tb[0], tb[1], tb[2])) {
            const std::int32_t a = tree.leafTriangleId(i);
            const std::int32_t b = tree.leafTriangleId(j);
            pairs.push_back({std::min(a, b), std::max(a, b)});
        }
    };
    // A pair (n, n) stands for the pairs inside subtree n: its children's inner pairs and the
    // pairs across them. Distinct subtrees are disjoint, so every triangle pair is seen once.
    std::vector<std::pair<std::int32_t, std::int32_t>> stack{{0, 0}};
    while (!stack.empty()) {
        const auto [ia, ib] = stack.back();
        stack.pop_back();
        const auto& na = nodes[static_cast<std::size_t>(ia)];
        const auto& nb = nodes[static_cast<std::size_t>(ib)];
        if (ia == ib) {
            if (na.isLeaf()) {
                for (std::int32_t i = na.first; i < na.first + na.count; ++i) {
                    for (std::int32_t j = i + 1; j < na.first + na.count; ++j) {
                        testLeafTriangles(i, j);
                    }
                }
            } else {
                stack.emplace_back(ia + 1, na.right);
                stack.emplace_back(na.right, na.right);
                stack.emplace_back(ia + 1, ia + 1);
            }
            continue;
        }
        ++bv_tests;
        if (!BvTraits<BV>::overlaps(na.volume, nb.volume, x)) continue;
        if (na.isLeaf() && nb.isLeaf()) {
            for (std::int32_t i = na.first; i < na.first + na.count; ++i) {
                for (std::int32_t j = nb.first; j < nb.first + nb.count; ++j) {
                    testLeafTriangles(i, j);
                }
            }
            continue;
        }
        pushChildrenOfLarger(stack, na, ia, nb, ib);
    }
    if (stats) {
        stats->bv_tests += bv_tests;
        stats->triangle_tests += tri_tests;
    }
    std::sort(pairs.begin(), pairs.end());
    return pairs;
}

// Explicit instantiation for every type of BvhVolumeTypes.
#define CDLAB_BVH_QUERIES(BV)                                                                  \
    template bool testBvhBvh<BV>(const Bvh<BV>&, const Bvh<BV>&, const Pose&, BvhQueryStats*); \
    template std::vector<TrianglePair> intersectBvhBvh<BV>(const Bvh<BV>&, const Bvh<BV>&,     \
                                                           const Pose&, BvhQueryStats*);       \
    template std::vector<TrianglePair> intersectSelf<BV>(const Bvh<BV>&, BvhQueryStats*);      \
    template MeshDistance distanceBvhBvh<BV>(const Bvh<BV>&, const Bvh<BV>&, const Pose&,      \
                                             BvhQueryStats*);
CDLAB_BVH_QUERIES(BoundingSphere)
CDLAB_BVH_QUERIES(Aabb)
CDLAB_BVH_QUERIES(Obb)
CDLAB_BVH_QUERIES(Kdop<6>)
CDLAB_BVH_QUERIES(Kdop<14>)
CDLAB_BVH_QUERIES(Kdop<18>)
CDLAB_BVH_QUERIES(Kdop<26>)
CDLAB_BVH_QUERIES(Rss)
CDLAB_BVH_QUERIES(Lss)
#undef CDLAB_BVH_QUERIES

}  // namespace collision
