// collision/src/broad_phase_hgrid.cpp -- hierarchical hash grid, rebuilt every frame.
// Completeness: let a, b overlap with level(a) <= level(b) = L. At level L both boxes are entered
// in (or looked up through) every cell their AABBs touch, and a point of their intersection lies
// in a cell both touch, so a's lookup at level L meets b. Pairs may be met in several shared
// cells; the final sort + unique removes the repeats.
#include "broad_phase_hgrid.h"

#include <algorithm>
#include <cmath>

#include "collision/debug_draw.h"

namespace collision {

void HierarchicalGrid::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    counters.volumes_updated += moved_;
    moved_ = 0;
    pairs.clear();
    entries_.clear();
    if (table_.count() == 0) return;

    // s0: the smallest non-zero extent, so the finest objects sit at level 0.
    Real smallest = std::numeric_limits<Real>::max();
    Real largest = 0;
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (!table_.contains(id)) continue;
        const Real e = table_[id].aabb.extents().maxCoeff();
        if (e > 0) smallest = std::min(smallest, e);
        largest = std::max(largest, e);
    }
    base_size_ = largest > 0 ? smallest : Real(1);
    // Keep the level count bounded for absurd ratios: coarsen the base instead.
    while (largest / base_size_ > std::ldexp(Real(1), kMaxLevels - 1)) base_size_ *= 2;

    level_of_.assign(static_cast<std::size_t>(table_.capacity()), -1);
    level_used_.assign(kMaxLevels, 0);
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (!table_.contains(id)) continue;
        const Aabb& box = table_[id].aabb;
        const Real e = box.extents().maxCoeff();
        int level = 0;
        while (level + 1 < kMaxLevels && cellSize(level) < e) ++level;
        level_of_[id] = level;
        level_used_[level] = 1;
        const Real inv = Real(1) / cellSize(level);
        const CellCoord lo = cellOf(box.min, inv);
        const CellCoord hi = cellOf(box.max, inv);
        for (std::int64_t z = lo.z; z <= hi.z; ++z) {
            for (std::int64_t y = lo.y; y <= hi.y; ++y) {
                for (std::int64_t x = lo.x; x <= hi.x; ++x) {
                    const CellCoord c{x, y, z};
                    entries_.push_back(Entry{hashCell(c, std::uint64_t(level)), c, level, id});
                }
            }
        }
    }
    bucket_count_ = nextPowerOfTwo(std::max<std::size_t>(2 * entries_.size(), 16));
    const std::uint64_t mask = bucket_count_ - 1;
    bucket_start_.assign(bucket_count_ + 1, 0);
    for (const Entry& e : entries_) ++bucket_start_[(e.hash & mask) + 1];
    for (std::size_t b = 0; b < bucket_count_; ++b) bucket_start_[b + 1] += bucket_start_[b];
    sorted_.resize(entries_.size());
    {
        std::vector<std::uint32_t> fill(bucket_start_.begin(), bucket_start_.end() - 1);
        for (const Entry& e : entries_) sorted_[fill[e.hash & mask]++] = e;
    }

    for (ProxyId a = 0; a < table_.capacity(); ++a) {
        if (!table_.contains(a)) continue;
        const Aabb& box = table_[a].aabb;
        const int own = level_of_[a];
        for (int level = own; level < kMaxLevels; ++level) {
            if (!level_used_[level]) continue;
            const Real inv = Real(1) / cellSize(level);
            const CellCoord lo = cellOf(box.min, inv);
            const CellCoord hi = cellOf(box.max, inv);
            for (std::int64_t z = lo.z; z <= hi.z; ++z) {
                for (std::int64_t y = lo.y; y <= hi.y; ++y) {
                    for (std::int64_t x = lo.x; x <= hi.x; ++x) {
                        const CellCoord c{x, y, z};
                        const std::uint64_t bucket = hashCell(c, std::uint64_t(level)) & mask;
                        for (std::uint32_t i = bucket_start_[bucket];
                             i < bucket_start_[bucket + 1]; ++i) {
                            const Entry& e = sorted_[i];
                            if (e.level != level || !(e.cell == c)) continue;
                            // Same level: each pair from its lower id only.
                            if (e.id == a || (level == own && e.id < a)) continue;
                            ++counters.volume_tests;
                            if (box.overlaps(table_[e.id].aabb)) {
                                pairs.push_back(a < e.id ? ProxyPair{a, e.id}
                                                         : ProxyPair{e.id, a});
                            }
                        }
                    }
                }
            }
        }
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void HierarchicalGrid::draw(DebugDraw& draw) const {
    // Occupied cells coloured by level: fine levels blue, coarse levels orange.
    for (const Entry& e : entries_) {
        const float t = std::min(1.0f, float(e.level) / 6.0f);
        const Color color{0.3f + 0.7f * t, 0.5f, 1.0f - 0.7f * t, 1};
        const Real s = cellSize(e.level);
        const Vec3 lo = Vec3(Real(e.cell.x), Real(e.cell.y), Real(e.cell.z)) * s;
        draw.drawAabb(Aabb{lo, lo + Vec3::Constant(s)}, color);
    }
}

}  // namespace collision
