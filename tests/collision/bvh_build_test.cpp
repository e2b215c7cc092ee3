// tests/collision/bvh_build_test.cpp -- the BVH build against a reference builder kept in this
// file: the plain top-down build that fits every node to all of its range's corners (copied out,
// before the range is partitioned) and selects the median with centroid look-ups. The library
// finishes box-like nodes from their children's bounds and projects OBB corners in place; the
// trees must be the same bit for bit: nodes, volumes, costs, leaf order, corners, depth.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "collision/bvh/bvh.h"
#include "test_meshes.h"
#include "test_random.h"
#include "volumes/bvh_volumes.h"
#include "volumes/fit_slack.h"

namespace {

using collision::Aabb;
using collision::BoundingSphere;
using collision::Bvh;
using collision::BvhBuild;
using collision::BvhBuildOptions;
using collision::BvhSplit;
using collision::BvTraits;
using collision::Kdop;
using collision::Lss;
using collision::Mat3;
using collision::Obb;
using collision::Real;
using collision::Rss;
using collision::TriangleMesh;
using collision::TriangleMoments;
using collision::Vec3;

// ---- Reference fits: one pass over all the points of the node. ----

Real refMagnitude(const std::vector<Vec3>& pts) {
    Vec3 lo = pts[0];
    Vec3 hi = pts[0];
    for (const Vec3& p : pts) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    return (hi - lo).maxCoeff() + std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
}

Aabb refFit(const std::vector<Vec3>& corners, Aabb*) {
    Aabb box{corners[0], corners[0]};
    for (const Vec3& p : corners) {
        box.min = box.min.cwiseMin(p);
        box.max = box.max.cwiseMax(p);
    }
    return box;
}

template <int K>
Kdop<K> refFit(const std::vector<Vec3>& corners, Kdop<K>*) {
    Kdop<K> d;
    d.min.fill(std::numeric_limits<Real>::infinity());
    d.max.fill(-std::numeric_limits<Real>::infinity());
    for (const Vec3& p : corners) {
        for (int i = 0; i < Kdop<K>::kSlabs; ++i) {
            const Real s = collision::kdopDirection(collision::kdopDirectionIndex<K>(i)).dot(p);
            d.min[i] = std::min(d.min[i], s);
            d.max[i] = std::max(d.max[i], s);
        }
    }
    const Real slack = Real(3) * collision::kFitSlack * refMagnitude(corners);
    for (int i = 3; i < Kdop<K>::kSlabs; ++i) {
        d.min[i] -= slack;
        d.max[i] += slack;
    }
    return d;
}

Obb refFitWithAxes(const std::vector<Vec3>& corners, const Mat3& axes, Obb*) {
    const Vec3 origin = corners[0];
    Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::max());
    Vec3 hi = Vec3::Constant(std::numeric_limits<Real>::lowest());
    for (const Vec3& p : corners) {
        const Vec3 proj = axes.transpose() * (p - origin);
        lo = lo.cwiseMin(proj);
        hi = hi.cwiseMax(proj);
    }
    Obb box;
    box.axes = axes;
    box.center = origin + axes * ((lo + hi) * Real(0.5));
    box.half_extents =
        (hi - lo) * Real(0.5) + Vec3::Constant(collision::kFitSlack * refMagnitude(corners));
    return box;
}
template <class BV>
BV refFitWithAxes(const std::vector<Vec3>& corners, const Mat3& axes, BV*) {
    return BvTraits<BV>::fitWithAxes(corners, axes);  // RSS, LSS: the library's point-set fit
}
BoundingSphere refFit(const std::vector<Vec3>& corners, BoundingSphere*) {
    return BvTraits<BoundingSphere>::fit(corners);
}

// A node's volume as the plain build fits it: oriented volumes along the summed moments' axes
// (a one-triangle leaf: its own frame), the others over the points.
template <class BV>
BV refFitNode(const std::vector<Vec3>& pts, const std::vector<TriangleMoments>& moments,
              const std::vector<std::int32_t>& ids, std::int32_t first, std::int32_t count) {
    if constexpr (collision::kFitsWithAxes<BV>) {
        Mat3 axes;
        if (count == 1 && collision::triangleAxes(pts[0], pts[1], pts[2], &axes)) {
            return refFitWithAxes(pts, axes, static_cast<BV*>(nullptr));
        }
        TriangleMoments sum;
        for (std::int32_t i = first; i < first + count; ++i) {
            sum.add(moments[static_cast<std::size_t>(ids[static_cast<std::size_t>(i)])]);
        }
        if (!collision::momentAxes(sum, &axes)) axes = collision::principalAxes(pts);
        return refFitWithAxes(pts, axes, static_cast<BV*>(nullptr));
    } else {
        return refFit(pts, static_cast<BV*>(nullptr));
    }
}

template <class BV>
struct RefTree {
    std::vector<typename Bvh<BV>::Node> nodes;
    std::vector<std::int32_t> ids;
    int depth = 0;
};

// The plain top-down build: every node fitted to a copy of its range's corners, in the order
// the range has before its partition; median selection comparing looked-up centroids.
template <class BV>
struct RefBuilder {
    const TriangleMesh& mesh;
    BvhBuildOptions options;
    RefTree<BV> tree;
    std::vector<std::array<Vec3, 3>> corners;
    std::vector<Vec3> centroids;
    std::vector<TriangleMoments> moments;

    RefBuilder(const TriangleMesh& m, const BvhBuildOptions& o) : mesh(m), options(o) {
        const std::size_t n = mesh.triangles.size();
        Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
        Vec3 hi = -lo;
        for (std::size_t i = 0; i < n; ++i) {
            std::array<Vec3, 3> c;
            for (std::size_t k = 0; k < 3; ++k) {
                c[k] = mesh.vertices[static_cast<std::size_t>(mesh.triangles[i][k])];
                lo = lo.cwiseMin(c[k]);
                hi = hi.cwiseMax(c[k]);
            }
            corners.push_back(c);
            centroids.push_back((c[0] + c[1] + c[2]) / Real(3));
            tree.ids.push_back(static_cast<std::int32_t>(i));
        }
        const Vec3 origin = (lo + hi) * Real(0.5);
        for (const auto& c : corners) {
            moments.push_back(collision::triangleMoments(c[0], c[1], c[2], origin));
        }
        build(0, static_cast<std::int32_t>(n), 1);
    }

    std::int32_t build(std::int32_t first, std::int32_t count, int level) {
        tree.depth = std::max(tree.depth, level);
        const auto index = static_cast<std::int32_t>(tree.nodes.size());
        tree.nodes.emplace_back();
        std::vector<Vec3> pts;
        for (std::int32_t i = first; i < first + count; ++i) {
            for (const Vec3& p : corners[static_cast<std::size_t>(tree.ids[i])]) pts.push_back(p);
        }
        auto& node = tree.nodes.back();
        node.volume = refFitNode<BV>(pts, moments, tree.ids, first, count);
        node.cost = BvTraits<BV>::cost(node.volume);
        if (count <= options.max_leaf_triangles) {
            node.first = first;
            node.count = count;
            return index;
        }
        const std::int32_t split = partition(first, count);
        build(first, split - first, level + 1);
        const std::int32_t right = build(split, first + count - split, level + 1);
        tree.nodes[static_cast<std::size_t>(index)].right = right;
        return index;
    }

    std::int32_t partition(std::int32_t first, std::int32_t count) {
        const auto begin = tree.ids.begin() + first;
        const auto end = begin + count;
        auto c = [&](std::int32_t id) -> const Vec3& { return centroids[std::size_t(id)]; };
        Vec3 lo = c(*begin);
        Vec3 hi = lo;
        Vec3 sum = Vec3::Zero();
        for (auto it = begin; it != end; ++it) {
            lo = lo.cwiseMin(c(*it));
            hi = hi.cwiseMax(c(*it));
            sum += c(*it);
        }
        int axis = 0;
        (hi - lo).maxCoeff(&axis);
        auto key = [&](std::int32_t id) { return c(id)[axis]; };
        if (options.split == BvhSplit::Mean) {
            const Real mean = sum[axis] / Real(count);
            const auto it =
                std::partition(begin, end, [&](std::int32_t id) { return key(id) < mean; });
            const auto left = static_cast<std::int32_t>(it - begin);
            if (left > 0 && left < count) return first + left;
        }
        const std::int32_t mid = count / 2;
        std::nth_element(begin, begin + mid, end, [&](std::int32_t i, std::int32_t j) {
            return key(i) < key(j) || (key(i) == key(j) && i < j);
        });
        return first + mid;
    }
};

// The bottom-up build's splits are the library's; its nodes are refitted here over their
// leaf-order ranges (that build fits every range in leaf order: nothing is partitioned).
template <class BV>
RefTree<BV> refitOverRanges(const Bvh<BV>& built, const TriangleMesh& mesh) {
    RefTree<BV> tree;
    tree.depth = built.depth();
    const std::size_t n = mesh.triangles.size();
    for (std::int32_t i = 0; i < built.triangleCount(); ++i) {
        tree.ids.push_back(built.leafTriangleId(i));
    }
    Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
    Vec3 hi = -lo;
    for (const Vec3& v : mesh.vertices) {
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
    }
    std::vector<TriangleMoments> moments;
    for (std::size_t i = 0; i < n; ++i) {
        const auto& t = mesh.triangles[i];
        moments.push_back(collision::triangleMoments(
            mesh.vertices[std::size_t(t[0])], mesh.vertices[std::size_t(t[1])],
            mesh.vertices[std::size_t(t[2])], (lo + hi) * Real(0.5)));
    }
    // Each node's range: its leaves' union (children follow their parent in depth-first order).
    const auto& nodes = built.nodes();
    std::vector<std::int32_t> first(nodes.size());
    std::vector<std::int32_t> last(nodes.size());
    for (std::size_t k = nodes.size(); k-- > 0;) {
        first[k] = nodes[k].isLeaf() ? nodes[k].first : first[k + 1];
        last[k] =
            nodes[k].isLeaf() ? nodes[k].first + nodes[k].count : last[std::size_t(nodes[k].right)];
    }
    for (std::size_t k = 0; k < nodes.size(); ++k) {
        std::vector<Vec3> pts;
        for (std::int32_t i = first[k]; i < last[k]; ++i) {
            for (const Vec3& p : built.leafTriangle(i)) pts.push_back(p);
        }
        auto node = nodes[k];
        node.volume = refFitNode<BV>(pts, moments, tree.ids, first[k], last[k] - first[k]);
        node.cost = BvTraits<BV>::cost(node.volume);
        tree.nodes.push_back(node);
    }
    return tree;
}

// The bytes of a value with every -0.0 made +0.0: the bottom-up fit of min/max keeps the earlier
// of two equal bounds, and -0.0 == +0.0, so the sign of a zero bound may follow the point order.
template <class T>
std::vector<unsigned char> canonicalBytes(const T& value) {
    static_assert(sizeof(T) % sizeof(Real) == 0);
    std::array<Real, sizeof(T) / sizeof(Real)> reals;
    std::memcpy(reals.data(), &value, sizeof(T));
    for (Real& r : reals) r += Real(0);  // -0 + 0 = +0; every other value unchanged
    std::vector<unsigned char> out(sizeof(T));
    std::memcpy(out.data(), reals.data(), sizeof(T));
    return out;
}

template <class BV>
void expectSameTree(const Bvh<BV>& built, const RefTree<BV>& ref, const TriangleMesh& mesh,
                    const std::string& what) {
    ASSERT_EQ(built.nodes().size(), ref.nodes.size()) << what;
    EXPECT_EQ(built.depth(), ref.depth) << what;
    for (std::size_t k = 0; k < ref.nodes.size(); ++k) {
        const auto& a = built.nodes()[k];
        const auto& b = ref.nodes[k];
        ASSERT_EQ(a.right, b.right) << what << " node " << k;
        ASSERT_EQ(a.first, b.first) << what << " node " << k;
        ASSERT_EQ(a.count, b.count) << what << " node " << k;
        ASSERT_EQ(canonicalBytes(a.volume), canonicalBytes(b.volume)) << what << " node " << k;
        ASSERT_EQ(canonicalBytes(a.cost), canonicalBytes(b.cost)) << what << " node " << k;
    }
    for (std::int32_t i = 0; i < built.triangleCount(); ++i) {
        const std::int32_t id = ref.ids[static_cast<std::size_t>(i)];
        ASSERT_EQ(built.leafTriangleId(i), id) << what << " leaf position " << i;
        for (std::size_t c = 0; c < 3; ++c) {
            const Vec3& v = mesh.vertices[std::size_t(mesh.triangles[std::size_t(id)][c])];
            ASSERT_EQ(canonicalBytes(built.leafTriangle(i)[c]), canonicalBytes(v)) << what;
        }
    }
}

// ---- Meshes: random soup, degenerate triangles, far from the origin, tiny and huge. ----

TriangleMesh randomSoup(std::uint64_t seed, int n, Real scale, const Vec3& offset) {
    cdlab_test::Rng rng(seed);
    TriangleMesh m;
    for (int i = 0; i < n; ++i) {
        const Vec3 c = offset + rng.vec(-scale, scale);
        for (int k = 0; k < 3; ++k) {
            m.vertices.push_back(c + rng.vec(-Real(0.05) * scale, Real(0.05) * scale));
        }
        m.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    }
    return m;
}

// Zero-area triangles (a point, a segment), exact duplicates (equal centroids: the median's
// ties), slivers, coplanar triangles on a grid with exact zero coordinates of both signs.
TriangleMesh degenerate() {
    TriangleMesh m;
    auto add = [&](const Vec3& a, const Vec3& b, const Vec3& c) {
        const auto base = static_cast<std::int32_t>(m.vertices.size());
        m.vertices.insert(m.vertices.end(), {a, b, c});
        m.triangles.push_back({base, base + 1, base + 2});
    };
    for (int i = 0; i < 6; ++i) {
        const Real x = Real(i);
        add(Vec3(x, 0, 0), Vec3(x, 0, 0), Vec3(x, 0, 0));          // a point
        add(Vec3(x, 1, 0), Vec3(x + 1, 1, 0), Vec3(x + 2, 1, 0));  // a segment
        add(Vec3(x, 2, 0), Vec3(x + 1, 2, 0), Vec3(x, 3, 0));      // twice the same
        add(Vec3(x, 2, 0), Vec3(x + 1, 2, 0), Vec3(x, 3, 0));
        add(Vec3(x, 4, 0), Vec3(x + 1, 4, 1e-17), Vec3(x + 2, 4, 0));       // a sliver
        add(Vec3(-0.0, x, -0.0), Vec3(0.0, x + 1, 0.0), Vec3(-0.0, x, 1));  // x = +-0
    }
    return m;
}

TriangleMesh allZeroArea() {
    TriangleMesh m;
    for (int i = 0; i < 20; ++i) {
        const Real t = Real(i) * Real(0.37);
        m.vertices.insert(m.vertices.end(), {Vec3(t, 2 * t, -t), Vec3(t + 1, 2 * t + 2, -t - 1),
                                             Vec3(t + 3, 2 * t + 6, -t - 3)});
        m.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    }
    return m;
}

struct NamedMesh {
    std::string name;
    TriangleMesh mesh;
};

std::vector<NamedMesh> meshes() {
    return {
        {"random", randomSoup(11, 300, 1, Vec3::Zero())},
        {"far", randomSoup(12, 200, 1, Vec3(1e6, -2e6, 3e6))},
        {"tiny", randomSoup(13, 200, Real(1e-4), Vec3::Zero())},
        {"huge", randomSoup(14, 200, Real(1e4), Vec3(-5e3, 0, 0))},
        {"degenerate", degenerate()},
        {"zero-area", allZeroArea()},
        {"torus", cdlab_test::makeTorusMesh(1.0, 0.4, 24, 10)},
        {"one", randomSoup(15, 1, 1, Vec3::Zero())},
    };
}

std::vector<std::pair<std::string, BvhBuildOptions>> topDownOptions() {
    BvhBuildOptions median;
    BvhBuildOptions mean;
    mean.split = BvhSplit::Mean;
    BvhBuildOptions wide_leaves;
    wide_leaves.max_leaf_triangles = 4;
    BvhBuildOptions mean_leaves = mean;
    mean_leaves.max_leaf_triangles = 3;
    return {{"median", median}, {"mean", mean}, {"leaves4", wide_leaves}, {"mean3", mean_leaves}};
}

template <class BV>
class BvhBuildSameAsReference : public ::testing::Test {};

using BuildVolumes =
    ::testing::Types<Aabb, Kdop<6>, Kdop<14>, Kdop<18>, Kdop<26>, Obb, Rss, Lss, BoundingSphere>;
TYPED_TEST_SUITE(BvhBuildSameAsReference, BuildVolumes);

TYPED_TEST(BvhBuildSameAsReference, TopDownNodesBitForBit) {
    for (const auto& [mesh_name, mesh] : meshes()) {
        for (const auto& [option_name, options] : topDownOptions()) {
            const Bvh<TypeParam> built(mesh, options);
            const RefBuilder<TypeParam> ref(mesh, options);
            expectSameTree(built, ref.tree, mesh, mesh_name + " " + option_name);
        }
    }
}

TYPED_TEST(BvhBuildSameAsReference, BottomUpNodesBitForBit) {
    BvhBuildOptions options;
    options.build = BvhBuild::BottomUp;
    for (const auto& [mesh_name, mesh] : meshes()) {
        const Bvh<TypeParam> built(mesh, options);
        expectSameTree(built, refitOverRanges(built, mesh), mesh, mesh_name + " bottom-up");
    }
}

// A refit fits every node to its range's corners in leaf order (the moved mesh's); box-like
// volumes merge their children's bounds instead.
TYPED_TEST(BvhBuildSameAsReference, RefitNodesBitForBit) {
    if constexpr (collision::MergeableFit<TypeParam>) {
        for (const auto& [mesh_name, mesh] : meshes()) {
            for (const auto& [option_name, options] : topDownOptions()) {
                TriangleMesh moved = mesh;
                for (Vec3& v : moved.vertices) {
                    v = Vec3(v.x() + Real(0.3) * std::sin(Real(3) * v.y()), -v.z() * Real(1.5),
                             v.y() + Real(0.25) * v.x());
                }
                Bvh<TypeParam> refitted(mesh, options);
                refitted.refit(moved);
                RefTree<TypeParam> ref;
                ref.depth = refitted.depth();
                const auto& nodes = refitted.nodes();
                std::vector<std::int32_t> first(nodes.size());
                std::vector<std::int32_t> last(nodes.size());
                for (std::size_t k = nodes.size(); k-- > 0;) {
                    first[k] = nodes[k].isLeaf() ? nodes[k].first : first[k + 1];
                    last[k] = nodes[k].isLeaf() ? nodes[k].first + nodes[k].count
                                                : last[std::size_t(nodes[k].right)];
                }
                for (std::int32_t i = 0; i < refitted.triangleCount(); ++i) {
                    ref.ids.push_back(refitted.leafTriangleId(i));
                }
                for (std::size_t k = 0; k < nodes.size(); ++k) {
                    std::vector<Vec3> pts;
                    for (std::int32_t i = first[k]; i < last[k]; ++i) {
                        for (const Vec3& p : refitted.leafTriangle(i)) pts.push_back(p);
                    }
                    auto node = nodes[k];
                    node.volume = refFit(pts, static_cast<TypeParam*>(nullptr));
                    node.cost = BvTraits<TypeParam>::cost(node.volume);
                    ref.nodes.push_back(node);
                }
                expectSameTree(refitted, ref, moved, mesh_name + " " + option_name + " refit");
            }
        }
    }
}

}  // namespace
