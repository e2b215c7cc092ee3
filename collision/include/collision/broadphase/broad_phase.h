// collision/broadphase/broad_phase.h -- the seam where broad phases are swapped, and their
// registry. A broad phase holds proxies (one per body, by id) with their bounding volumes and
// reports the candidate pairs whose volumes overlap. Every implementation reports the same pair set
// as its brute-force reference: pairs sorted by (a, b), a < b, no duplicates, touching counts;
// or, when its user asks for PairOrder::Found, the same pairs in the order it met them.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "collision/volumes/bounding_volumes.h"
#include "collision/volumes/volume_kind.h"

namespace collision {

class DebugDraw;

using ProxyId = std::int32_t;

/// A candidate pair; always a < b.
struct ProxyPair {
    ProxyId a = 0;
    ProxyId b = 0;
    friend bool operator==(const ProxyPair&, const ProxyPair&) = default;
    friend auto operator<=>(const ProxyPair&, const ProxyPair&) = default;
};

/// The order findPairs writes its pairs in.
enum class PairOrder {
    /// By (a, b): the default, the order every broad phase can be compared in with `==`.
    Sorted,
    /// The broad phase's own order: the same pairs, each as (a, b) with a < b, no duplicates, in
    /// the order its sweep met them, without a final sort. Deterministic: the same sequence of
    /// calls gives the same list. For a caller that needs the set, not the order. Only a broad
    /// phase whose registry row has `found_order` writes anything but sorted pairs (hgrid, and
    /// hgrid2 while it runs on one thread); every other one meets its pairs in sorted order or
    /// sorts them anyway, so it writes the same sorted list.
    Found,
};

/// "sorted" or "found".
std::string_view pairOrderName(PairOrder order);
/// The order of that name; nullopt for any other name.
std::optional<PairOrder> findPairOrder(std::string_view name);
/// "sorted, found", for error messages and --help.
std::string pairOrderNames();

/// The volumes a broad phase may look at. Each broad phase uses the one it is built on.
struct ProxyVolumes {
    Aabb aabb;
    BoundingSphere sphere;
    Obb obb;
};

/// The volumes of a proxy known only by its box: the box, its circumscribed sphere (the centre,
/// the half diagonal; each rounded once, so a corner may lie outside by a rounding error) and the
/// box as an axis-aligned OBB. What insertBoxes() and moveBoxes() give a broad phase that decides
/// on spheres or OBBs.
ProxyVolumes volumesOfBox(const Aabb& box);

/// Cost-model counters of one findPairs call (F = Nv·Cv + Np·Cp + Nu·Cu).
struct BroadPhaseCounters {
    std::int64_t volume_tests = 0;     ///< Nv: bounding-volume overlap tests made
    std::int64_t pairs_flagged = 0;    ///< pairs reported
    std::int64_t volumes_updated = 0;  ///< Nu: proxies whose volumes changed since the last call
    std::int64_t swaps = 0;            ///< insertion-sort swaps (SAP), 0 elsewhere
};

class BroadPhase {
public:
    virtual ~BroadPhase() = default;

    /// Registry name ("brute", "sphere", "sap", ...).
    virtual std::string_view name() const = 0;
    /// A copy holding the same proxies and the same coherence state (orders, fat boxes, trees,
    /// levels, pair order): the same calls on the two give the same pairs and counters. What
    /// World::snapshot keeps; a copy of a broad phase running on threads gets threads of its own.
    virtual std::unique_ptr<BroadPhase> clone() const = 0;
    /// Adds a proxy. `id` must not be present; ids need not be dense but should be small.
    virtual void insert(ProxyId id, const ProxyVolumes& volumes) = 0;
    /// Adds proxies first, first + 1, ..., one per entry of `volumes`, as insert() called for
    /// each in that order would; none of those ids may be present. Default: that loop. Broad
    /// phases that can take the boxes at once (growing their storage once) override it.
    virtual void insertMany(ProxyId first, std::span<const ProxyVolumes> volumes) {
        for (std::size_t i = 0; i < volumes.size(); ++i) {
            insert(first + static_cast<ProxyId>(i), volumes[i]);
        }
    }
    /// insertMany() for a caller that has boxes alone, as a contiguous array (a PhysX-style
    /// bounds array): proxies first, first + 1, ... get volumesOfBox(boxes[i]). A broad phase
    /// that decides on AABBs reads the boxes and builds no other volume. Default: insert() of
    /// each volumesOfBox.
    virtual void insertBoxes(ProxyId first, std::span<const Aabb> boxes);
    /// move() for every proxy of such an array: as move(first + i, volumesOfBox(boxes[i])) for
    /// each i in order would. The proxies must be present. Default: that loop. Broad phases that
    /// decide on AABBs override it to read the array in one pass, without a call per proxy.
    virtual void moveBoxes(ProxyId first, std::span<const Aabb> boxes);
    /// Removes a present proxy.
    virtual void remove(ProxyId id) = 0;
    /// Replaces a present proxy's volumes.
    virtual void move(ProxyId id, const ProxyVolumes& volumes) = 0;
    /// Writes every overlapping pair into `pairs` (cleared first), unique, a < b, sorted by
    /// (a, b) unless setPairOrder(PairOrder::Found) was called.
    virtual void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) = 0;
    /// The order the next findPairs calls write in (default Sorted). A broad phase without an
    /// order of its own (no `found_order` in its registry row) keeps writing sorted pairs.
    virtual void setPairOrder(PairOrder /*order*/) {}
    /// Draws the broad phase's own structure (cells, intervals, nodes) as it was at the last
    /// findPairs, in kStructurePalette colours, and names each colour with DebugDraw::legend.
    /// `bounds` is the box the picture frames (the world bounds): what has no place in space of
    /// its own (SAP's intervals on each axis) is laid out along its edges. Default: no lines,
    /// and a legend line saying the broad phase has no structure of its own to draw.
    virtual void draw(DebugDraw& draw, const Aabb& bounds) const;
    /// Proxies the last findPairs kept in a potentially colliding set before pairing them
    /// (CULLIDE's visibility pruning), or -1 for a method that keeps no such set.
    virtual std::int64_t potentiallyCollidingSize() const { return -1; }
    /// Checks internal invariants; returns an empty string when they hold, else what is broken.
    virtual std::string validate() const { return {}; }
};

/// One row of the registry: the scene loader and the CLI both look broad phases up here.
struct BroadPhaseEntry {
    std::string_view name;
    std::string_view description;
    VolumeKind volume;           ///< the volume it decides on
    std::string_view reference;  ///< name of the brute-force broad phase it must equal
    std::unique_ptr<BroadPhase> (*create)();
    int threads = 1;  ///< threads it runs on (timing it by thread CPU time needs 1)
    /// Needs a rendering context (a VisibilityOracle factory, see visibility_oracle.h): create()
    /// throws BroadPhaseUnavailable without one.
    bool needs_render_context = false;
    /// PairOrder::Found leaves out a final sort: its pairs come in an order of its own. Without
    /// this the found order is the sorted one.
    bool found_order = false;
};

std::span<const BroadPhaseEntry> broadPhaseRegistry();
/// nullptr when no broad phase has that name.
const BroadPhaseEntry* findBroadPhase(std::string_view name);
/// Comma-separated registry names, for error messages and --help.
std::string broadPhaseNames();

}  // namespace collision
