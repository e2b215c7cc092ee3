// collision/src/bvh/build.cpp -- building a Bvh<BV> (top-down splits, or bottom-up merging in
// Morton order), refitting it to a deformed mesh, and validating it.
// Invariants: nodes are in depth-first order (left child = parent + 1), each leaf owns a
// contiguous range of the leaf-ordered triangles and the leaves partition them.
#include <algorithm>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>
#include <sstream>
#include <type_traits>
#include <unordered_map>

#include "collision/assert.h"
#include "collision/bvh/bvh.h"
#include "volumes/bvh_volumes.h"
#include "volumes/fit_slack.h"

namespace collision {

namespace {

// Relative tolerance of validate()'s containment check (the fits add 16-48 ulps).
constexpr Real kValidateSlack = Real(1024) * kEpsilon;

// What a subtree's build hands its parent: the bounds its volume is finished from (mergeable
// fits), else the box of its corners (the magnitude of an OBB's slack).
template <class BV>
struct BuildCarry {
    using type = Aabb;
};
template <MergeableFit BV>
struct BuildCarry<BV> {
    using type = typename BvTraits<BV>::Bounds;
};

template <class BV>
struct Builder {
    const BvhBuildOptions& options;
    std::vector<typename Bvh<BV>::Node>& nodes;
    const std::vector<std::array<Vec3, 3>>& corners;  // by mesh triangle index
    const std::vector<Vec3>& centroids;               // by mesh triangle index
    std::vector<std::int32_t>& ids;                   // leaf order -> mesh index, permuted here
    const std::vector<TriangleMoments>& moments;      // by mesh triangle index (oriented BVs)
    // Bottom-up builds: the split of each cluster's range (key first * (n + 1) + count), found
    // by bottomUpSplits; null for top-down.
    const std::unordered_map<std::int64_t, std::int32_t>* splits = nullptr;
    std::vector<Vec3> scratch;  // reused: no allocation per node
    struct KeyedId {
        Real key;
        std::int32_t id;
    };
    std::vector<KeyedId> keyed;  // partition's median selection, reused
    int depth = 0;               // longest root-to-leaf path so far (a lone leaf: 1)

    using Carry = typename BuildCarry<BV>::type;

    const std::array<Vec3, 3>& triangle(std::int32_t i) const {
        return corners[static_cast<std::size_t>(ids[static_cast<std::size_t>(i)])];
    }

    // Builds the subtree over leaf-order range [first, first + count) whose root is at `level`
    // (the root: 1); returns its node index and sets `carry` for the parent. Mergeable volumes
    // are fitted bottom-up: a leaf from its corners, any other node from its children's bounds,
    // so each corner is visited once. Other volumes are fitted to the range before it is
    // partitioned (an OBB's axes, origin and projections depend on that order).
    std::int32_t build(std::int32_t first, std::int32_t count, int level, Carry& carry) {
        depth = std::max(depth, level);
        const auto index = static_cast<std::int32_t>(nodes.size());
        nodes.emplace_back();
        if constexpr (std::is_same_v<BV, Obb>) {
            nodes[static_cast<std::size_t>(index)].volume = obbBeforeSlack(first, count);
        } else if constexpr (!MergeableFit<BV>) {
            fillScratch(first, count);
            auto& node = nodes[static_cast<std::size_t>(index)];
            node.volume = fitNode(first, count);
            node.cost = BvTraits<BV>::cost(node.volume);
        }
        if (count <= options.max_leaf_triangles) {
            auto& node = nodes[static_cast<std::size_t>(index)];
            node.first = first;
            node.count = count;
            if constexpr (MergeableFit<BV> || std::is_same_v<BV, Obb>) {
                using Traits = std::conditional_t<MergeableFit<BV>, BvTraits<BV>, BvTraits<Aabb>>;
                carry = Traits::bounds(triangle(first).data(), 3);
                for (std::int32_t i = first + 1; i < first + count; ++i) {
                    carry = Traits::merge(carry, Traits::bounds(triangle(i).data(), 3));
                }
                finishNode(node, carry);
            }
            return index;
        }
        const std::int32_t split = splits
                                       ? splits->at(static_cast<std::int64_t>(first) *
                                                        static_cast<std::int64_t>(ids.size() + 1) +
                                                    count)
                                       : partition(first, count);
        Carry left;
        Carry right;
        build(first, split - first, level + 1, left);
        const std::int32_t right_index = build(split, first + count - split, level + 1, right);
        auto& node = nodes[static_cast<std::size_t>(index)];
        node.right = right_index;
        if constexpr (MergeableFit<BV>) {
            carry = BvTraits<BV>::merge(left, right);
            finishNode(node, carry);
        } else if constexpr (std::is_same_v<BV, Obb>) {
            carry = BvTraits<Aabb>::merge(left, right);
            finishNode(node, carry);
        }
        return index;
    }

    void finishNode(typename Bvh<BV>::Node& node, const Carry& carry) {
        if constexpr (MergeableFit<BV>) {
            node.volume = BvTraits<BV>::finish(carry);
        } else if constexpr (std::is_same_v<BV, Obb>) {
            BvTraits<Obb>::widen(node.volume, carry);
        }
        node.cost = BvTraits<BV>::cost(node.volume);
    }

    // The corners of leaf-order range [first, first + count), in order, into `scratch`.
    void fillScratch(std::int32_t first, std::int32_t count) {
        scratch.clear();
        for (std::int32_t i = first; i < first + count; ++i) {
            for (const Vec3& p : triangle(i)) scratch.push_back(p);
        }
    }

    // fitNode for an OBB, read from the corners in place, without the slack (it needs the box
    // of the corners, which the children hand up): the same axes, origin and projections.
    Obb obbBeforeSlack(std::int32_t first, std::int32_t count) {
        const std::array<Vec3, 3>& t0 = triangle(first);
        Mat3 axes;
        if (count != 1 || !triangleAxes(t0[0], t0[1], t0[2], &axes)) {
            TriangleMoments sum;
            for (std::int32_t i = first; i < first + count; ++i) {
                sum.add(moments[static_cast<std::size_t>(ids[static_cast<std::size_t>(i)])]);
            }
            if (!momentAxes(sum, &axes)) {
                fillScratch(first, count);
                axes = principalAxes(scratch);
            }
        }
        Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::max());
        Vec3 hi = Vec3::Constant(std::numeric_limits<Real>::lowest());
        for (std::int32_t i = first; i < first + count; ++i) {
            for (const Vec3& p : triangle(i)) extendProjectionRange(axes, p, t0[0], lo, hi);
        }
        return BvTraits<Obb>::boxOfRange(axes, t0[0], lo, hi);
    }

    // The node volume over `scratch` (the corners of leaf-order range [first, first + count)).
    // Oriented volumes take their axes from per-triangle moments summed over the range (one
    // pass of additions instead of the covariance from corners), and a one-triangle leaf the
    // triangle's own frame (a flat, tight box); the extents are measured from the corners either
    // way, so every volume contains its triangles whatever the axes.
    BV fitNode(std::int32_t first, std::int32_t count) {
        if constexpr (kFitsWithAxes<BV>) {
            Mat3 axes;
            if (count == 1 && triangleAxes(scratch[0], scratch[1], scratch[2], &axes)) {
                return BvTraits<BV>::fitWithAxes(scratch, axes);
            }
            TriangleMoments sum;
            for (std::int32_t i = first; i < first + count; ++i) {
                sum.add(moments[static_cast<std::size_t>(ids[static_cast<std::size_t>(i)])]);
            }
            if (!momentAxes(sum, &axes)) axes = principalAxes(scratch);
            return BvTraits<BV>::fitWithAxes(scratch, axes);
        } else {
            (void)first;
            (void)count;
            return BvTraits<BV>::fit(scratch);
        }
    }

    // Splits along the longest axis of the centroids' bounding box; returns the first index of
    // the right half (strictly inside the range).
    std::int32_t partition(std::int32_t first, std::int32_t count) {
        const auto begin = ids.begin() + first;
        const auto end = begin + count;
        auto centroid = [&](std::int32_t id) -> const Vec3& {
            return centroids[static_cast<std::size_t>(id)];
        };
        Vec3 lo = centroid(*begin);
        Vec3 hi = lo;
        Vec3 sum = Vec3::Zero();
        for (auto it = begin; it != end; ++it) {
            lo = lo.cwiseMin(centroid(*it));
            hi = hi.cwiseMax(centroid(*it));
            sum += centroid(*it);
        }
        int axis = 0;
        (hi - lo).maxCoeff(&axis);
        auto key = [&](std::int32_t id) { return centroid(id)[axis]; };
        if (options.split == BvhSplit::Mean) {
            const Real mean = sum[axis] / Real(count);
            const auto it =
                std::partition(begin, end, [&](std::int32_t id) { return key(id) < mean; });
            const auto left = static_cast<std::int32_t>(it - begin);
            if (left > 0 && left < count) return first + left;
        }
        // Median; ties broken by triangle index so the build is deterministic. The selection
        // runs on (key, id) copies, read once, instead of looking the centroid up at every
        // comparison: the comparisons answer the same, so the ids end in the same order.
        const std::int32_t mid = count / 2;
        keyed.clear();
        for (auto it = begin; it != end; ++it) keyed.push_back({key(*it), *it});
        std::nth_element(keyed.begin(), keyed.begin() + mid, keyed.end(),
                         [](const KeyedId& i, const KeyedId& j) {
                             return i.key < j.key || (i.key == j.key && i.id < j.id);
                         });
        for (std::int32_t k = 0; k < count; ++k) {
            begin[k] = keyed[static_cast<std::size_t>(k)].id;
        }
        return first + mid;
    }
};

// Spreads the low 10 bits of v to every third bit (Morton code, RTCD 7.3.5).
std::uint32_t spreadBits(std::uint32_t v) {
    v &= 0x3ffu;
    v = (v | (v << 16)) & 0x030000ffu;
    v = (v | (v << 8)) & 0x0300f00fu;
    v = (v | (v << 4)) & 0x030c30c3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

// The bottom-up build's clustering. Puts `ids` in Morton order of the centroids (ties by
// triangle index: deterministic), then merges neighbouring clusters of that order greedily, the
// pair with the smallest merged AABB surface area first (ties: the leftmost), until one is left.
// Clusters are contiguous ranges of the order, so the result is a split per internal range.
std::unordered_map<std::int64_t, std::int32_t> bottomUpSplits(
    const std::vector<std::array<Vec3, 3>>& corners, const std::vector<Vec3>& centroids,
    std::vector<std::int32_t>& ids) {
    const std::size_t n = ids.size();
    Vec3 lo = centroids[0];
    Vec3 hi = centroids[0];
    for (const Vec3& c : centroids) {
        lo = lo.cwiseMin(c);
        hi = hi.cwiseMax(c);
    }
    const Vec3 extent = (hi - lo).cwiseMax(Vec3::Constant(std::numeric_limits<Real>::min()));
    std::vector<std::uint32_t> code(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 u = ((centroids[i] - lo).array() / extent.array()) * Real(1023);
        code[i] = spreadBits(static_cast<std::uint32_t>(u.x())) |
                  (spreadBits(static_cast<std::uint32_t>(u.y())) << 1) |
                  (spreadBits(static_cast<std::uint32_t>(u.z())) << 2);
    }
    std::sort(ids.begin(), ids.end(), [&](std::int32_t a, std::int32_t b) {
        const auto ca = code[static_cast<std::size_t>(a)];
        const auto cb = code[static_cast<std::size_t>(b)];
        return ca < cb || (ca == cb && a < b);
    });
    struct Cluster {
        std::int32_t first;
        std::int32_t count;
        Vec3 lo;
        Vec3 hi;
        std::int32_t prev;
        std::int32_t next;
        bool alive;
    };
    std::vector<Cluster> clusters;
    clusters.reserve(2 * n);
    for (std::size_t k = 0; k < n; ++k) {
        const auto& t = corners[static_cast<std::size_t>(ids[k])];
        clusters.push_back({static_cast<std::int32_t>(k), 1, t[0].cwiseMin(t[1]).cwiseMin(t[2]),
                            t[0].cwiseMax(t[1]).cwiseMax(t[2]), static_cast<std::int32_t>(k) - 1,
                            k + 1 < n ? static_cast<std::int32_t>(k + 1) : -1, true});
    }
    auto area = [](const Vec3& l, const Vec3& h) {
        const Vec3 e = h - l;
        return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
    };
    struct Candidate {
        Real cost;
        std::int32_t first;  // leftmost triangle: the tie-break
        std::int32_t left;
        std::int32_t right;
        bool operator>(const Candidate& o) const {
            return cost > o.cost || (cost == o.cost && first > o.first);
        }
    };
    std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> queue;
    auto push = [&](std::int32_t l, std::int32_t r) {
        if (l < 0 || r < 0) return;
        const Cluster& a = clusters[static_cast<std::size_t>(l)];
        const Cluster& b = clusters[static_cast<std::size_t>(r)];
        queue.push({area(a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi)), a.first, l, r});
    };
    for (std::size_t k = 0; k + 1 < n; ++k) {
        push(static_cast<std::int32_t>(k), static_cast<std::int32_t>(k + 1));
    }
    std::unordered_map<std::int64_t, std::int32_t> splits;
    splits.reserve(n);
    const auto key_base = static_cast<std::int64_t>(n + 1);
    while (!queue.empty()) {
        const Candidate c = queue.top();
        queue.pop();
        Cluster& a = clusters[static_cast<std::size_t>(c.left)];
        Cluster& b = clusters[static_cast<std::size_t>(c.right)];
        if (!a.alive || !b.alive || a.next != c.right) continue;  // stale entry
        a.alive = false;
        b.alive = false;
        const auto id = static_cast<std::int32_t>(clusters.size());
        const Cluster merged{
            a.first, a.count + b.count, a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi), a.prev, b.next,
            true};
        splits[static_cast<std::int64_t>(merged.first) * key_base + merged.count] = b.first;
        if (merged.prev >= 0) clusters[static_cast<std::size_t>(merged.prev)].next = id;
        if (merged.next >= 0) clusters[static_cast<std::size_t>(merged.next)].prev = id;
        clusters.push_back(merged);
        push(merged.prev, id);
        push(id, merged.next);
    }
    return splits;
}

}  // namespace

template <class BV>
Bvh<BV>::Bvh(const TriangleMesh& mesh, const BvhBuildOptions& options) {
    CDLAB_ASSERT(options.max_leaf_triangles >= 1, "leaves need at least one triangle");
    const std::size_t n = mesh.triangles.size();
    if (n == 0) return;
    corners_.resize(n);
    ids_.resize(n);
    vertex_ids_.resize(n);
    std::vector<Vec3> centroids(n);
    Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
    Vec3 hi = -lo;
    for (std::size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
            const auto v = mesh.triangles[i][static_cast<std::size_t>(k)];
            CDLAB_ASSERT(v >= 0 && static_cast<std::size_t>(v) < mesh.vertices.size(),
                         "triangle index out of range");
            corners_[i][static_cast<std::size_t>(k)] = mesh.vertices[static_cast<std::size_t>(v)];
            lo = lo.cwiseMin(corners_[i][static_cast<std::size_t>(k)]);
            hi = hi.cwiseMax(corners_[i][static_cast<std::size_t>(k)]);
        }
        ids_[i] = static_cast<std::int32_t>(i);
        centroids[i] = (corners_[i][0] + corners_[i][1] + corners_[i][2]) / Real(3);
    }
    scale_ = (hi - lo).maxCoeff() + std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
    BvhBuildOptions opts = options;
    opts.max_leaf_triangles = std::max(1, opts.max_leaf_triangles);
    nodes_.reserve(2 * n);
    std::vector<TriangleMoments> moments;
    if constexpr (kFitsWithAxes<BV>) {
        // About the centre of the mesh's box, so the sums stay small far from the origin.
        const Vec3 origin = (lo + hi) * Real(0.5);
        moments.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            moments[i] = triangleMoments(corners_[i][0], corners_[i][1], corners_[i][2], origin);
        }
    }
    std::unordered_map<std::int64_t, std::int32_t> splits;
    if (opts.build == BvhBuild::BottomUp) splits = bottomUpSplits(corners_, centroids, ids_);
    Builder<BV> builder{opts,
                        nodes_,
                        corners_,
                        centroids,
                        ids_,
                        moments,
                        opts.build == BvhBuild::BottomUp ? &splits : nullptr,
                        {},
                        {}};
    if constexpr (!MergeableFit<BV> && !std::is_same_v<BV, Obb>) {
        builder.scratch.reserve(3 * n);  // the root's corners: no regrowth during the build
    }
    builder.keyed.reserve(n);
    typename Builder<BV>::Carry root_carry;
    builder.build(0, static_cast<std::int32_t>(n), 1, root_carry);
    // Corners into leaf order, so a leaf's triangles are contiguous in memory.
    std::vector<std::array<Vec3, 3>> by_mesh = std::move(corners_);
    corners_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
        corners_[k] = by_mesh[static_cast<std::size_t>(ids_[k])];
        vertex_ids_[k] = mesh.triangles[static_cast<std::size_t>(ids_[k])];
    }
    depth_ = builder.depth;
}

template <class BV>
std::int32_t Bvh<BV>::refit(const TriangleMesh& mesh) {
    CDLAB_ASSERT(mesh.triangles.size() == ids_.size(), "refit with another mesh");
    if (mesh.triangles.size() != ids_.size() || nodes_.empty()) return 0;
    Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity());
    Vec3 hi = -lo;
    for (std::size_t k = 0; k < ids_.size(); ++k) {
        const auto& tri = mesh.triangles[static_cast<std::size_t>(ids_[k])];
        for (std::size_t c = 0; c < 3; ++c) {
            CDLAB_ASSERT(tri[c] >= 0 && static_cast<std::size_t>(tri[c]) < mesh.vertices.size(),
                         "triangle index out of range");
            corners_[k][c] = mesh.vertices[static_cast<std::size_t>(tri[c])];
            lo = lo.cwiseMin(corners_[k][c]);
            hi = hi.cwiseMax(corners_[k][c]);
        }
    }
    scale_ = (hi - lo).maxCoeff() + std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
    // Children come after their parent in depth-first order, so a reverse sweep sees both
    // children of a node before the node: mergeable volumes merge their children's bounds (the
    // bounds of all the node's corners, as a fit over them gives), the others are fitted to
    // their range's corners.
    if constexpr (MergeableFit<BV>) {
        std::vector<typename BvTraits<BV>::Bounds> bounds(nodes_.size());
        for (std::size_t k = nodes_.size(); k-- > 0;) {
            Node& node = nodes_[k];
            if (node.isLeaf()) {
                bounds[k] = BvTraits<BV>::bounds(corners_[std::size_t(node.first)].data(), 3);
                for (std::int32_t i = node.first + 1; i < node.first + node.count; ++i) {
                    bounds[k] = BvTraits<BV>::merge(
                        bounds[k], BvTraits<BV>::bounds(corners_[std::size_t(i)].data(), 3));
                }
            } else {
                bounds[k] = BvTraits<BV>::merge(bounds[k + 1],
                                                bounds[static_cast<std::size_t>(node.right)]);
            }
            node.volume = BvTraits<BV>::finish(bounds[k]);
            node.cost = BvTraits<BV>::cost(node.volume);
        }
        return static_cast<std::int32_t>(nodes_.size());
    }
    std::vector<std::int32_t> first(nodes_.size());
    std::vector<std::int32_t> last(nodes_.size());
    std::vector<Vec3> scratch;
    for (std::size_t k = nodes_.size(); k-- > 0;) {
        Node& node = nodes_[k];
        if (node.isLeaf()) {
            first[k] = node.first;
            last[k] = node.first + node.count;
        } else {
            first[k] = first[k + 1];
            last[k] = last[static_cast<std::size_t>(node.right)];
        }
        scratch.clear();
        for (std::int32_t i = first[k]; i < last[k]; ++i) {
            for (const Vec3& p : corners_[static_cast<std::size_t>(i)]) scratch.push_back(p);
        }
        node.volume = BvTraits<BV>::fit(scratch);
        node.cost = BvTraits<BV>::cost(node.volume);
    }
    return static_cast<std::int32_t>(nodes_.size());
}

template <class BV>
bool Bvh<BV>::validate(std::string* error) const {
    auto fail = [&](const std::string& what) {
        if (error) *error = what;
        return false;
    };
    if (nodes_.empty()) {
        return ids_.empty() ? true : fail("triangles without nodes");
    }
    const Real tol = kValidateSlack * scale_;
    std::vector<int> seen(ids_.size(), 0);
    // Each stack entry: node, and the range [first, last) it must cover.
    struct Item {
        std::int32_t node;
        std::int32_t first;
        std::int32_t last;
    };
    std::vector<Item> stack{{0, 0, static_cast<std::int32_t>(ids_.size())}};
    std::size_t visited = 0;
    while (!stack.empty()) {
        const Item it = stack.back();
        stack.pop_back();
        if (it.node < 0 || static_cast<std::size_t>(it.node) >= nodes_.size()) {
            return fail("child index out of range");
        }
        ++visited;
        const Node& node = nodes_[static_cast<std::size_t>(it.node)];
        for (std::int32_t i = it.first; i < it.last; ++i) {
            for (const Vec3& p : corners_[static_cast<std::size_t>(i)]) {
                if (!BvTraits<BV>::contains(node.volume, p, tol)) {
                    std::ostringstream msg;
                    msg << "node " << it.node << " does not contain a corner of triangle "
                        << ids_[static_cast<std::size_t>(i)];
                    return fail(msg.str());
                }
            }
        }
        if (node.isLeaf()) {
            if (node.first != it.first || node.first + node.count != it.last) {
                return fail("leaf range does not match its parent's split");
            }
            for (std::int32_t i = it.first; i < it.last; ++i) ++seen[static_cast<std::size_t>(i)];
            continue;
        }
        // The right child's subtree starts where the left one's range ends: find it from the
        // left subtree's leaves (depth-first order).
        const std::int32_t left = it.node + 1;
        const std::int32_t right = node.right;
        if (right <= left || static_cast<std::size_t>(right) >= nodes_.size()) {
            return fail("internal node with bad children");
        }
        std::int32_t split = -1;
        for (std::int32_t k = right - 1; k >= left; --k) {  // last leaf before `right`
            if (nodes_[static_cast<std::size_t>(k)].isLeaf()) {
                split = nodes_[static_cast<std::size_t>(k)].first +
                        nodes_[static_cast<std::size_t>(k)].count;
                break;
            }
        }
        if (split <= it.first || split >= it.last) return fail("empty child range");
        stack.push_back({left, it.first, split});
        stack.push_back({right, split, it.last});
    }
    if (visited != nodes_.size()) return fail("unreachable nodes");
    for (std::size_t i = 0; i < seen.size(); ++i) {
        if (seen[i] != 1) return fail("a triangle is not in exactly one leaf");
    }
    std::vector<std::int32_t> sorted = ids_;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t i = 0; i < sorted.size(); ++i) {
        if (sorted[i] != static_cast<std::int32_t>(i))
            return fail("triangle ids not a permutation");
    }
    return true;
}

template class Bvh<BoundingSphere>;
template class Bvh<Aabb>;
template class Bvh<Obb>;
template class Bvh<Kdop<6>>;
template class Bvh<Kdop<14>>;
template class Bvh<Kdop<18>>;
template class Bvh<Kdop<26>>;
template class Bvh<Rss>;
template class Bvh<Lss>;

}  // namespace collision
