// collision/broadphase/loose_broad_phase.h -- broad phases with a loose pair output: a superset
// of the overlapping pairs, as Bullet's pair cache holds, for a caller that tests the exact boxes
// itself (its narrow phase does anyway). Kept out of the registry, whose entries must equal brute
// force; the benchmarks compare them like for like with the peers' pair caches.
#pragma once

#include <memory>

#include "collision/broadphase/broad_phase.h"

namespace collision {

/// sap-packed whose findPairs writes its candidate pairs: every pair whose fat boxes (each
/// proxy's AABB grown by its motion margins and rounded outward to float) overlap, sorted by
/// (a, b), unique, without the exact confirm. Contains every pair whose AABBs overlap; the first
/// findPairs after an insert or remove uses no margins, so its extra pairs only touch within
/// float rounding. Same cost per frame as sap-packed less the exact test of each candidate.
std::unique_ptr<BroadPhase> createLoosePackedSweepAndPrune();

}  // namespace collision
