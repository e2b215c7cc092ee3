// collision/src/broadphase/tree.h -- dynamic AABB tree with fattened leaves.
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "broadphase/proxy_table.h"
#include "collision/broadphase/broad_phase.h"

namespace collision {

/// Incremental bounding-volume tree over the proxies' AABBs (the design of Box2D's
/// b2DynamicTree and Bullet's btDbvt; Catto, "Dynamic Bounding Volume Hierarchies", GDC 2019).
/// Leaves hold AABBs fattened by a margin proportional to the box's size, so a proxy that moves
/// a little is not touched at all; one that leaves its fat box is removed and re-inserted.
/// Insertion descends by the surface-area heuristic (the sibling that least increases the total
/// area of the ancestors), then surface-area rotations keep siblings close. Pairs: one
/// traversal of the tree against itself, leaves tested on their exact AABBs.
class DynamicAabbTree : public BroadPhase {
public:
    std::string_view name() const override { return "tree"; }
    std::unique_ptr<BroadPhase> clone() const override {
        return std::make_unique<DynamicAabbTree>(*this);
    }
    void insert(ProxyId id, const ProxyVolumes& v) override;
    void remove(ProxyId id) override;
    void move(ProxyId id, const ProxyVolumes& v) override;
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    void draw(DebugDraw& draw, const Aabb& bounds) const override;
    std::string validate() const override;

    /// Relative fattening of leaves: margin = kFatRatio * largest extent (+ a floor for points).
    static constexpr Real kFatRatio = Real(0.1);

private:
    static constexpr int kNull = -1;
    struct Node {
        Aabb box;
        int parent = kNull;
        int child1 = kNull;
        int child2 = kNull;
        int height = 0;  // leaf = 0; free = -1
        ProxyId proxy = -1;
        bool isLeaf() const { return child1 == kNull; }
    };

    int allocateNode();
    void freeNode(int node);
    void insertLeaf(int leaf);
    void removeLeaf(int leaf);
    int balance(int a);
    Aabb fatten(const Aabb& box) const;
    std::string validateNode(int node, int parent) const;

    ProxyTable table_;
    std::vector<Node> nodes_;
    std::vector<int> leaf_of_;  // proxy id -> leaf node
    int root_ = kNull;
    int free_list_ = kNull;
    std::int64_t moved_ = 0;
    std::vector<std::pair<int, int>> pair_stack_;
    std::vector<std::uint64_t> keys_;
    std::vector<std::uint64_t> scratch_;
};

}  // namespace collision
