// collision/src/broadphase/octree.h -- loose octree, rebuilt every frame.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "broadphase/proxy_table.h"
#include "collision/broadphase/broad_phase.h"

namespace collision {

/// Loose octree (Ulrich, "Loose Octrees", Game Programming Gems 2000; RTCD 7.3.5) with looseness
/// k = 2: a node of side s holds proxies whose centre lies in its cell and whose largest extent
/// is at most s, so every proxy sits in exactly one node, its "loose" box (the cell grown by s/2
/// on every side) containing the proxy's AABB. Each proxy then queries the nodes whose loose box
/// overlaps its AABB and keeps partners of higher id. The root cube covers all AABB centres;
/// depth is capped at kMaxDepth.
class LooseOctree : public RebuildingBroadPhase {
public:
    std::string_view name() const override { return "octree"; }
    std::unique_ptr<BroadPhase> clone() const override {
        return std::make_unique<LooseOctree>(*this);
    }
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    void draw(DebugDraw& draw, const Aabb& bounds) const override;

    static constexpr int kMaxDepth = 16;

private:
    struct Node {
        Vec3 center;
        Real half = 0;  // half side of the cell
        int depth = 0;
        std::array<int, 8> child{-1, -1, -1, -1, -1, -1, -1, -1};
        std::vector<ProxyId> proxies;
    };
    Aabb looseBox(const Node& n) const {
        return Aabb{n.center - Vec3::Constant(2 * n.half), n.center + Vec3::Constant(2 * n.half)};
    }

    std::vector<Node> nodes_;
    std::vector<int> stack_;
};

}  // namespace collision
