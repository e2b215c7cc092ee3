// collision/src/broadphase/sap1.h -- single-axis sort and sweep on the axis of greatest spread.
#pragma once

#include <memory>
#include <vector>

#include "broadphase/proxy_table.h"
#include "collision/broadphase/broad_phase.h"

namespace collision {

/// Sort-and-sweep on one axis (Baraff 1992; RTCD 7.5.2), the axis chosen each frame as the one
/// along which the AABB centres vary most, so that the sweep sees the fewest overlapping
/// intervals. The sorted order persists between frames and is repaired by insertion sort while
/// the axis stays the same (O(n + swaps) under coherent motion); a change of axis or of the proxy
/// set re-sorts. Candidates from the sweep get the full AABB test.
class SortAndSweep1 : public BroadPhase {
public:
    std::string_view name() const override { return "sap1"; }
    std::unique_ptr<BroadPhase> clone() const override {
        return std::make_unique<SortAndSweep1>(*this);
    }
    void insert(ProxyId id, const ProxyVolumes& v) override;
    void remove(ProxyId id) override;
    void move(ProxyId id, const ProxyVolumes& v) override;
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    void draw(DebugDraw& draw, const Aabb& bounds) const override;
    std::string validate() const override;

private:
    struct Item {
        Real lo;
        Real hi;
        ProxyId id;
    };
    static bool before(const Item& x, const Item& y) {
        return x.lo != y.lo ? x.lo < y.lo : x.id < y.id;
    }
    int chooseAxis() const;

    ProxyTable table_;
    std::vector<Item> items_;
    int axis_ = -1;
    bool dirty_ = true;
    std::int64_t moved_ = 0;
};

}  // namespace collision
