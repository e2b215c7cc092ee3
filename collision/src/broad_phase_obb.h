// collision/src/broad_phase_obb.h -- OBB broad phase: an AABB sweep, then the separating axes.
#pragma once

#include <vector>

#include "collision/broad_phase.h"
#include "proxy_table.h"

namespace collision {

/// Oriented boxes (Gottschalk, Lin, Manocha, "OBBTree", SIGGRAPH 1996 §4): candidates come from
/// a sort-and-sweep over each OBB's own enclosing AABB (which contains the OBB, unlike the
/// shape's AABB, so no OBB-overlapping pair is lost), then the 15-axis separating-axis test
/// decides. Equals "obb-brute", which applies the same test to every pair.
class ObbBroadPhase : public BroadPhase {
public:
    std::string_view name() const override { return "obb"; }
    void insert(ProxyId id, const ProxyVolumes& v) override { table_.insert(id, v); }
    void remove(ProxyId id) override { table_.remove(id); }
    void move(ProxyId id, const ProxyVolumes& v) override {
        table_.move(id, v);
        ++moved_;
    }
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;

private:
    struct Item {
        Aabb box;
        ProxyId id;
    };
    ProxyTable table_{ProxyTable::kObb};
    std::vector<Item> items_;
    std::int64_t moved_ = 0;
};

}  // namespace collision
