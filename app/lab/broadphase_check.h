// app/lab/broadphase_check.h -- `cdlab run --check-broadphase`: the registry's brute-force reference
// run beside the world's broad phase on the same volumes, every step.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "engine/world.h"

namespace app {

/// `expected` sorted, `got` sorted or in its broad phase's own order (PairOrder::Found). Empty
/// when `got` holds exactly the pairs of `expected`; else a report naming the missed and extra
/// pairs (at most 20 of each) with the bodies' ids and names.
std::string describePairMismatch(std::string_view name, std::string_view reference_name,
                                 std::span<const collision::ProxyPair> got,
                                 std::span<const collision::ProxyPair> expected,
                                 std::span<const engine::Body> bodies);

class BroadPhaseChecker {
public:
    /// `name` must be in the registry.
    explicit BroadPhaseChecker(const std::string& name);
    /// Feeds the world's current volumes to the reference; returns describePairMismatch(...).
    std::string check(const engine::World& world);

private:
    std::string reference_name_;
    std::unique_ptr<collision::BroadPhase> reference_;
    std::vector<collision::ProxyPair> expected_;
    std::size_t inserted_ = 0;
};

}  // namespace app
