// collision/src/bvh/traversal.h -- the one tandem traversal behind every query of two trees
// (Gottschalk 1996 §5), the tree-against-one-volume traversal, and their stack; private to the
// BVH files (queries, type erasure, replay, levels).
// Invariant: every query moves B's volumes and triangle corners into A's frame with one
// BvhTransform, so every implementation (and the brute-force reference) tests bit-identical
// triangles.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "collision/assert.h"
#include "collision/bvh/bvh.h"
#include "collision/bvh/bvh_replay.h"
#include "geometry/triangle_triangle.h"
#include "volumes/bvh_volumes.h"

namespace collision {

/// The tandem descent rule (Gottschalk 1996 §5) for a node pair that is not two leaves: the node
/// of larger cost is split, or the only internal one; both (child, other node) pairs are pushed,
/// the right child's first, so the left child's pair is visited first.
template <class Node, class Stack>
void pushChildrenOfLarger(Stack& stack, const Node& na, std::int32_t ia, const Node& nb,
                          std::int32_t ib) {
    if (nb.isLeaf() || (!na.isLeaf() && na.cost >= nb.cost)) {
        stack.emplace_back(na.right, ib);
        stack.emplace_back(ia + 1, ib);
    } else {
        stack.emplace_back(ia, nb.right);
        stack.emplace_back(ia, ib + 1);
    }
}

// Asks the cache for every line of a node (a hint: no effect on any answer).
template <class Node>
inline void prefetchNode(const Node& node) {
    const char* p = reinterpret_cast<const char*>(&node);
    for (std::size_t offset = 0; offset < sizeof(Node); offset += 64) {
        __builtin_prefetch(p + offset);
    }
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
// Records every node pair and triangle pair the traversal tests, in order (recordTests).
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
        // The right child lies a whole left subtree away in memory: fetch it now (the left child
        // follows its parent and is popped next).
        if (descend_a) {
            prefetchNode(na[static_cast<std::size_t>(node_a.right)]);
            stack.push({node_a.right, ib});
            stack.push({ia + 1, ib});
        } else {
            prefetchNode(nb[static_cast<std::size_t>(node_b.right)]);
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
inline const std::vector<Vec3>& boxSurfaceCorners(const Vec3& lo, const Vec3& hi) {
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

// Self-collision skips adjacent triangles: those sharing a vertex index (coincident vertices
// with different indices do not count), in the query and in its reference alike.
inline bool shareVertex(const std::array<std::int32_t, 3>& u,
                        const std::array<std::int32_t, 3>& v) {
    for (const std::int32_t i : u) {
        if (i == v[0] || i == v[1] || i == v[2]) return true;
    }
    return false;
}

}  // namespace collision
