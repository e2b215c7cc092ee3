// collision/src/broadphase/octree.cpp -- loose octree.
// Completeness: a proxy's AABB lies inside its node's loose box (centre in the cell, half extent
// <= half side <= the loosening), so a proxy whose AABB overlaps it is in a node whose loose box
// overlaps it too, and the query from the lower id reaches that node. Loose boxes are grown by a
// relative epsilon against the rounding of centre/half computations.
#include "broadphase/octree.h"

#include <algorithm>

#include "collision/debug_draw.h"

namespace collision {

void LooseOctree::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    countMoves(counters);
    pairs.clear();
    nodes_.clear();
    if (table_.count() == 0) return;

    // Root cube: bounds of the AABB centres, squared up, side at least the largest extent.
    Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::max());
    Vec3 hi = Vec3::Constant(std::numeric_limits<Real>::lowest());
    Real largest = 0;
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (!table_.contains(id)) continue;
        const Aabb& box = table_.aabb(id);
        lo = lo.cwiseMin(box.center());
        hi = hi.cwiseMax(box.center());
        largest = std::max(largest, box.extents().maxCoeff());
    }
    Node root;
    root.center = (lo + hi) * Real(0.5);
    root.half = std::max({(hi - lo).maxCoeff() * Real(0.5), largest, Real(1e-30)});
    root.half *= 1 + 64 * kEpsilon;
    nodes_.push_back(root);

    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (!table_.contains(id)) continue;
        const Aabb& box = table_.aabb(id);
        const Vec3 c = box.center();
        const Real extent = box.extents().maxCoeff();
        int index = 0;
        // Descend while the child cell (side = half of this) still takes the proxy's extent.
        while (nodes_[index].depth < kMaxDepth && extent <= nodes_[index].half) {
            const Node& n = nodes_[index];
            const int octant = (c.x() >= n.center.x() ? 1 : 0) | (c.y() >= n.center.y() ? 2 : 0) |
                               (c.z() >= n.center.z() ? 4 : 0);
            if (n.child[octant] < 0) {
                Node child;
                child.half = n.half * Real(0.5);
                child.center = n.center + Vec3((octant & 1) ? child.half : -child.half,
                                               (octant & 2) ? child.half : -child.half,
                                               (octant & 4) ? child.half : -child.half);
                child.depth = n.depth + 1;
                nodes_.push_back(std::move(child));
                nodes_[index].child[octant] = static_cast<int>(nodes_.size()) - 1;
            }
            index = nodes_[index].child[octant];
        }
        nodes_[index].proxies.push_back(id);
    }

    for (ProxyId a = 0; a < table_.capacity(); ++a) {
        if (!table_.contains(a)) continue;
        const Aabb& box = table_.aabb(a);
        stack_.clear();
        stack_.push_back(0);
        while (!stack_.empty()) {
            const Node& n = nodes_[stack_.back()];
            stack_.pop_back();
            Aabb loose = looseBox(n);
            const Real slack = 64 * kEpsilon * (2 * n.half + n.center.cwiseAbs().maxCoeff());
            loose.min.array() -= slack;
            loose.max.array() += slack;
            ++counters.volume_tests;
            if (!loose.overlaps(box)) continue;
            for (ProxyId b : n.proxies) {
                if (b <= a) continue;
                ++counters.volume_tests;
                if (box.overlaps(table_.aabb(b))) pairs.push_back(ProxyPair{a, b});
            }
            for (int c : n.child) {
                if (c >= 0) stack_.push_back(c);
            }
        }
    }
    std::sort(pairs.begin(), pairs.end());
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void LooseOctree::draw(DebugDraw& draw, const Aabb& /*bounds*/) const {
    // The cells of the nodes that hold proxies (their loose boxes are twice as wide), one colour
    // per depth.
    int depths = 0;
    for (const Node& n : nodes_) {
        if (n.proxies.empty()) continue;
        draw.drawAabb(Aabb{n.center - Vec3::Constant(n.half), n.center + Vec3::Constant(n.half)},
                      structureColor(n.depth));
        depths = std::max(depths, n.depth + 1);
    }
    legendByNumber(draw, "octree cells holding proxies, depth", depths);
}

}  // namespace collision
