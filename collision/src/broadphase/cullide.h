// collision/src/broadphase/cullide.h -- CULLIDE: the potentially colliding set by visibility
// queries on a rasteriser, then the exact AABB test among what is left.
#pragma once

#include <memory>
#include <vector>

#include "broadphase/proxy_table.h"
#include "collision/visibility_oracle.h"

namespace collision {

/// Prunes every proxy whose AABB is fully visible with respect to all others in some view,
/// then reports the overlapping AABB pairs among the rest: the same pairs as `brute`.
class CullideBroadPhase : public RebuildingBroadPhase {
public:
    /// `oracle` must not be null.
    explicit CullideBroadPhase(std::unique_ptr<VisibilityOracle> oracle);

    std::string_view name() const override { return "cullide"; }
    std::unique_ptr<BroadPhase> clone() const override;
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;

    /// Proxies left in the potentially colliding set by the last findPairs, ascending.
    const std::vector<ProxyId>& potentiallyColliding() const { return pcs_; }
    std::int64_t potentiallyCollidingSize() const override {
        return static_cast<std::int64_t>(pcs_.size());
    }

private:
    /// The same proxies and scratch with an oracle of its own from the installed factory.
    CullideBroadPhase(const CullideBroadPhase& other);
    void pruneAlong(int axis, std::vector<char>& pruned);

    std::unique_ptr<VisibilityOracle> oracle_;
    std::vector<ProxyId> ids_;
    std::vector<Aabb> ndc_;
    std::vector<Aabb> ordered_;
    std::vector<char> forward_;
    std::vector<char> backward_;
    std::vector<ProxyId> pcs_;
};

/// The registry's constructor: throws BroadPhaseUnavailable when no oracle factory is installed.
std::unique_ptr<BroadPhase> createCullide();

}  // namespace collision
