// collision/src/broad_phase_sphere.h -- bounding spheres, pruned by one sort along x.
#pragma once

#include <vector>

#include "collision/broad_phase.h"
#include "proxy_table.h"

namespace collision {

/// The coursework's bounding-sphere test (|c_a - c_b| <= r_a + r_b), with the pairs to test
/// found by sorting the spheres' x-intervals and sweeping: O(n log n + pairs whose x-intervals
/// overlap) instead of all pairs. Equals "sphere-brute" exactly: both apply the same test.
class SphereBroadPhase : public BroadPhase {
public:
    std::string_view name() const override { return "sphere"; }
    void insert(ProxyId id, const ProxyVolumes& v) override { table_.insert(id, v); }
    void remove(ProxyId id) override { table_.remove(id); }
    void move(ProxyId id, const ProxyVolumes& v) override {
        table_.move(id, v);
        ++moved_;
    }
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;

private:
    struct Item {
        Real lo;
        Real hi;
        ProxyId id;
    };
    ProxyTable table_{ProxyTable::kSphere};
    std::vector<Item> items_;
    std::int64_t moved_ = 0;
};

}  // namespace collision
