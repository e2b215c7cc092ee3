// app/lab/bench/bench_method.h -- one broad phase as the benchmarks drive it: cdlab's registry entries and
// the peer libraries (Bullet, FCL) behind one small interface, listed by name.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "bench_workload.h"
#include "collision/broadphase/broad_phase.h"

namespace app {

/// A broad phase under benchmark. Proxy i is box i of the workload. A frame is moveAll() then
/// findPairs(); both are timed. Two figures are kept per frame: the pairs as the method holds
/// them (today's rule: a peer whose pair cache is a superset of the exact pairs, from fattened or
/// quantised boxes, is not charged for filtering it), and the exact pairs delivered, which adds
/// deliverExact() to the timed frame. summary() is never timed and checks the exact pairs.
class BenchMethod {
public:
    virtual ~BenchMethod() = default;
    /// Adds every box of `boxes` (volumes[i] is box i's). Called once.
    virtual void insertAll(const MovingBoxes& boxes,
                           std::span<const collision::ProxyVolumes> volumes) = 0;
    /// Gives every proxy its box at the workload's current frame.
    virtual void moveAll(const MovingBoxes& boxes,
                         std::span<const collision::ProxyVolumes> volumes) = 0;
    /// Finds the overlapping pairs of the current boxes.
    virtual void findPairs() = 0;
    /// Writes the exact pairs of the last findPairs() into a list of the method's own, as a caller
    /// would use them: a peer with a loose pair cache filters it with the exact boxes. Nothing to
    /// do for a method whose findPairs() already delivers exact pairs (cdlab's, FCL's callbacks).
    virtual void deliverExact(const MovingBoxes& /*boxes*/) {}
    /// The exact overlapping pairs found by the last findPairs().
    virtual PairSummary summary(const MovingBoxes& boxes) = 0;
    /// Pairs the method itself holds before exact filtering (its pair cache), or -1 when it
    /// reports exact pairs.
    virtual std::int64_t rawPairs() const { return -1; }
    /// Boxes the method kept in a potentially colliding set at the last findPairs() (cullide's
    /// visibility pruning), or -1 when it keeps none.
    virtual std::int64_t potentiallyColliding() const { return -1; }
};

struct BenchMethodEntry {
    std::string name;
    std::string description;
    bool peer = false;         ///< a Bullet or FCL configuration (the "best peer" is among these)
    bool default_set = false;  ///< run when no --methods is given
    /// Skipped in the default set from this many boxes on (0: never), with `skip_reason`.
    int default_max_n = 0;
    std::string skip_reason;
    /// Threads the method runs on. Thread CPU time (the default clock) would count only the
    /// calling thread's share of a method on more than one, so those run with --clock wall only.
    int threads = 1;
    /// The method also puts work on threads it does not own (cullide: llvmpipe rasterises on
    /// threads of its own). The thread's CPU clock would miss that work, so under --clock
    /// thread such a method is timed by the process's CPU time (every thread's) instead.
    bool foreign_threads = false;
    /// Peer configurations swept for the best: the peer (e.g. "bullet-dbvt") this entry is one
    /// configuration of, and the configuration ("m0.1:deferred"). Empty family: not swept.
    std::string family;
    std::string config;
    /// The method cannot run this many boxes or more (0: no limit), e.g. 16-bit handles.
    int hard_max_n = 0;
    std::function<std::unique_ptr<BenchMethod>()> create;
};

/// Every method the benchmarks know: the AABB-based cdlab registry entries, then the peer
/// configurations compiled in (none when Bullet and FCL were not found at configure time).
const std::vector<BenchMethodEntry>& benchMethods();
/// nullptr when there is no method of that name.
const BenchMethodEntry* findBenchMethod(std::string_view name);

/// Peer configurations, appended to benchMethods(); defined in bench_peers.cpp.
void appendPeerMethods(std::vector<BenchMethodEntry>& methods);
/// Terdiman's BoxPruning17 as `terdiman-v17` when configured with CDLAB_BOXPRUNING_DIR, else
/// nothing; defined in bench_boxpruning_peer.cpp.
void appendBoxPruningPeer(std::vector<BenchMethodEntry>& methods);

}  // namespace app
