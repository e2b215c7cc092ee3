// collision/src/broadphase/hgrid.cpp -- hierarchical grid of sorted columns, rebuilt each frame.
// Completeness and uniqueness. Let a, b overlap, with a at level ka, b at level kb, and
// j = min(ka, kb) the coarser level. Both have an entry at level j (one is its own, the other
// its own or a guest), in every column of level j their boxes touch. The point
// p = (max(a.min_y, b.min_y), max(a.min_z, b.min_z)) lies in both boxes' (y, z) projections,
// and because column(v) is a non-decreasing function of v, p's column is
// (max of the two min-y columns, max of the two min-z columns): both boxes touch it, and it is
// the only column where each axis has one of the two entries at its own min column, i.e. where
// the flags' OR has bits 0 and 1 set. Bit 2 (one of them is at its own level) holds at level j
// only, since at a coarser level both are guests and at a finer one the coarser box is absent.
// In that one column the two entries are swept once, from whichever comes first in (min x, id):
// an own member scans every entry after it, a guest only the own members after it (two guests
// never need to meet there: they meet at the coarser of their own levels).
#include "broadphase/hgrid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "broadphase/radix_sort.h"
#include "collision/debug_draw.h"

namespace collision {

using radix::bitsFor;

namespace {

inline bool before(Real xa, std::uint32_t ia, Real xb, std::uint32_t ib) {
    return xa < xb || (xa == xb && ia < ib);
}

// Overlap of a fixed entry's (y, z) interval with others'; touching counts. With SSE2 and double
// coordinates, the four comparisons are two (min y, min z) <= (max y, max z) vector compares.
#if defined(__SSE2__) && !defined(CDLAB_USE_FLOAT)
template <typename T>
struct YzTestOf;
template <>
struct YzTestOf<double> {
    using Entry = HierarchicalGrid::Entry;
    explicit YzTestOf(const Entry& a) : lo(_mm_loadu_pd(&a.min_y)), hi(_mm_loadu_pd(&a.max_y)) {}
    bool overlaps(const Entry& b) const {
        const __m128d in = _mm_and_pd(_mm_cmple_pd(_mm_loadu_pd(&b.min_y), hi),
                                      _mm_cmple_pd(lo, _mm_loadu_pd(&b.max_y)));
        return _mm_movemask_pd(in) == 3;
    }
    __m128d lo, hi;
};
#endif

template <typename T>
struct YzTestOf {
    using Entry = HierarchicalGrid::Entry;
    explicit YzTestOf(const Entry& a) : a_(a) {}
    bool overlaps(const Entry& b) const {
        return (b.min_y <= a_.max_y) & (a_.min_y <= b.max_y) & (b.min_z <= a_.max_z) &
               (a_.min_z <= b.max_z);
    }
    const Entry& a_;
};
using YzTest = YzTestOf<Real>;

}  // namespace

HierarchicalGrid::HierarchicalGrid(bool two_threads, PairOrder order, LevelPlan plan)
    : level_plan_(plan),
      level_bits_(plan == LevelPlan::Hierarchy ? 1 : kLevelBits),
      pair_order_(order) {
    if (two_threads) helper_ = HelperSlot(true);
}

HierarchicalGrid::~HierarchicalGrid() = default;

std::int64_t HierarchicalGrid::column(const Level& lv, Real v, Real origin, std::int64_t n) const {
    if (n == 1) return 0;
    // v >= origin (the smallest min coordinate of all proxies), so the product is >= 0 and the
    // truncation is floor: non-decreasing in v, which is all the owner rule needs.
    // Compared before the cast: a value past the last column (huge, infinite or NaN) would make
    // the cast undefined.
    const Real c = (v - origin) * lv.inv_cell;
    if (!(c < Real(n - 1))) return n - 1;
    return static_cast<std::int64_t>(c);
}

HierarchicalGrid::Span HierarchicalGrid::span(const Level& lv, const Aabb& b) const {
    const std::int64_t y0 = column(lv, b.min.y(), origin_y_, lv.ny);
    const std::int64_t z0 = column(lv, b.min.z(), origin_z_, lv.nz);
    return Span{y0, z0, column(lv, b.max.y(), origin_y_, lv.ny) - y0,
                column(lv, b.max.z(), origin_z_, lv.nz) - z0};
}

void HierarchicalGrid::insert(ProxyId id, const ProxyVolumes& v) {
    RebuildingBroadPhase::insert(id, v);
    order_stale_ = true;
}

void HierarchicalGrid::insertMany(ProxyId first, std::span<const ProxyVolumes> v) {
    RebuildingBroadPhase::insertMany(first, v);
    order_stale_ = true;
}

void HierarchicalGrid::insertBoxes(ProxyId first, std::span<const Aabb> boxes) {
    RebuildingBroadPhase::insertBoxes(first, boxes);
    order_stale_ = true;
}

void HierarchicalGrid::remove(ProxyId id) {
    RebuildingBroadPhase::remove(id);
    order_stale_ = true;
}

std::int64_t HierarchicalGrid::fixColumns(const Level& lv, std::size_t from, std::size_t to) {
    // Each column is in (float(min x), id) order: restore (min x, id) by insertion sort. Only
    // boxes whose min x round to the same float can be out of order, so this is one comparison
    // per entry unless the coordinates are far larger than the boxes (1e6 with 1e-4 boxes);
    // past a budget of shifts a column is sorted outright, so that case stays O(m log m).
    Entry* const e = entries_.data() + lv.first;
    const auto less = [](const Entry& a, const Entry& b) {
        return before(a.min_x, a.id, b.min_x, b.id);
    };
    std::int64_t shifts = 0;
    for (std::size_t c = from; c < to; ++c) {
        const std::uint32_t c0 = lv.start[c];
        const std::uint32_t c1 = lv.start[c + 1];
        const std::size_t budget = 8 * std::size_t(c1 - c0) + 64;
        std::size_t column_shifts = 0;
        for (std::uint32_t i = c0 + 1; i < c1; ++i) {
            if (!less(e[i], e[i - 1])) continue;
            const Entry moving = e[i];
            std::uint32_t j = i;
            do {
                e[j] = e[j - 1];
                --j;
            } while (j > c0 && less(moving, e[j - 1]));
            e[j] = moving;
            column_shifts += i - j;
            if (column_shifts > budget) {
                std::sort(e + c0, e + c1, less);
                break;
            }
        }
        shifts += static_cast<std::int64_t>(column_shifts);
    }
    return shifts;
}

// Columns laid out level after level; returns the number of entries, and the number of columns
// in `flat_columns`.
std::size_t HierarchicalGrid::layoutColumns(std::size_t& flat_columns) {
    // Columns laid out level after level; within a column lane 0's entries come before lane
    // 1's, which keeps each column in (float(min x), id) order. Each lane's counts become its
    // cursors.
    std::size_t total = 0;
    flat_columns = 0;
    for (int k = 0; k < level_count_; ++k) {
        Level& lv = levels_[k];
        lv.first = total;
        lv.count = 0;
        lv.first_column = flat_columns;
        if (lv.members == 0) continue;
        const std::size_t columns = std::size_t(lv.ny * lv.nz);
        flat_columns += columns;
        lv.start.resize(columns + 1);
        std::uint32_t running = 0;
        for (std::size_t c = 0; c < columns; ++c) {
            lv.start[c] = running;
            for (int t = 0; t < lane_count_; ++t) {
                std::uint32_t& slot = lanes_[t].cursor[k][kCursorPad + c];
                const std::uint32_t here = slot;
                slot = running;
                running += here;
            }
        }
        lv.start[columns] = running;
        lv.count = running;
        total += lv.count;
    }
    return total;
}

void HierarchicalGrid::planChunks(std::size_t total, std::size_t flat_columns) {
    id_shift_ = bitsFor(static_cast<std::uint64_t>(table_.capacity()));
    chunks_.clear();
    chunks_.push_back(0);
    const std::size_t target = std::max<std::size_t>(total / 64, 1);
    std::size_t in_chunk = 0;
    for (int k = 0; k < level_count_; ++k) {
        const Level& lv = levels_[k];
        if (lv.members == 0) continue;
        for (std::size_t c = 0; c + 1 < lv.start.size(); ++c) {
            in_chunk += lv.start[c + 1] - lv.start[c];
            if (in_chunk >= target) {
                chunks_.push_back(lv.first_column + c + 1);
                in_chunk = 0;
            }
        }
    }
    if (chunks_.back() != flat_columns) chunks_.push_back(flat_columns);
    next_chunk_.store(0);
}

// The two lanes' sorted, disjoint pair lists merged into `pairs`, in two halves at once.
void HierarchicalGrid::mergeLanePairs(std::vector<ProxyPair>& pairs) {
    // Merged in two halves at once: the first half of the output takes the smallest
    // `half` pairs of the two lists, i of them from a and half - i from b, with i found by
    // binary search (the lists are disjoint, so the split is unique).
    const std::vector<ProxyPair>& a = lanes_[0].pairs;
    const std::vector<ProxyPair>& b = lanes_[1].pairs;
    const std::size_t total_pairs = a.size() + b.size();
    const std::size_t half = total_pairs / 2;
    std::size_t lo = half > b.size() ? half - b.size() : 0;
    std::size_t hi = std::min(half, a.size());
    while (lo < hi) {  // smallest i with a[i] > b[half - i - 1] (or i = min(half, |a|))
        const std::size_t i = (lo + hi) / 2;
        if (a[i] < b[half - i - 1]) {
            lo = i + 1;
        } else {
            hi = i;
        }
    }
    const std::size_t take_a = lo;
    pairs.resize(total_pairs);
    auto work = [&](int t) {
        if (t == 0) {
            std::merge(a.begin(), a.begin() + std::ptrdiff_t(take_a), b.begin(),
                       b.begin() + std::ptrdiff_t(half - take_a), pairs.begin());
        } else {
            std::merge(a.begin() + std::ptrdiff_t(take_a), a.end(),
                       b.begin() + std::ptrdiff_t(half - take_a), b.end(),
                       pairs.begin() + std::ptrdiff_t(half));
        }
    };
    helper_->runBoth(work);
}

void HierarchicalGrid::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    countMoves(counters);
    pairs.clear();
    level_count_ = 0;
    if (table_.count() == 0) return;
    const bool two_lanes = helper_ && std::size_t(table_.count()) >= kTwoLaneMinimum;
    if (two_lanes) helper_->prepare();  // wakes while this thread sorts
    sortByMinX();
    const std::size_t n = order_.size();
    level_of_.resize(n);

    // Lanes: lane 0 alone, or lanes 0 and 1 on two threads. Positions (for level finding,
    // counting and scattering) are split in two fixed halves, lane 0's first, and the sweep
    // takes chunks of columns; the output is the same however many lanes run.
    const int lanes = two_lanes ? 2 : 1;
    lane_count_ = lanes;
    for (int t = 0; t < lanes; ++t) {
        lanes_[t].first = n * std::size_t(t) / std::size_t(lanes);
        lanes_[t].last = n * std::size_t(t + 1) / std::size_t(lanes);
    }
    const auto inLanes = [&](auto&& work) {
        if (lanes == 1) {
            work(0);
        } else {
            helper_->runBoth(work);
        }
    };
    // Gathered by this thread alone: the table was just written here, by move(), and a helper
    // reading half of it from the other core made the pass slower than on one thread (10k
    // boxes: 75 against 38 us).
    const Extents x = gatherBoxes();
    const Real top = x.top;
    origin_y_ = x.lo_y;
    origin_z_ = x.lo_z;

    inLanes([this, top](int t) { levelLane(lanes_[t], top); });
    chooseLevels(top, x);

    inLanes([this](int t) { countLane(lanes_[t]); });

    std::size_t flat_columns = 0;
    const std::size_t total = layoutColumns(flat_columns);
    // Past the end: where each lane's branch-free scatter drops entries, 4 slots (224 bytes)
    // apart so that the two lanes never write one cache line.
    entries_.resize(total + 5);
    inLanes([this, total](int t) { scatterLane(lanes_[t], total + 4 * std::size_t(t)); });

    // Sweep: the columns, level after level, in chunks of about 1/64 of the entries, which the
    // lanes take in turn as they finish the last (column costs vary: a 1:100 size mix puts
    // more candidates per entry in its coarse columns). Which lane sweeps a chunk varies from
    // run to run; the pairs do not: each lane sorts its own, and the lists (disjoint: a pair is
    // found in one column) are merged.
    planChunks(total, flat_columns);
    if (lanes == 1) {
        sweepLane(lanes_[0], pairs);
    } else {
        inLanes([this](int t) { sweepLane(lanes_[t], lanes_[t].pairs); });
        mergeLanePairs(pairs);
    }
    for (int t = 0; t < lanes; ++t) {
        counters.volume_tests += lanes_[t].tests;
        counters.swaps += lanes_[t].swaps;
    }
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void HierarchicalGrid::countLane(Lane& lane) {
    // A box touches one or two columns per axis (its extent is at most the cell, widened by
    // 2^-20 so rounding cannot make it three in double); the common case runs without
    // branches on it. The columns found are kept for the scatter.
    for (int k = 0; k < level_count_; ++k) {
        const Level& lv = levels_[k];
        if (lv.members > 0) lane.cursor[k].assign(std::size_t(lv.ny * lv.nz) + 2 * kCursorPad, 0);
    }
    lane.placements.clear();
    for (std::size_t p = lane.first; p < lane.last; ++p) {
        const Aabb& b = box_[p];
        const int own = flat_ ? 0 : level_of_[p] == kZeroSize ? finest_ : level_of_[p];
        for (int k = 0; k <= own; ++k) {
            const Level& lv = levels_[k];
            if (lv.members == 0) continue;
            const Span s = span(lv, b);
            const std::int64_t c = s.z0 * lv.ny + s.y0;
            lane.placements.push_back(Placement{std::uint32_t(c), std::uint16_t(s.dy),
                                                std::uint16_t(s.dz), std::uint8_t(k),
                                                std::uint8_t(k == own)});
            std::uint32_t* const count = lane.cursor[k].data() + kCursorPad;
            if (s.dy <= 1 && s.dz <= 1) {
                count[c] += 1;
                count[c + s.dy] += std::uint32_t(s.dy);
                count[c + s.dz * lv.ny] += std::uint32_t(s.dz);
                count[c + s.dz * lv.ny + s.dy] += std::uint32_t(s.dy & s.dz);
                continue;
            }
            for (std::int64_t z = 0; z <= s.dz; ++z) {
                for (std::int64_t y = 0; y <= s.dy; ++y) ++count[c + z * lv.ny + y];
            }
        }
    }
}

void HierarchicalGrid::scatterLane(Lane& lane, std::size_t spare_slot) {
    // In (float(min x), id) order, so every column is nearly sorted by (min x, id).
    const Placement* placement = lane.placements.data();
    for (std::size_t p = lane.first; p < lane.last; ++p) {
        const std::uint32_t id = order_[p];
        const Aabb& b = box_[p];
        const Entry proto{b.min.x(), b.max.x(), b.min.y(), b.min.z(), b.max.y(), b.max.z(), id, 0};
        for (bool last = false; !last; ++placement) {
            const Placement& pl = *placement;
            last = pl.own;  // a box's own level comes last, after the coarser ones it visits
            const Level& lv = levels_[pl.level];
            Entry entry = proto;
            const std::uint32_t level_bit = std::uint32_t(pl.own) << 2;
            Entry* const out = entries_.data() + lv.first;
            std::uint32_t* const next = lane.cursor[pl.level].data() + kCursorPad;
            const std::uint32_t c = pl.column, dy = pl.dy, dz = pl.dz;
            if (dy <= 1 && dz <= 1) {
                // Four writes; those for columns the box does not touch go to the spare slot.
                const std::uint32_t spare = std::uint32_t(spare_slot - lv.first);
                const std::uint32_t row = dz * std::uint32_t(lv.ny);
                const std::uint32_t cells[4] = {c, c + dy, c + row, c + row + dy};
                const std::uint32_t used[4] = {1, dy, dz, dy & dz};
                const std::uint32_t flags[4] = {3, 2 | (1 - dy), 1 | (1 - dz) << 1,
                                                (1 - dy) | (1 - dz) << 1};
                for (int i = 0; i < 4; ++i) {
                    const std::uint32_t slot = next[cells[i]];
                    next[cells[i]] = slot + used[i];
                    entry.flags = flags[i] | level_bit;
                    // The slot or the spare one, chosen by a mask: written as `used ? slot :
                    // spare`, GCC branched on it, mispredicted about 0.8 times a box.
                    out[spare ^ ((slot ^ spare) & (0u - used[i]))] = entry;
                }
                continue;
            }
            for (std::uint32_t z = 0; z <= dz; ++z) {
                for (std::uint32_t y = 0; y <= dy; ++y) {
                    entry.flags = std::uint32_t(y == 0) | std::uint32_t(z == 0) << 1 | level_bit;
                    out[next[c + z * std::uint32_t(lv.ny) + y]++] = entry;
                }
            }
        }
    }
}

void HierarchicalGrid::sweepLane(Lane& lane, std::vector<ProxyPair>& pairs) {
    // Each entry scans forward while the next ones start within its x interval. Keys are
    // written unconditionally and kept when the pair counts (no branch on the outcome), so the
    // buffer always has room for the rest of the column.
    lane.tests = 0;
    lane.swaps = 0;
    const int shift = id_shift_;
    std::size_t count = 0;
    std::int64_t tests = 0;
    // Room for as many pairs as entries up front: growing from empty copied the keys several
    // times over in a one-shot frame.
    if (lane.keys.size() < entries_.size()) lane.keys.resize(entries_.size());
    for (;;) {
        const std::size_t chunk = next_chunk_.fetch_add(1);
        if (chunk + 1 >= chunks_.size()) break;
        const std::size_t flat_from = chunks_[chunk];
        const std::size_t flat_to = chunks_[chunk + 1];
        for (int k = 0; k < level_count_; ++k) {
            const Level& lv = levels_[k];
            if (lv.members == 0) continue;
            const std::size_t columns = lv.start.size() - 1;
            const std::size_t lo = std::max(flat_from, lv.first_column);
            const std::size_t hi = std::min(flat_to, lv.first_column + columns);
            if (lo >= hi) continue;
            const std::size_t from = lo - lv.first_column;
            const std::size_t to = hi - lv.first_column;
            lane.swaps += fixColumns(lv, from, to);
            const Entry* const e = entries_.data() + lv.first;
            const bool has_guests = lv.guests > 0;
            for (std::size_t c = from; c < to; ++c) {
                const std::uint32_t c0 = lv.start[c];
                const std::uint32_t c1 = lv.start[c + 1];
                if (c1 - c0 < 2) continue;
                // With guests, the column's own members in order: a guest scans only these
                // (guests meet each other at their own level), from a cursor that follows it.
                std::uint32_t* natives = nullptr;
                std::uint32_t native_count = 0;
                if (has_guests) {
                    lane.natives.resize(c1 - c0 + 1);
                    natives = lane.natives.data();
                    for (std::uint32_t i = c0; i < c1; ++i) {
                        natives[native_count] = i;
                        native_count += (e[i].flags >> 2) & 1u;
                    }
                    natives[native_count] = c1;  // sentinel
                }
                std::uint32_t next_native = 0;  // first native after the current entry
                for (std::uint32_t i = c0; i + 1 < c1; ++i) {
                    if (lane.keys.size() < count + (c1 - i)) {
                        lane.keys.resize(std::max(2 * lane.keys.size(), count + (c1 - i)) + 1024);
                    }
                    std::uint64_t* const out = lane.keys.data();
                    const Entry& a = e[i];
                    const YzTest yz(a);
                    if (has_guests) {
                        while (natives[next_native] <= i) ++next_native;
                        if ((a.flags & 4u) == 0) {
                            std::uint32_t r = next_native;
                            for (; natives[r] < c1 && e[natives[r]].min_x <= a.max_x; ++r) {
                                const Entry& b = e[natives[r]];
                                const bool hit = yz.overlaps(b) & ((a.flags | b.flags) == 7u);
                                out[count] = (std::uint64_t(a.id) << shift) | b.id;
                                count += hit;
                            }
                            tests += r - next_native;
                            continue;
                        }
                    }
                    std::uint32_t q = i + 1;
                    for (; q < c1 && e[q].min_x <= a.max_x; ++q) {
                        const Entry& b = e[q];
                        const bool hit = yz.overlaps(b) & ((a.flags | b.flags) == 7u);
                        out[count] = (std::uint64_t(a.id) << shift) | b.id;  // ordered later
                        count += hit;
                    }
                    tests += q - i - 1;
                }
            }
        }
    }
    lane.tests = tests;
    const std::span<std::uint64_t> keys(lane.keys.data(), count);
    if (pair_order_ == PairOrder::Found && lane_count_ == 1) {
        radix::keysToPairs(keys, shift, pairs);
        return;
    }
    // (a, b) order: one radix sort of the packed keys.
    radix::keysToSortedPairs(keys, lane.scratch, shift, pairs, /*order_ids=*/true);
}

void HierarchicalGrid::draw(DebugDraw& draw, const Aabb& /*bounds*/) const {
    // Each proxy's home cell at its own level (one cell tall at its min x), one colour per level.
    for (int k = 0; k < level_count_; ++k) {
        const Level& lv = levels_[k];
        if (lv.members == 0) continue;
        const Color color = structureColor(k);
        const Entry* const e = entries_.data() + lv.first;
        for (std::size_t c = 0; c + 1 < lv.start.size(); ++c) {
            const Real y = origin_y_ + Real(std::int64_t(c) % lv.ny) * lv.cell;
            const Real z = origin_z_ + Real(std::int64_t(c) / lv.ny) * lv.cell;
            for (std::uint32_t i = lv.start[c]; i < lv.start[c + 1]; ++i) {
                if (e[i].flags != 7u) continue;
                const Vec3 lo(std::floor(e[i].min_x / lv.cell) * lv.cell, y, z);
                draw.drawAabb(Aabb{lo, lo + Vec3::Constant(lv.cell)}, color);
            }
        }
        char label[96];
        std::snprintf(label, sizeof label,
                      "hgrid level %d: home cells of its %zu proxies, %.3g wide", k, lv.members,
                      double(lv.cell));
        draw.legend(label, color);
    }
    // Why there is one level, when there is.
    if (level_count_ != 1) return;
    char why[160];
    if (size_levels_ <= 1) {
        std::snprintf(why, sizeof why, "one level: every proxy within %dx of the largest extent",
                      1 << level_bits_);
    } else {
        std::snprintf(why, sizeof why,
                      "one level, not %d by size: est. %.3g tests vs %.3g (hgrid-levels keeps them)",
                      size_levels_, one_level_estimate_, hierarchy_estimate_);
    }
    draw.legend(why, structureColor(0));
}

std::string HierarchicalGrid::validate() const {
    std::ostringstream out;
    std::size_t homes = 0;
    for (int k = 0; k < level_count_; ++k) {
        const Level& lv = levels_[k];
        if (lv.members == 0) continue;
        const Entry* const e = entries_.data() + lv.first;
        for (std::size_t c = 0; c + 1 < lv.start.size(); ++c) {
            for (std::uint32_t i = lv.start[c]; i < lv.start[c + 1]; ++i) {
                if (!table_.contains(ProxyId(e[i].id))) {
                    out << "level " << k << " holds absent proxy " << e[i].id << "; ";
                    continue;
                }
                const Aabb& b = table_.aabb(ProxyId(e[i].id));
                if (e[i].min_x != b.min.x() || e[i].max_y != b.max.y()) {
                    out << "level " << k << " entry of proxy " << e[i].id << " is stale; ";
                }
                if ((e[i].flags & 4u) && extentOf(b) > lv.cell) {
                    out << "proxy " << e[i].id << " larger than its level's cells; ";
                }
                if (e[i].flags == 7u) ++homes;
                if (i > lv.start[c] && before(e[i].min_x, e[i].id, e[i - 1].min_x, e[i - 1].id)) {
                    out << "level " << k << " column " << c << " out of x order at " << i << "; ";
                }
            }
        }
    }
    if (level_count_ > 0 && homes != static_cast<std::size_t>(table_.count())) {
        out << "levels hold " << homes << " home entries for " << table_.count() << " proxies; ";
    }
    return out.str();
}

}  // namespace collision
