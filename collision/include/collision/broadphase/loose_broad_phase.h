// collision/broadphase/loose_broad_phase.h -- broad phases with a loose pair output: a superset
// of the overlapping pairs, as Bullet's pair cache holds, for a caller that tests the exact boxes
// itself (its narrow phase does anyway). Kept out of the registry, whose entries must equal brute
// force; the benchmarks compare them like for like with the peers' pair caches.
#pragma once

#include <memory>
#include <span>

#include "collision/broadphase/broad_phase.h"

namespace collision {

/// A broad phase that holds its loose pair list between frames. findPairs() copies the list out
/// as every broad phase does; updatePairs() brings it up to date without a copy and heldPairs()
/// reads it in place, as a caller of Bullet reads its pair cache after
/// calculateOverlappingPairs().
class LooseBroadPhase : public BroadPhase {
public:
    /// Brings the held pairs up to date with the proxies' current boxes: the work of findPairs()
    /// without writing a list.
    virtual void updatePairs(BroadPhaseCounters& counters) = 0;
    /// The held pairs as of the last updatePairs() or findPairs(): sorted by (a, b), unique,
    /// every overlapping pair among them. Valid until the next call that changes the broad phase
    /// (insert, remove, move, findPairs, updatePairs).
    virtual std::span<const ProxyPair> heldPairs() const = 0;
};

/// sap-packed whose findPairs writes its candidate pairs: every pair whose fat boxes (each
/// proxy's AABB grown by its motion margins and rounded outward to float) overlap, sorted by
/// (a, b), unique, without the exact confirm. Contains every pair whose AABBs overlap; the first
/// findPairs after an insert or remove uses no margins, so its extra pairs only touch within
/// float rounding. Same cost per frame as sap-packed less the exact test of each candidate;
/// updatePairs() and heldPairs() save the copy too.
std::unique_ptr<LooseBroadPhase> createLoosePackedSweepAndPrune();

}  // namespace collision
