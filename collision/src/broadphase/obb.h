// collision/src/broadphase/obb.h -- OBB broad phase: an AABB sweep, then the separating axes.
#pragma once

#include <memory>
#include <vector>

#include "broadphase/proxy_table.h"
#include "collision/broadphase/broad_phase.h"

namespace collision {

/// Oriented boxes (Gottschalk, Lin, Manocha, "OBBTree", SIGGRAPH 1996 §4): candidates come from
/// a sort-and-sweep over each OBB's own enclosing AABB (which contains the OBB, unlike the
/// shape's AABB, so no OBB-overlapping pair is lost), then the 15-axis separating-axis test
/// decides. Equals "obb-brute", which applies the same test to every pair.
class ObbBroadPhase : public RebuildingBroadPhase {
public:
    ObbBroadPhase() : RebuildingBroadPhase(ProxyTable::kObb) {}

    std::string_view name() const override { return "obb"; }
    std::unique_ptr<BroadPhase> clone() const override {
        return std::make_unique<ObbBroadPhase>(*this);
    }
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    /// The sweep's sorted x-intervals as a 1-D interval diagram along the bounds' front bottom
    /// edge (interval_diagram.h), those of proxies in an overlapping pair marked.
    void draw(DebugDraw& draw, const Aabb& bounds) const override;

private:
    struct Item {
        Aabb box;
        ProxyId id;
    };
    std::vector<Item> items_;
};

}  // namespace collision
