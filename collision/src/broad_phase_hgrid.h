// collision/src/broad_phase_hgrid.h -- hierarchical grid (Mirtich, MERL TR-97-23, §2-2.2).
#pragma once

#include <vector>

#include "broad_phase_cells.h"
#include "collision/broad_phase.h"
#include "proxy_table.h"

namespace collision {

/// Hierarchical hash grid after Mirtich, "Efficient Algorithms for Two-Phase Collision
/// Detection" (TR-97-23 §2.2). Level L has cells of size s0 * 2^L, s0 = the smallest non-zero
/// AABB extent. Each proxy lives at the finest level whose cells are at least as large as its
/// AABB's largest extent, so it touches at most 2 x 2 x 2 cells there, and is entered in those
/// cells of one shared hash table keyed by (level, cell). Two boxes overlap only if they share a
/// cell at the coarser of their two levels (TR-97-23 §2.2), so each proxy looks itself up at its
/// own level (partners of higher id) and at every coarser occupied level. This keeps the cost per
/// proxy bounded whatever the size ratio (1:10^4 costs ~14 levels, not 10^12 cells).
class HierarchicalGrid : public BroadPhase {
public:
    std::string_view name() const override { return "hgrid"; }
    void insert(ProxyId id, const ProxyVolumes& v) override { table_.insert(id, v); }
    void remove(ProxyId id) override { table_.remove(id); }
    void move(ProxyId id, const ProxyVolumes& v) override {
        table_.move(id, v);
        ++moved_;
    }
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    void draw(DebugDraw& draw) const override;

    static constexpr int kMaxLevels = 48;

private:
    struct Entry {
        std::uint64_t hash;
        CellCoord cell;
        std::int32_t level;
        ProxyId id;
    };
    Real cellSize(int level) const { return std::ldexp(base_size_, level); }

    ProxyTable table_;
    std::int64_t moved_ = 0;
    Real base_size_ = 1;
    std::vector<std::int32_t> level_of_;
    std::vector<char> level_used_;
    std::vector<Entry> entries_;
    std::vector<Entry> sorted_;
    std::vector<std::uint32_t> bucket_start_;
    std::uint64_t bucket_count_ = 0;
};

}  // namespace collision
