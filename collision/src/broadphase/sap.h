// collision/src/broadphase/sap.h -- three-axis sweep-and-prune with insertion-sort coherence.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "broadphase/pair_set.h"
#include "broadphase/proxy_table.h"
#include "collision/broadphase/broad_phase.h"

namespace collision {

/// Sweep-and-prune on AABBs (Cohen, Lin, Manocha, Ponamgi, I-COLLIDE, I3D 1995 §5.2).
/// Keeps one sorted endpoint list per axis from frame to frame; each frame re-sorts them by
/// insertion sort, which costs O(n + swaps) when motion is coherent. A swap that makes two
/// intervals start overlapping triggers a full AABB test and adds the pair; a swap that makes
/// them stop overlapping removes it. Insertions and removals trigger a full rebuild (sort plus
/// one sweep) at the next findPairs.
class SweepAndPrune : public BroadPhase {
public:
    std::string_view name() const override { return "sap"; }
    std::unique_ptr<BroadPhase> clone() const override {
        return std::make_unique<SweepAndPrune>(*this);
    }
    void insert(ProxyId id, const ProxyVolumes& v) override;
    void remove(ProxyId id) override;
    void move(ProxyId id, const ProxyVolumes& v) override;
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    void draw(DebugDraw& draw, const Aabb& bounds) const override;
    std::string validate() const override;

private:
    /// An interval end on one axis. At equal values mins sort before maxes, so touching
    /// intervals count as overlapping; then by id, so the order is total and deterministic.
    struct Endpoint {
        Real value;
        ProxyId id;
        bool is_max;
    };
    static bool before(const Endpoint& x, const Endpoint& y) {
        if (x.value != y.value) return x.value < y.value;
        if (x.is_max != y.is_max) return !x.is_max;
        return x.id < y.id;
    }
    static std::uint64_t key(ProxyId a, ProxyId b);

    void refreshValues();
    void rebuild(BroadPhaseCounters& counters);
    void insertionSort(int axis, BroadPhaseCounters& counters);

    ProxyTable table_;
    std::array<std::vector<Endpoint>, 3> axes_;
    PairSet pairs_;
    std::vector<std::uint64_t> keys_;
    std::vector<std::uint64_t> scratch_;
    std::vector<ProxyId> active_;
    bool dirty_ = true;
    std::int64_t moved_ = 0;
};

}  // namespace collision
