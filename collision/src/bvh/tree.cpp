// collision/src/bvh/tree.cpp -- the generic BVH: top-down build, validate, and the one tandem
// traversal behind every query; the brute-force reference; lookup of a volume type by name.
// Invariants: nodes are in depth-first order (left child = parent + 1), each leaf owns a
// contiguous range of the leaf-ordered triangles and the leaves partition them; every query moves
// B's volumes and triangle corners into A's frame with one BvhTransform (the brute force uses the
// same one), so every implementation tests bit-identical triangles; pair lists are sorted by
// (a, b) and free of duplicates, so any two implementations compare with ==.
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
#include "geometry/triangle_distance.h"
#include "geometry/triangle_triangle.h"
#include "volumes/bvh_volumes.h"

namespace collision {

namespace {

// Relative tolerance of validate()'s containment check (the fits add 16-48 ulps).
constexpr Real kValidateSlack = Real(1024) * kEpsilon;

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
    int depth = 0;              // longest root-to-leaf path so far (a lone leaf: 1)

    // Builds the subtree over leaf-order range [first, first + count) whose root is at `level`
    // (the root: 1); returns its node index.
    std::int32_t build(std::int32_t first, std::int32_t count, int level) {
        depth = std::max(depth, level);
        const auto index = static_cast<std::int32_t>(nodes.size());
        nodes.emplace_back();
        scratch.clear();
        for (std::int32_t i = first; i < first + count; ++i) {
            const auto id = static_cast<std::size_t>(ids[static_cast<std::size_t>(i)]);
            for (const Vec3& p : corners[id]) scratch.push_back(p);
        }
        {
            auto& node = nodes[static_cast<std::size_t>(index)];
            node.volume = fitNode(first, count);
            node.cost = BvTraits<BV>::cost(node.volume);
        }
        if (count <= options.max_leaf_triangles) {
            auto& node = nodes[static_cast<std::size_t>(index)];
            node.first = first;
            node.count = count;
            return index;
        }
        const std::int32_t split = splits
                                       ? splits->at(static_cast<std::int64_t>(first) *
                                                        static_cast<std::int64_t>(ids.size() + 1) +
                                                    count)
                                       : partition(first, count);
        build(first, split - first, level + 1);
        const std::int32_t right = build(split, first + count - split, level + 1);
        nodes[static_cast<std::size_t>(index)].right = right;
        return index;
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
        // Median; ties broken by triangle index so the build is deterministic.
        const std::int32_t mid = count / 2;
        std::nth_element(begin, begin + mid, end, [&](std::int32_t i, std::int32_t j) {
            return key(i) < key(j) || (key(i) == key(j) && i < j);
        });
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

// A traversal stack that lives on the call stack when the bound on its size fits (the usual
// case: the bound is the sum of the tree depths), so a query allocates nothing; larger bounds
// (very deep trees) fall back to the heap once per query.
template <class T>
class NodeStack {
public:
    explicit NodeStack(std::size_t bound) {
        if (bound > kInline) {
            heap_.resize(bound);
            data_ = heap_.data();
        }
    }
    NodeStack(const NodeStack&) = delete;
    NodeStack& operator=(const NodeStack&) = delete;
    void push(const T& v) {
        CDLAB_ASSERT(size_ < capacity(), "traversal stack bound exceeded");
        data_[size_++] = v;
    }
    T pop() { return data_[--size_]; }
    bool empty() const { return size_ == 0; }
    void clear() { size_ = 0; }

private:
    static constexpr std::size_t kInline = 256;
    std::size_t capacity() const { return heap_.empty() ? kInline : heap_.size(); }
    std::array<T, kInline> inline_{};
    std::vector<T> heap_;
    T* data_ = inline_.data();
    std::size_t size_ = 0;
};

// The traversal's test recorder: the queries pass this one, which records nothing (its empty
// inline calls compile away, so the timed queries are unchanged).
struct NoTestRecord {
    void node(std::int32_t, std::int32_t) {}
    void triangle(std::int32_t, std::int32_t) {}
};
// Records every node pair and triangle pair the traversal tests, in order (MeshBvh::recordTests).
struct SampleTestRecord {
    BvhTestSample* sample;
    void node(std::int32_t ia, std::int32_t ib) { sample->node_pairs.push_back({ia, ib}); }
    void triangle(std::int32_t i, std::int32_t j) { sample->triangle_pairs.push_back({i, j}); }
};

// The tandem traversal (Gottschalk 1996 §5): pop a node pair, test the volumes, and at two leaves
// test their triangles; otherwise descend the node with the larger volume (a leaf never
// descends). Every intersecting triangle pair goes to on_pair(i, j, ta, tb) (leaf-order indices,
// corners in A's frame), which returns true to stop. Returns true when stopped. `record` sees
// every node pair and triangle pair tested.
template <class BV, class OnPair, class Record = NoTestRecord>
bool traverse(const Bvh<BV>& a, const Bvh<BV>& b, const BvhTransform& x, BvhQueryStats* stats,
              OnPair&& on_pair, Record record = {}) {
    const auto& na = a.nodes();
    const auto& nb = b.nodes();
    if (na.empty() || nb.empty()) return false;
    std::int64_t bv_tests = 0;
    std::int64_t tri_tests = 0;
    bool stopped = false;
    // Depth-first with an explicit stack; its size is bounded by depth(a) + depth(b) + 1.
    // Each pop pushes at most two pairs and each push descends one level of A or B, so the
    // stack never holds more than depth(a) + depth(b) + 1 pairs.
    NodeStack<std::pair<std::int32_t, std::int32_t>> stack(
        static_cast<std::size_t>(a.depth() + b.depth() + 2));
    stack.push({0, 0});
    // B's node volume moved into A's frame, kept while the traversal descends A under the same
    // B node (the pair popped next after descending A has the same B node).
    [[maybe_unused]] BV moved_b{};
    [[maybe_unused]] std::int32_t moved_id = -1;
    while (!stack.empty() && !stopped) {
        const auto [ia, ib] = stack.pop();
        const auto& node_a = na[static_cast<std::size_t>(ia)];
        const auto& node_b = nb[static_cast<std::size_t>(ib)];
        ++bv_tests;
        record.node(ia, ib);
        if constexpr (MovableVolume<BV>) {
            if (ib != moved_id) {
                moved_b = BvTraits<BV>::move(node_b.volume, x);
                moved_id = ib;
            }
            if (!BvTraits<BV>::overlapsMoved(node_a.volume, moved_b, x)) continue;
        } else {
            if (!BvTraits<BV>::overlaps(node_a.volume, node_b.volume, x)) continue;
        }
        if (node_a.isLeaf() && node_b.isLeaf()) {
            for (std::int32_t j = node_b.first; j < node_b.first + node_b.count && !stopped; ++j) {
                const auto& tb = b.leafTriangle(j);
                const std::array<Vec3, 3> moved{x.apply(tb[0]), x.apply(tb[1]), x.apply(tb[2])};
                for (std::int32_t i = node_a.first; i < node_a.first + node_a.count; ++i) {
                    const auto& ta = a.leafTriangle(i);
                    ++tri_tests;
                    record.triangle(i, j);
                    if (!testTriangleTriangle(ta[0], ta[1], ta[2], moved[0], moved[1], moved[2])) {
                        continue;
                    }
                    if (on_pair(i, j, ta, moved)) {
                        stopped = true;
                        break;
                    }
                }
            }
            continue;
        }
        const bool descend_a = node_b.isLeaf() || (!node_a.isLeaf() && node_a.cost >= node_b.cost);
        if (descend_a) {
            stack.push({node_a.right, ib});
            stack.push({ia + 1, ib});
        } else {
            stack.push({ia, node_b.right});
            stack.push({ia, ib + 1});
        }
    }
    if (stats) {
        stats->bv_tests += bv_tests;
        stats->triangle_tests += tri_tests;
    }
    return stopped;
}

// The tree-against-one-volume traversal: every leaf triangle whose node volumes all overlap
// `volume` (in B's frame, placed by x) goes to on_triangle(i, corners) (leaf order), which returns
// true to stop. Returns true when stopped.
template <class BV, class OnTriangle>
bool traverseVolume(const Bvh<BV>& a, const BV& volume, const BvhTransform& x, BvhQueryStats* stats,
                    OnTriangle&& on_triangle) {
    const auto& na = a.nodes();
    if (na.empty()) return false;
    std::int64_t bv_tests = 0;
    bool stopped = false;
    NodeStack<std::int32_t> stack(static_cast<std::size_t>(a.depth() + 2));
    stack.push(0);
    [[maybe_unused]] BV moved{};
    if constexpr (MovableVolume<BV>) moved = BvTraits<BV>::move(volume, x);
    while (!stack.empty() && !stopped) {
        const std::int32_t ia = stack.pop();
        const auto& node = na[static_cast<std::size_t>(ia)];
        ++bv_tests;
        if constexpr (MovableVolume<BV>) {
            if (!BvTraits<BV>::overlapsMoved(node.volume, moved, x)) continue;
        } else {
            if (!BvTraits<BV>::overlaps(node.volume, volume, x)) continue;
        }
        if (node.isLeaf()) {
            for (std::int32_t i = node.first; i < node.first + node.count; ++i) {
                if (on_triangle(i, a.leafTriangle(i))) {
                    stopped = true;
                    break;
                }
            }
            continue;
        }
        stack.push(node.right);
        stack.push(ia + 1);
    }
    if (stats) stats->bv_tests += bv_tests;
    return stopped;
}

// The closed surface of the box [lo, hi] as 12 triangles (36 corners): the fits that weight by
// triangle area (OBB, RSS, LSS) see a box, not a point cloud.
const std::vector<Vec3>& boxSurfaceCorners(const Vec3& lo, const Vec3& hi) {
    auto corner = [&](int bits) {
        return Vec3((bits & 1) ? hi.x() : lo.x(), (bits & 2) ? hi.y() : lo.y(),
                    (bits & 4) ? hi.z() : lo.z());
    };
    thread_local std::vector<Vec3> out;  // reused: no allocation per query once warm
    out.clear();
    for (int axis = 0; axis < 3; ++axis) {
        const int u = 1 << ((axis + 1) % 3);
        const int v = 1 << ((axis + 2) % 3);
        for (int side = 0; side < 2; ++side) {
            const int base = side ? (1 << axis) : 0;
            for (const int bits : {base, base | u, base | u | v, base, base | u | v, base | v}) {
                out.push_back(corner(bits));
            }
        }
    }
    return out;
}

// What levelNodes() draws for a node volume (bvh.h, BvhLevelNode): the sphere itself, or a box
// containing the volume.
void setLevelShape(const BoundingSphere& v, BvhLevelNode& out) {
    out.is_sphere = true;
    out.sphere = v;
}
void setLevelShape(const Aabb& v, BvhLevelNode& out) {
    out.box.center = v.center();
    out.box.half_extents = (v.max - v.min) * Real(0.5);
}
void setLevelShape(const Obb& v, BvhLevelNode& out) { out.box = v; }
template <int K>
void setLevelShape(const Kdop<K>& v, BvhLevelNode& out) {
    // Slabs 0..2 are the unit axes (kKdopDirections): their box contains the k-DOP.
    const Vec3 lo(v.min[0], v.min[1], v.min[2]);
    const Vec3 hi(v.max[0], v.max[1], v.max[2]);
    out.box.center = (lo + hi) * Real(0.5);
    out.box.half_extents = (hi - lo) * Real(0.5);
}
void setLevelShape(const Rss& v, BvhLevelNode& out) {
    out.box.center = v.center;
    out.box.axes = v.axes;
    out.box.half_extents =
        Vec3(v.half_lengths[0] + v.radius, v.half_lengths[1] + v.radius, v.radius);
}

void setLevelShape(const Lss& v, BvhLevelNode& out) {
    // The capsule's box: the segment's axis first, any two unit vectors across it.
    const Vec3 u = v.axis.normalized();
    const Vec3 helper = std::abs(u.x()) < Real(0.9) ? Vec3(Vec3::UnitX()) : Vec3(Vec3::UnitY());
    const Vec3 w1 = u.cross(helper).normalized();
    out.box.center = v.center;
    out.box.axes.col(0) = u;
    out.box.axes.col(1) = w1;
    out.box.axes.col(2) = u.cross(w1);
    out.box.half_extents = Vec3(v.half_length + v.radius, v.radius, v.radius);
}

// The cut of `tree` at `depth` (MeshBvh::levelNodes), in depth-first order.
template <class BV>
std::vector<BvhLevelNode> levelNodesOf(const Bvh<BV>& tree, int depth) {
    std::vector<BvhLevelNode> out;
    const auto& nodes = tree.nodes();
    if (depth < 0 || nodes.empty()) return out;
    std::vector<std::pair<std::int32_t, int>> stack{{0, 0}};
    std::vector<std::int32_t> subtree;
    while (!stack.empty()) {
        const auto [index, d] = stack.back();
        stack.pop_back();
        const auto& node = nodes[static_cast<std::size_t>(index)];
        if (d < depth && !node.isLeaf()) {
            stack.push_back({node.right, d + 1});  // left (index + 1) pops first
            stack.push_back({index + 1, d + 1});
            continue;
        }
        BvhLevelNode level;
        level.node = index;
        level.depth = d;
        setLevelShape(node.volume, level);
        subtree.assign(1, index);
        while (!subtree.empty()) {
            const std::int32_t i = subtree.back();
            subtree.pop_back();
            const auto& n = nodes[static_cast<std::size_t>(i)];
            if (n.isLeaf()) {
                for (std::int32_t k = n.first; k < n.first + n.count; ++k) {
                    level.triangles.push_back(tree.leafTriangleId(k));
                }
            } else {
                subtree.push_back(i + 1);
                subtree.push_back(n.right);
            }
        }
        std::sort(level.triangles.begin(), level.triangles.end());
        out.push_back(std::move(level));
    }
    return out;
}

// Depth-first indices of the cut (levelNodesOf without the triangle lists).
template <class BV>
std::vector<std::int32_t> levelIndices(const Bvh<BV>& tree, int depth) {
    std::vector<std::int32_t> out;
    const auto& nodes = tree.nodes();
    if (depth < 0 || nodes.empty()) return out;
    std::vector<std::pair<std::int32_t, int>> stack{{0, 0}};
    while (!stack.empty()) {
        const auto [index, d] = stack.back();
        stack.pop_back();
        const auto& node = nodes[static_cast<std::size_t>(index)];
        if (d < depth && !node.isLeaf()) {
            stack.push_back({node.right, d + 1});
            stack.push_back({index + 1, d + 1});
        } else {
            out.push_back(index);
        }
    }
    return out;
}

// The volume tests of `sample` as traverse() does them: B's node volume moved into A's frame
// once per run of pairs with the same B node (movable types), then the overlap test. Returns how
// many overlap, `repeats` times over.
template <class BV>
std::int64_t replayVolumeTestsOf(const Bvh<BV>& a, const Bvh<BV>& b, const BvhTransform& x,
                                 const BvhTestSample& sample, int repeats) {
    const auto& na = a.nodes();
    const auto& nb = b.nodes();
    std::int64_t overlapping = 0;
    for (int r = 0; r < repeats; ++r) {
        [[maybe_unused]] BV moved_b{};
        [[maybe_unused]] std::int32_t moved_id = -1;
        for (const auto& [ia, ib] : sample.node_pairs) {
            const auto& node_a = na[static_cast<std::size_t>(ia)];
            const auto& node_b = nb[static_cast<std::size_t>(ib)];
            if constexpr (MovableVolume<BV>) {
                if (ib != moved_id) {
                    moved_b = BvTraits<BV>::move(node_b.volume, x);
                    moved_id = ib;
                }
                overlapping += BvTraits<BV>::overlapsMoved(node_a.volume, moved_b, x) ? 1 : 0;
            } else {
                overlapping += BvTraits<BV>::overlaps(node_a.volume, node_b.volume, x) ? 1 : 0;
            }
        }
    }
    return overlapping;
}

// The triangle tests of `sample` as traverse() does them at a leaf pair of one triangle each:
// B's triangle moved into A's frame, then the exact test. Returns how many intersect.
template <class BV>
std::int64_t replayTriangleTestsOf(const Bvh<BV>& a, const Bvh<BV>& b, const BvhTransform& x,
                                   const BvhTestSample& sample, int repeats) {
    std::int64_t intersecting = 0;
    for (int r = 0; r < repeats; ++r) {
        for (const auto& [i, j] : sample.triangle_pairs) {
            const auto& tb = b.leafTriangle(j);
            const std::array<Vec3, 3> moved{x.apply(tb[0]), x.apply(tb[1]), x.apply(tb[2])};
            const auto& ta = a.leafTriangle(i);
            intersecting +=
                testTriangleTriangle(ta[0], ta[1], ta[2], moved[0], moved[1], moved[2]) ? 1 : 0;
        }
    }
    return intersecting;
}

template <class BV>
class MeshBvhOf final : public MeshBvh {
public:
    MeshBvhOf(const TriangleMesh& mesh, const BvhBuildOptions& options) : tree_(mesh, options) {}
    std::string_view volumeName() const override { return BvName<BV>::value; }
    std::int32_t nodeCount() const override {
        return static_cast<std::int32_t>(tree_.nodes().size());
    }
    int depth() const override { return tree_.depth(); }
    bool validate(std::string* error) const override { return tree_.validate(error); }
    bool testOverlap(const MeshBvh& b, const Pose& b_in_a, BvhQueryStats* stats) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        return other != nullptr && testBvhBvh(tree_, other->tree_, b_in_a, stats);
    }
    std::vector<TrianglePair> intersect(const MeshBvh& b, const Pose& b_in_a,
                                        BvhQueryStats* stats) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        if (other == nullptr) return {};
        return intersectBvhBvh(tree_, other->tree_, b_in_a, stats);
    }
    std::int32_t triangleCount() const override { return tree_.triangleCount(); }
    const Bvh<Obb>* obbTree() const override {
        if constexpr (std::is_same_v<BV, Obb>) {
            return &tree_;
        } else {
            return nullptr;
        }
    }
    std::int32_t refit(const TriangleMesh& mesh) override { return tree_.refit(mesh); }
    MeshDistance distance(const MeshBvh& b, const Pose& b_in_a,
                          BvhQueryStats* stats) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        if (other == nullptr) {
            MeshDistance none;
            none.distance = std::numeric_limits<Real>::infinity();
            return none;
        }
        return distanceBvhBvh(tree_, other->tree_, b_in_a, stats);
    }
    std::vector<TrianglePair> intersectSelf(BvhQueryStats* stats) const override {
        return collision::intersectSelf(tree_, stats);
    }
    bool sameVolumeType(const MeshBvh& b) const override {
        return dynamic_cast<const MeshBvhOf<BV>*>(&b) != nullptr;
    }
    bool visitIntersecting(const MeshBvh& b, const Mat3& rotation, const Vec3& translation,
                           TrianglePairVisitor& visitor, BvhQueryStats* stats) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        if (other == nullptr) return false;
        const Bvh<BV>& tb = other->tree_;
        const BvhTransform x = makeBvhTransform(rotation, translation, tree_.scale(), tb.scale());
        return traverse(tree_, tb, x, stats,
                        [&](std::int32_t i, std::int32_t j, const std::array<Vec3, 3>& ta,
                            const std::array<Vec3, 3>& moved) {
                            return visitor.visit(tree_.leafTriangleId(i), ta, tb.leafTriangleId(j),
                                                 moved);
                        });
    }
    bool visitNearBox(const Vec3& box_min, const Vec3& box_max, const Mat3& rotation,
                      const Vec3& translation, TriangleVisitor& visitor,
                      BvhQueryStats* stats) const override {
        if (tree_.nodes().empty()) return false;
        const Real box_scale =
            (box_max - box_min).maxCoeff() +
            std::max(box_min.cwiseAbs().maxCoeff(), box_max.cwiseAbs().maxCoeff());
        const BV volume = BvTraits<BV>::fit(boxSurfaceCorners(box_min, box_max));
        const BvhTransform x = makeBvhTransform(rotation, translation, tree_.scale(), box_scale);
        return traverseVolume(tree_, volume, x, stats,
                              [&](std::int32_t i, const std::array<Vec3, 3>& corners) {
                                  return visitor.visit(tree_.leafTriangleId(i), corners);
                              });
    }
    BvhTestSample recordTests(const MeshBvh& b, const Pose& b_in_a) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        BvhTestSample sample;
        if (other == nullptr) return sample;
        const BvhTransform x = makeBvhTransform(b_in_a, tree_.scale(), other->tree_.scale());
        traverse(
            tree_, other->tree_, x, nullptr,
            [](std::int32_t, std::int32_t, const std::array<Vec3, 3>&, const std::array<Vec3, 3>&) {
                return false;
            },
            SampleTestRecord{&sample});
        return sample;
    }
    std::int64_t replayVolumeTests(const MeshBvh& b, const Pose& b_in_a,
                                   const BvhTestSample& sample, int repeats) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        if (other == nullptr) return 0;
        if (!sampleFits(sample, other->tree_)) return -1;
        const BvhTransform x = makeBvhTransform(b_in_a, tree_.scale(), other->tree_.scale());
        return replayVolumeTestsOf(tree_, other->tree_, x, sample, repeats);
    }
    std::int64_t replayTriangleTests(const MeshBvh& b, const Pose& b_in_a,
                                     const BvhTestSample& sample, int repeats) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        if (other == nullptr) return 0;
        if (!sampleFits(sample, other->tree_)) return -1;
        const BvhTransform x = makeBvhTransform(b_in_a, tree_.scale(), other->tree_.scale());
        return replayTriangleTestsOf(tree_, other->tree_, x, sample, repeats);
    }
    std::vector<BvhLevelNode> levelNodes(int depth) const override {
        return levelNodesOf(tree_, depth);
    }
    std::vector<BvhLevelPair> levelOverlaps(int depth, const MeshBvh& b, const Mat3& rotation,
                                            const Vec3& translation) const override {
        const auto* other = dynamic_cast<const MeshBvhOf<BV>*>(&b);
        CDLAB_ASSERT(other != nullptr, "BVH query between different volume types");
        std::vector<BvhLevelPair> out;
        if (other == nullptr) return out;
        const Bvh<BV>& tb = other->tree_;
        const BvhTransform x = makeBvhTransform(rotation, translation, tree_.scale(), tb.scale());
        const std::vector<std::int32_t> cut_a = levelIndices(tree_, depth);
        const std::vector<std::int32_t> cut_b = levelIndices(tb, depth);
        for (std::size_t i = 0; i < cut_a.size(); ++i) {
            const BV& va = tree_.nodes()[static_cast<std::size_t>(cut_a[i])].volume;
            for (std::size_t j = 0; j < cut_b.size(); ++j) {
                const BV& vb = tb.nodes()[static_cast<std::size_t>(cut_b[j])].volume;
                if (BvTraits<BV>::overlaps(va, vb, x)) {
                    out.push_back({static_cast<std::int32_t>(i), static_cast<std::int32_t>(j)});
                }
            }
        }
        return out;
    }
    std::vector<std::int32_t> levelOverlapsBox(int depth, const Vec3& box_min, const Vec3& box_max,
                                               const Mat3& rotation,
                                               const Vec3& translation) const override {
        std::vector<std::int32_t> out;
        if (tree_.nodes().empty()) return out;
        // The volume and transform of visitNearBox.
        const Real box_scale =
            (box_max - box_min).maxCoeff() +
            std::max(box_min.cwiseAbs().maxCoeff(), box_max.cwiseAbs().maxCoeff());
        const BV volume = BvTraits<BV>::fit(boxSurfaceCorners(box_min, box_max));
        const BvhTransform x = makeBvhTransform(rotation, translation, tree_.scale(), box_scale);
        const std::vector<std::int32_t> cut = levelIndices(tree_, depth);
        for (std::size_t i = 0; i < cut.size(); ++i) {
            const BV& v = tree_.nodes()[static_cast<std::size_t>(cut[i])].volume;
            if (BvTraits<BV>::overlaps(v, volume, x)) out.push_back(static_cast<std::int32_t>(i));
        }
        return out;
    }

private:
    // Every index of `sample` names a node or leaf triangle of this tree (A) and of `b`.
    bool sampleFits(const BvhTestSample& sample, const Bvh<BV>& b) const {
        const auto nodes_a = static_cast<std::int32_t>(tree_.nodes().size());
        const auto nodes_b = static_cast<std::int32_t>(b.nodes().size());
        for (const auto& [ia, ib] : sample.node_pairs) {
            if (ia < 0 || ia >= nodes_a || ib < 0 || ib >= nodes_b) return false;
        }
        for (const auto& [i, j] : sample.triangle_pairs) {
            if (i < 0 || i >= tree_.triangleCount() || j < 0 || j >= b.triangleCount()) {
                return false;
            }
        }
        return true;
    }

    Bvh<BV> tree_;
};

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
                        {}};
    builder.scratch.reserve(3 * n);  // the root's corners: no regrowth during the build
    builder.build(0, static_cast<std::int32_t>(n), 1);
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
    // Ranges bottom-up: children come after their parent in depth-first order, so a reverse
    // sweep sees both children of a node before the node.
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

MeshDistance distanceMeshMeshBruteForce(const TriangleMesh& a, const TriangleMesh& b,
                                        const Pose& b_in_a, BvhQueryStats* stats) {
    const BvhTransform x = makeBvhTransform(b_in_a, 0, 0);  // the BVH query's transform
    MeshDistance out;
    out.distance = std::numeric_limits<Real>::infinity();
    std::vector<std::array<Vec3, 3>> moved(b.triangles.size());
    for (std::size_t j = 0; j < b.triangles.size(); ++j) {
        for (std::size_t k = 0; k < 3; ++k) {
            moved[j][k] = x.apply(b.vertices[static_cast<std::size_t>(b.triangles[j][k])]);
        }
    }
    std::int64_t tests = 0;
    for (std::size_t i = 0; i < a.triangles.size(); ++i) {
        const auto& t = a.triangles[i];
        const Vec3& p1 = a.vertices[static_cast<std::size_t>(t[0])];
        const Vec3& q1 = a.vertices[static_cast<std::size_t>(t[1])];
        const Vec3& r1 = a.vertices[static_cast<std::size_t>(t[2])];
        for (std::size_t j = 0; j < moved.size(); ++j) {
            ++tests;
            const TriangleDistance td =
                distanceTriangleTriangle(p1, q1, r1, moved[j][0], moved[j][1], moved[j][2]);
            if (td.distance < out.distance) {
                out.distance = td.distance;
                out.a = static_cast<std::int32_t>(i);
                out.b = static_cast<std::int32_t>(j);
                out.point_on_a = td.point_on_1;
                out.point_on_b = td.point_on_2;
            }
        }
    }
    if (stats) stats->triangle_tests += tests;
    return out;
}

namespace {

bool shareVertex(const std::array<std::int32_t, 3>& u, const std::array<std::int32_t, 3>& v) {
    for (const std::int32_t i : u) {
        if (i == v[0] || i == v[1] || i == v[2]) return true;
    }
    return false;
}

}  // namespace

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
        const bool descend_a = nb.isLeaf() || (!na.isLeaf() && na.cost >= nb.cost);
        if (descend_a) {
            stack.emplace_back(na.right, ib);
            stack.emplace_back(ia + 1, ib);
        } else {
            stack.emplace_back(ia, nb.right);
            stack.emplace_back(ia, ib + 1);
        }
    }
    if (stats) {
        stats->bv_tests += bv_tests;
        stats->triangle_tests += tri_tests;
    }
    std::sort(pairs.begin(), pairs.end());
    return pairs;
}

std::vector<TrianglePair> intersectSelfBruteForce(const TriangleMesh& mesh, BvhQueryStats* stats) {
    std::vector<TrianglePair> pairs;
    std::int64_t tests = 0;
    const std::size_t n = mesh.triangles.size();
    auto corner = [&](std::size_t t, int k) -> const Vec3& {
        return mesh
            .vertices[static_cast<std::size_t>(mesh.triangles[t][static_cast<std::size_t>(k)])];
    };
    std::vector<Vec3> lo(n);
    std::vector<Vec3> hi(n);
    for (std::size_t i = 0; i < n; ++i) {
        lo[i] = corner(i, 0).cwiseMin(corner(i, 1)).cwiseMin(corner(i, 2));
        hi[i] = corner(i, 0).cwiseMax(corner(i, 1)).cwiseMax(corner(i, 2));
    }
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n; ++j) {
            // Disjoint exact boxes of the same coordinates: the triangles are apart.
            if ((lo[i].array() > hi[j].array()).any() || (lo[j].array() > hi[i].array()).any()) {
                continue;
            }
            if (shareVertex(mesh.triangles[i], mesh.triangles[j])) continue;
            ++tests;
            if (testTriangleTriangle(corner(i, 0), corner(i, 1), corner(i, 2), corner(j, 0),
                                     corner(j, 1), corner(j, 2))) {
                pairs.push_back({static_cast<std::int32_t>(i), static_cast<std::int32_t>(j)});
            }
        }
    }
    if (stats) stats->triangle_tests += tests;
    return pairs;  // generated in (a, b) order
}

std::vector<TrianglePair> intersectMeshMeshBruteForce(const TriangleMesh& a, const TriangleMesh& b,
                                                      const Pose& b_in_a, BvhQueryStats* stats) {
    // The same transform as the BVH queries (scales do not matter: only `apply` is used).
    const BvhTransform x = makeBvhTransform(b_in_a, 0, 0);
    struct Tri {
        Vec3 p, q, r, lo, hi;
    };
    auto make = [](const Vec3& p, const Vec3& q, const Vec3& r) {
        return Tri{p, q, r, p.cwiseMin(q).cwiseMin(r), p.cwiseMax(q).cwiseMax(r)};
    };
    std::vector<Tri> ta;
    std::vector<Tri> tb;
    for (const auto& t : a.triangles) {
        ta.push_back(make(a.vertices[static_cast<std::size_t>(t[0])],
                          a.vertices[static_cast<std::size_t>(t[1])],
                          a.vertices[static_cast<std::size_t>(t[2])]));
    }
    for (const auto& t : b.triangles) {
        tb.push_back(make(x.apply(b.vertices[static_cast<std::size_t>(t[0])]),
                          x.apply(b.vertices[static_cast<std::size_t>(t[1])]),
                          x.apply(b.vertices[static_cast<std::size_t>(t[2])])));
    }
    std::vector<TrianglePair> pairs;
    std::int64_t tests = 0;
    for (std::size_t i = 0; i < ta.size(); ++i) {
        for (std::size_t j = 0; j < tb.size(); ++j) {
            // Disjoint exact (unrounded) boxes of the same coordinates: the triangles are apart.
            if ((ta[i].lo.array() > tb[j].hi.array()).any() ||
                (tb[j].lo.array() > ta[i].hi.array()).any()) {
                continue;
            }
            ++tests;
            if (testTriangleTriangle(ta[i].p, ta[i].q, ta[i].r, tb[j].p, tb[j].q, tb[j].r)) {
                pairs.push_back({static_cast<std::int32_t>(i), static_cast<std::int32_t>(j)});
            }
        }
    }
    if (stats) stats->triangle_tests += tests;
    return pairs;  // generated in (a, b) order: sorted and unique
}

std::vector<TrianglePair> intersectMeshMeshSweep(const TriangleMesh& a, const TriangleMesh& b,
                                                 const Pose& b_in_a, BvhQueryStats* stats) {
    // The brute force's triangles and boxes (same transform, same expressions), but B's boxes
    // sorted by min.x: for A's triangle i only B's boxes with min.x in
    // [lo_i.x - widest B box, hi_i.x] can overlap, and those are tested with the brute force's
    // exact comparisons, so the candidate set and the answer are the brute force's.
    const BvhTransform x = makeBvhTransform(b_in_a, 0, 0);
    struct Tri {
        Vec3 p, q, r, lo, hi;
        std::int32_t id;
    };
    auto make = [](const Vec3& p, const Vec3& q, const Vec3& r, std::size_t id) {
        return Tri{p,
                   q,
                   r,
                   p.cwiseMin(q).cwiseMin(r),
                   p.cwiseMax(q).cwiseMax(r),
                   static_cast<std::int32_t>(id)};
    };
    std::vector<Tri> ta;
    std::vector<Tri> tb;
    ta.reserve(a.triangles.size());
    tb.reserve(b.triangles.size());
    for (std::size_t i = 0; i < a.triangles.size(); ++i) {
        const auto& t = a.triangles[i];
        ta.push_back(make(a.vertices[static_cast<std::size_t>(t[0])],
                          a.vertices[static_cast<std::size_t>(t[1])],
                          a.vertices[static_cast<std::size_t>(t[2])], i));
    }
    Real widest = 0;
    for (std::size_t j = 0; j < b.triangles.size(); ++j) {
        const auto& t = b.triangles[j];
        tb.push_back(make(x.apply(b.vertices[static_cast<std::size_t>(t[0])]),
                          x.apply(b.vertices[static_cast<std::size_t>(t[1])]),
                          x.apply(b.vertices[static_cast<std::size_t>(t[2])]), j));
        widest = std::max(widest, tb.back().hi.x() - tb.back().lo.x());
    }
    std::sort(tb.begin(), tb.end(), [](const Tri& u, const Tri& v) {
        return u.lo.x() < v.lo.x() || (u.lo.x() == v.lo.x() && u.id < v.id);
    });
    std::vector<TrianglePair> pairs;
    std::int64_t tests = 0;
    for (const Tri& ti : ta) {
        // Every box with lo.x >= ti.lo.x - widest, moved down by a rounding margin (only widens
        // the scan: the exact box test below decides).
        const Real from = ti.lo.x() - widest - Real(4) * kEpsilon * (std::abs(ti.lo.x()) + widest);
        auto it = std::lower_bound(tb.begin(), tb.end(), from,
                                   [](const Tri& u, Real v) { return u.lo.x() < v; });
        for (; it != tb.end() && it->lo.x() <= ti.hi.x(); ++it) {
            const Tri& tj = *it;
            if ((ti.lo.array() > tj.hi.array()).any() || (tj.lo.array() > ti.hi.array()).any()) {
                continue;
            }
            ++tests;
            if (testTriangleTriangle(ti.p, ti.q, ti.r, tj.p, tj.q, tj.r)) {
                pairs.push_back({ti.id, tj.id});
            }
        }
    }
    if (stats) stats->triangle_tests += tests;
    std::sort(pairs.begin(), pairs.end());
    return pairs;
}

const std::vector<std::string_view>& bvhVolumeNames() {
    static const std::vector<std::string_view> names = [] {
        std::vector<std::string_view> out;
        std::apply([&](auto... bv) { (out.push_back(BvName<decltype(bv)>::value), ...); },
                   BvhVolumeTypes{});
        return out;
    }();
    return names;
}

std::unique_ptr<MeshBvh> buildMeshBvh(std::string_view volume_name, const TriangleMesh& mesh,
                                      const BvhBuildOptions& options) {
    std::unique_ptr<MeshBvh> out;
    std::apply(
        [&](auto... bv) {
            ((BvName<decltype(bv)>::value == volume_name && !out
                  ? (void)(out = std::make_unique<MeshBvhOf<decltype(bv)>>(mesh, options))
                  : (void)0),
             ...);
        },
        BvhVolumeTypes{});
    return out;
}

// Explicit instantiation for every type of BvhVolumeTypes (registration is explicit).
#define CDLAB_BVH_INSTANTIATE(BV)                                                              \
    template class Bvh<BV>;                                                                    \
    template bool testBvhBvh<BV>(const Bvh<BV>&, const Bvh<BV>&, const Pose&, BvhQueryStats*); \
    template std::vector<TrianglePair> intersectBvhBvh<BV>(const Bvh<BV>&, const Bvh<BV>&,     \
                                                           const Pose&, BvhQueryStats*);       \
    template std::vector<TrianglePair> intersectSelf<BV>(const Bvh<BV>&, BvhQueryStats*);      \
    template MeshDistance distanceBvhBvh<BV>(const Bvh<BV>&, const Bvh<BV>&, const Pose&,      \
                                             BvhQueryStats*);
CDLAB_BVH_INSTANTIATE(BoundingSphere)
CDLAB_BVH_INSTANTIATE(Aabb)
CDLAB_BVH_INSTANTIATE(Obb)
CDLAB_BVH_INSTANTIATE(Kdop<6>)
CDLAB_BVH_INSTANTIATE(Kdop<14>)
CDLAB_BVH_INSTANTIATE(Kdop<18>)
CDLAB_BVH_INSTANTIATE(Kdop<26>)
CDLAB_BVH_INSTANTIATE(Rss)
CDLAB_BVH_INSTANTIATE(Lss)
#undef CDLAB_BVH_INSTANTIATE

}  // namespace collision
