// collision/src/broadphase/grid.h -- uniform grid and spatial hash.
#pragma once

#include <memory>
#include <vector>

#include "broadphase/cells.h"
#include "broadphase/proxy_table.h"
#include "collision/broadphase/broad_phase.h"

namespace collision {

/// Uniform-grid binning (RTCD 7.1; the lecture's "regular grid broad phase") rebuilt each frame
/// by a counting sort of (cell, proxy) entries. The cell size starts at twice the median AABB
/// extent; `Dense` doubles it until the grid has at most ~2n cells, `Hashed` (at most 4 times)
/// until at most 1/64 of the proxies are oversized.
///  - `Dense`: a bounded grid over the union of the AABBs with at most ~2n cells; cell indices
///    are clamped, so anything outside the grid lands in a border cell and is still found.
///  - `Hashed`: an unbounded grid whose cells are hashed into ~2x(entries) buckets (Teschner et
///    al. 2003); hash collisions only cost extra tests, since entries keep their true cell.
/// A pair is reported only from the cell holding the lowest corner of the two boxes'
/// intersection, so no duplicate removal is needed. Proxies that would cover more than
/// kMaxCellsPerProxy cells (huge size ratios) are not binned: each visits its cells (or, when
/// it covers more cells than there are entries, tests every proxy).
class GridBroadPhase : public RebuildingBroadPhase {
public:
    enum class Mode { Dense, Hashed };
    explicit GridBroadPhase(Mode mode) : mode_(mode) {}

    std::string_view name() const override { return mode_ == Mode::Dense ? "grid" : "hash"; }
    std::unique_ptr<BroadPhase> clone() const override {
        return std::make_unique<GridBroadPhase>(*this);
    }
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    void draw(DebugDraw& draw, const Aabb& bounds) const override;

    static constexpr std::int64_t kMaxCellsPerProxy = 64;

private:
    struct Entry {
        std::uint64_t bucket;
        CellCoord cell;
        ProxyId id;
    };
    CellCoord clampToGrid(const CellCoord& c) const;
    std::uint64_t bucketOf(const CellCoord& c) const;
    // The steps of findPairs, in order (grid.cpp); `inv` is 1 / cell_size_.
    void chooseCells();
    void binProxies(Real inv);
    void pairsInCells(Real inv, std::vector<ProxyPair>& pairs,
                      BroadPhaseCounters& counters) const;
    void pairsOfOversized(Real inv, std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters);

    Mode mode_;
    // Per-frame state, kept for reuse and for draw().
    Real cell_size_ = 1;
    Vec3 origin_ = Vec3::Zero();
    CellCoord dims_;  // dense: cells per axis
    std::uint64_t bucket_count_ = 0;
    std::vector<Entry> entries_;
    std::vector<Entry> sorted_;
    std::vector<std::uint32_t> bucket_start_;
    std::vector<ProxyId> big_;
    std::vector<char> is_big_;  // per proxy id, this frame
};

}  // namespace collision
