// collision/src/broadphase/brute.h -- the references: every pair tested, O(n^2).
#pragma once

#include <memory>

#include "broadphase/proxy_table.h"
#include "collision/broadphase/broad_phase.h"
#include "collision/volumes/volume_kind.h"

namespace collision {

/// Tests every pair of present proxies with one volume kind. The ground truth every other broad
/// phase is compared against; never used for speed.
class BruteForceBroadPhase : public BroadPhase {
public:
    explicit BruteForceBroadPhase(VolumeKind volume)
        : volume_(volume),
          table_(volume == VolumeKind::Aabb     ? ProxyTable::kAabb
                 : volume == VolumeKind::Sphere ? ProxyTable::kSphere
                                                : ProxyTable::kObb) {}

    std::string_view name() const override;
    std::unique_ptr<BroadPhase> clone() const override {
        return std::make_unique<BruteForceBroadPhase>(*this);
    }
    void insert(ProxyId id, const ProxyVolumes& v) override { table_.insert(id, v); }
    void remove(ProxyId id) override { table_.remove(id); }
    void move(ProxyId id, const ProxyVolumes& v) override { table_.move(id, v); }
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    /// No lines: a legend line saying every pair is tested, and how many pairs that is.
    void draw(DebugDraw& draw, const Aabb& bounds) const override;

private:
    VolumeKind volume_;
    ProxyTable table_;
};

}  // namespace collision
