// collision/src/broadphase/grid.cpp -- uniform grid and spatial hash, rebuilt every frame.
// Why each overlapping pair is reported exactly once: for overlapping boxes the lowest corner m
// of their intersection lies in both boxes, and cell indices are monotone in the coordinate
// (floor of a positive scaling, then a clamp), so the cell of m is in both boxes' cell ranges.
// Only that cell reports the pair.
#include "broadphase/grid.h"

#include <algorithm>
#include <cstdio>

#include "collision/debug_draw.h"

namespace collision {

CellCoord GridBroadPhase::clampToGrid(const CellCoord& c) const {
    if (mode_ == Mode::Hashed) return c;
    return CellCoord{std::clamp<std::int64_t>(c.x, 0, dims_.x - 1),
                     std::clamp<std::int64_t>(c.y, 0, dims_.y - 1),
                     std::clamp<std::int64_t>(c.z, 0, dims_.z - 1)};
}

std::uint64_t GridBroadPhase::bucketOf(const CellCoord& c) const {
    if (mode_ == Mode::Dense) {
        return static_cast<std::uint64_t>((c.z * dims_.y + c.y) * dims_.x + c.x);
    }
    return hashCell(c) & (bucket_count_ - 1);
}

// The cell size (and, dense, the grid's origin and dimensions) for this frame's proxies.
void GridBroadPhase::chooseCells() {
    cell_size_ = medianCellSize(table_);
    if (mode_ == Mode::Dense) {
        Aabb all{Vec3::Constant(std::numeric_limits<Real>::max()),
                 Vec3::Constant(std::numeric_limits<Real>::lowest())};
        for (ProxyId id = 0; id < table_.capacity(); ++id) {
            if (!table_.contains(id)) continue;
            all.min = all.min.cwiseMin(table_.aabb(id).min);
            all.max = all.max.cwiseMax(table_.aabb(id).max);
        }
        origin_ = all.min;
        // At most ~2n cells: a grid far larger than the population is mostly empty memory.
        // Doubling from any positive size reaches the extent of any finite box within ~2100
        // steps; infinite or NaN extents never fit, and get one cell holding every proxy (all
        // pairs tested: slow, but exact and finite).
        const Real limit = std::max<Real>(64, 2 * Real(table_.count()));
        constexpr int kMaxDoublings = 2200;
        dims_ = CellCoord{1, 1, 1};
        for (int k = 0; k < kMaxDoublings && std::isfinite(cell_size_); ++k) {
            const Vec3 d = (all.extents() / cell_size_).array().ceil().max(Real(1));
            if (d.prod() <= limit) {
                dims_ =
                    CellCoord{static_cast<std::int64_t>(d.x()), static_cast<std::int64_t>(d.y()),
                              static_cast<std::int64_t>(d.z())};
                break;
            }
            cell_size_ *= 2;
        }
        if (!all.min.allFinite()) origin_.setZero();
    } else {
        origin_.setZero();
        // Twice the median extent leaves a mixed 1:100 population with ~8 % oversized proxies,
        // each visiting hundreds of hashed cells, which at 1e5 bodies misses the cache on
        // nearly every lookup. Coarser cells (doubled at most kMaxDoublings times) until at
        // most 1/kOversizedShare of the proxies are oversized. Only sizes decide this, never
        // positions: far-away outliers, which the hash is for, do not coarsen the cells.
        constexpr int kMaxDoublings = 4;
        constexpr std::int64_t kOversizedShare = 64;
        for (int k = 0; k < kMaxDoublings; ++k) {
            const Real inv_try = Real(1) / cell_size_;
            std::int64_t oversized = 0;
            for (ProxyId id = 0; id < table_.capacity(); ++id) {
                if (!table_.contains(id)) continue;
                const Aabb& box = table_.aabb(id);
                const CellCoord lo = cellOf(box.min, inv_try);
                const CellCoord hi = cellOf(box.max, inv_try);
                oversized += !(cellCount(lo, hi) <= Real(kMaxCellsPerProxy));
            }
            if (oversized * kOversizedShare <= table_.count()) break;
            cell_size_ *= 2;
        }
    }
}

// Every proxy into the cells its AABB covers (oversized ones into big_ instead), then the entries
// sorted by bucket.
void GridBroadPhase::binProxies(Real inv) {
    // Bin every proxy into the cells its AABB covers.
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (!table_.contains(id)) continue;
        const Aabb& box = table_.aabb(id);
        const CellCoord lo = clampToGrid(cellOf(box.min - origin_, inv));
        const CellCoord hi = clampToGrid(cellOf(box.max - origin_, inv));
        if (!(cellCount(lo, hi) <= Real(kMaxCellsPerProxy))) {
            big_.push_back(id);
            continue;
        }
        for (std::int64_t z = lo.z; z <= hi.z; ++z) {
            for (std::int64_t y = lo.y; y <= hi.y; ++y) {
                for (std::int64_t x = lo.x; x <= hi.x; ++x) {
                    entries_.push_back(Entry{0, CellCoord{x, y, z}, id});
                }
            }
        }
    }
    bucket_count_ = mode_ == Mode::Dense
                        ? static_cast<std::uint64_t>(dims_.x * dims_.y * dims_.z)
                        : nextPowerOfTwo(std::max<std::size_t>(2 * entries_.size(), 16));
    for (Entry& e : entries_) e.bucket = bucketOf(e.cell);

    // Counting sort by bucket; stable, so entries keep proxy order within a bucket.
    bucket_start_.assign(bucket_count_ + 1, 0);
    for (const Entry& e : entries_) ++bucket_start_[e.bucket + 1];
    for (std::size_t b = 0; b < bucket_count_; ++b) bucket_start_[b + 1] += bucket_start_[b];
    sorted_.resize(entries_.size());
    {
        std::vector<std::uint32_t> fill(bucket_start_.begin(), bucket_start_.end() - 1);
        for (const Entry& e : entries_) sorted_[fill[e.bucket]++] = e;
    }
}

// Pairs of binned proxies sharing a cell, each reported by the cell that holds the corner of
// their overlap (the owner cell), so once.
void GridBroadPhase::pairsInCells(Real inv, std::vector<ProxyPair>& pairs,
                                  BroadPhaseCounters& counters) const {
    for (std::size_t b = 0; b < bucket_count_; ++b) {
        const std::uint32_t begin = bucket_start_[b];
        const std::uint32_t end = bucket_start_[b + 1];
        for (std::uint32_t i = begin; i < end; ++i) {
            const Entry& ei = sorted_[i];
            const Aabb& bi = table_.aabb(ei.id);
            for (std::uint32_t j = i + 1; j < end; ++j) {
                const Entry& ej = sorted_[j];
                if (!(ej.cell == ei.cell) || ej.id == ei.id) continue;
                ++counters.volume_tests;
                const Aabb& bj = table_.aabb(ej.id);
                if (!bi.overlaps(bj)) continue;
                const CellCoord owner = clampToGrid(cellOf(bi.min.cwiseMax(bj.min) - origin_, inv));
                if (owner == ei.cell) {
                    pairs.push_back(ei.id < ej.id ? ProxyPair{ei.id, ej.id}
                                                  : ProxyPair{ej.id, ei.id});
                }
            }
        }
    }
}

void GridBroadPhase::pairsOfOversized(Real inv, std::vector<ProxyPair>& pairs,
                                      BroadPhaseCounters& counters) {
    // Oversized proxies (more than kMaxCellsPerProxy cells) are not binned; each one visits
    // the cells it covers and meets the binned proxies there, with the same owner-cell rule
    // (the owner cell is in the binned proxy's cell range, so the pair is met exactly once).
    // Testing them against everyone instead made the mixed 1:100 workload quadratic (about a
    // tenth of the boxes oversized: 4.4 s/frame at 100k). A proxy covering more cells than
    // there are binned entries (1:10^4 size ratios) is tested against every proxy instead,
    // so its cost is min(cells, n). Oversized pairs among themselves: a sweep, below.
    is_big_.assign(static_cast<std::size_t>(table_.capacity()), 0);
    for (ProxyId id : big_) is_big_[static_cast<std::size_t>(id)] = 1;
    const Real cell_budget = Real(sorted_.size()) + 64;
    for (std::size_t k = 0; k < big_.size(); ++k) {
        const ProxyId b = big_[k];
        const Aabb& bb = table_.aabb(b);
        const CellCoord lo = clampToGrid(cellOf(bb.min - origin_, inv));
        const CellCoord hi = clampToGrid(cellOf(bb.max - origin_, inv));
        const Real cells = cellCount(lo, hi);
        if (cells > 0 && cells <= cell_budget) {
            for (std::int64_t z = lo.z; z <= hi.z; ++z) {
                for (std::int64_t y = lo.y; y <= hi.y; ++y) {
                    for (std::int64_t x = lo.x; x <= hi.x; ++x) {
                        const CellCoord c{x, y, z};
                        const std::uint64_t bucket = bucketOf(c);
                        for (std::uint32_t i = bucket_start_[bucket]; i < bucket_start_[bucket + 1];
                             ++i) {
                            const Entry& e = sorted_[i];
                            if (!(e.cell == c)) continue;
                            ++counters.volume_tests;
                            const Aabb& be = table_.aabb(e.id);
                            if (!bb.overlaps(be)) continue;
                            const CellCoord owner =
                                clampToGrid(cellOf(bb.min.cwiseMax(be.min) - origin_, inv));
                            if (owner == c) {
                                pairs.push_back(b < e.id ? ProxyPair{b, e.id} : ProxyPair{e.id, b});
                            }
                        }
                    }
                }
            }
        } else {
            for (ProxyId o = 0; o < table_.capacity(); ++o) {
                if (!table_.contains(o) || is_big_[static_cast<std::size_t>(o)]) continue;
                ++counters.volume_tests;
                if (bb.overlaps(table_.aabb(o))) {
                    pairs.push_back(b < o ? ProxyPair{b, o} : ProxyPair{o, b});
                }
            }
        }
    }
    // Oversized pairs among themselves by sort and sweep on x (a tenth of a mixed 1:100
    // population is oversized, so all pairs would be quadratic again). Closed intervals:
    // touching boxes are met.
    std::sort(big_.begin(), big_.end(), [this](ProxyId x, ProxyId y) {
        const Real ax = table_.aabb(x).min.x(), ay = table_.aabb(y).min.x();
        return ax < ay || (ax == ay && x < y);
    });
    for (std::size_t k = 0; k < big_.size(); ++k) {
        const ProxyId b = big_[k];
        const Aabb& bb = table_.aabb(b);
        for (std::size_t m = k + 1; m < big_.size(); ++m) {
            const ProxyId o = big_[m];
            const Aabb& bo = table_.aabb(o);
            if (bo.min.x() > bb.max.x()) break;
            ++counters.volume_tests;
            if (bb.overlaps(bo)) pairs.push_back(b < o ? ProxyPair{b, o} : ProxyPair{o, b});
        }
    }
}

void GridBroadPhase::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    countMoves(counters);
    pairs.clear();
    entries_.clear();
    big_.clear();
    if (table_.count() == 0) return;

    chooseCells();
    const Real inv = Real(1) / cell_size_;

    binProxies(inv);
    pairsInCells(inv, pairs, counters);
    pairsOfOversized(inv, pairs, counters);
    std::sort(pairs.begin(), pairs.end());
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void GridBroadPhase::draw(DebugDraw& draw, const Aabb& /*bounds*/) const {
    const Color& color = kStructurePalette[0];
    for (std::size_t i = 0; i < sorted_.size(); ++i) {
        if (i > 0 && sorted_[i].cell == sorted_[i - 1].cell) continue;
        const CellCoord& c = sorted_[i].cell;
        const Vec3 lo = origin_ + Vec3(Real(c.x), Real(c.y), Real(c.z)) * cell_size_;
        draw.drawAabb(Aabb{lo, lo + Vec3::Constant(cell_size_)}, color);
    }
    if (sorted_.empty()) return;
    char label[96];
    std::snprintf(label, sizeof label, "%s cells holding proxies, %.3g wide",
                  mode_ == Mode::Dense ? "grid" : "hash", double(cell_size_));
    draw.legend(label, color);
}

}  // namespace collision
