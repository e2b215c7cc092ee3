// collision/src/broadphase/sphere.h -- bounding spheres, pruned by one sort along x.
#pragma once

#include <memory>
#include <vector>

#include "broadphase/proxy_table.h"
#include "collision/broadphase/broad_phase.h"

namespace collision {

/// The coursework's bounding-sphere test (|c_a - c_b| <= r_a + r_b), with the pairs to test
/// found by sorting the spheres' x-intervals and sweeping: O(n log n + pairs whose x-intervals
/// overlap) instead of all pairs. Equals "sphere-brute" exactly: both apply the same test.
class SphereBroadPhase : public RebuildingBroadPhase {
public:
    SphereBroadPhase() : RebuildingBroadPhase(ProxyTable::kSphere) {}

    std::string_view name() const override { return "sphere"; }
    std::unique_ptr<BroadPhase> clone() const override {
        return std::make_unique<SphereBroadPhase>(*this);
    }
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    /// The sweep's sorted x-intervals as a 1-D interval diagram along the bounds' front bottom
    /// edge (interval_diagram.h), those of proxies in an overlapping pair marked.
    void draw(DebugDraw& draw, const Aabb& bounds) const override;

private:
    struct Item {
        Real lo;
        Real hi;
        ProxyId id;
    };
    std::vector<Item> items_;
};

}  // namespace collision
