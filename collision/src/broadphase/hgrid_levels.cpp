// collision/src/broadphase/hgrid_levels.cpp -- hgrid's levels: each proxy's level, and the
// column grid of each level, planned both as a hierarchy and as one level (the cheaper kept).
#include "broadphase/hgrid.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>


namespace collision {

namespace {

// floor(log2(x)) for x >= 1 (and large for x = inf), from the exponent bits.
inline int floorLog2(Real x) {
    using Bits = std::conditional_t<sizeof(Real) == 8, std::uint64_t, std::uint32_t>;
    constexpr int kMantissa = std::numeric_limits<Real>::digits - 1;
    constexpr int kBias = std::numeric_limits<Real>::max_exponent - 1;
    constexpr Bits kMask = (Bits(1) << (sizeof(Real) * 8 - 1 - kMantissa)) - 1;
    return int((std::bit_cast<Bits>(x) >> kMantissa) & kMask) - kBias;
}

}  // namespace

void HierarchicalGrid::levelLane(Lane& lane, Real top) {
    // Level k has cells s_top / 2^(level_bits k) (8^k for hgrid); a box goes to the finest
    // level whose cells hold its extent. Zero-size boxes fit anywhere: marked here, they join
    // the finest level in use.
    std::array<Real, kMaxLevels> base_cell;
    for (int k = 0; k < kMaxLevels; ++k) base_cell[k] = std::ldexp(top, -level_bits_ * k);
    lane.extent_sum.fill(0);
    lane.members.fill(0);
    lane.zero_size = 0;
    lane.finest = 0;
    for (std::size_t p = lane.first; p < lane.last; ++p) {
        const Real e = extentOf(box_[p]);
        if (!(e > 0)) {
            level_of_[p] = kZeroSize;
            ++lane.zero_size;
            continue;
        }
        int k = std::min(floorLog2(top / e) / level_bits_, kMaxLevels - 1);
        while (k > 0 && base_cell[k] < e) --k;  // guard: cell >= extent
        level_of_[p] = static_cast<std::uint8_t>(k);
        lane.extent_sum[k] += e;
        ++lane.members[k];
        lane.finest = std::max(lane.finest, k);
    }
}

double HierarchicalGrid::planLevels(const std::array<std::size_t, kMaxLevels>& members,
                                    const std::array<Real, kMaxLevels>& extent_sum, int level_count,
                                    int level_bits, Real top, const Bounds& b, Plan& plan) {
    // Column grids: cells at least the level's own s_top / 8^k and twice its members' mean
    // extent (columns much wider than the boxes cost more candidates, much narrower ones more
    // entries per box: on the bench's uniform workload 1.11 ms/frame at the level's cell, 1.04
    // at twice the mean extent), widened (doubled) until a level has at most ~2 columns per
    // entry. Returns an estimate of the sweep's cost in candidate tests, entries counted as 3:
    // a level's entries spread evenly over its columns and over x, each entry of one of its
    // own members meets those that start within its x extent, each guest only the members.
    double cost = 0;
    std::size_t guests = 0;  // proxies of finer levels, entered as guests
    Real guest_extent = 0;   // their extents' sum
    for (int k = level_count - 1; k >= 0; --k) {
        Grid& lv = plan[k];
        lv.members = members[k];
        lv.guests = guests;
        if (lv.members == 0) continue;
        const std::size_t entries = lv.members + guests;
        const Real limit = std::max<Real>(64, 2 * Real(entries));
        const Real mean = extent_sum[k] / Real(lv.members);
        lv.cell = std::max(std::ldexp(top, -level_bits * k), kCellPerExtent * mean) *
                  (1 + std::ldexp(Real(1), -20));
        for (;;) {
            lv.inv_cell = 1 / lv.cell;
            const Real sy = (b.hi_y - b.lo_y) * lv.inv_cell;
            const Real sz = (b.hi_z - b.lo_z) * lv.inv_cell;
            if (!std::isfinite(sy) || !std::isfinite(sz) || lv.inv_cell == 0) {
                lv.ny = lv.nz = 1;  // coordinates beyond the range of a column index
                break;
            }
            const Real ny = std::floor(sy) + 1;
            const Real nz = std::floor(sz) + 1;
            if (ny * nz <= limit) {
                lv.ny = static_cast<std::int64_t>(ny);
                lv.nz = static_cast<std::int64_t>(nz);
                break;
            }
            lv.cell *= 2;
        }
        const double w = double(lv.cell);
        const double own_mean = double(mean);
        const double guest_mean = guests > 0 ? double(guest_extent) / double(guests) : 0;
        const double own = double(lv.members) * (1 + own_mean / w) * (1 + own_mean / w);
        const double visiting = double(guests) * (1 + guest_mean / w) * (1 + guest_mean / w);
        // Entries per column and unit of x, over the columns and the x range the boxes' centres
        // occupy (not the bounds, which a few huge boxes can stretch far beyond the rest).
        const auto across = [&](Real range) { return std::floor(double(range) / w) + 1; };
        const double per_x = 1 / (across(b.centre_span.y()) * across(b.centre_span.z()) *
                                  std::max(double(b.centre_span.x()), own_mean));
        if (std::isfinite(per_x)) {
            cost += own * own_mean * (own + visiting) * per_x + visiting * guest_mean * own * per_x;
        }
        cost += 3 * (own + visiting);
        // With guests the sweep first lists each column's own members (a guest scans only
        // those): one more pass over the level's entries. A handful of small boxes that would
        // make a level of their own and visit the one holding all the rest cost that pass there
        // and save next to nothing (Terdiman's BoxPruning scene: 17 of 10,000 boxes).
        if (guests > 0) cost += own + visiting;
        guests += lv.members;
        guest_extent += extent_sum[k];
    }
    return cost;
}

// Each level's members and extents gathered from the lanes, and the levels planned both ways
// (a hierarchy, or one level); the cheaper estimate is kept.
void HierarchicalGrid::chooseLevels(Real top, const Extents& x) {
    finest_ = 0;
    for (int t = 0; t < lane_count_; ++t) finest_ = std::max(finest_, lanes_[t].finest);
    level_count_ = finest_ + 1;
    std::array<Real, kMaxLevels> extent_sum{};
    std::array<std::size_t, kMaxLevels> members{};
    for (int k = 0; k < level_count_; ++k) {
        for (int t = 0; t < lane_count_; ++t) {
            members[k] += lanes_[t].members[k];
            extent_sum[k] += lanes_[t].extent_sum[k];
        }
    }
    for (int t = 0; t < lane_count_; ++t) members[finest_] += lanes_[t].zero_size;

    // The hierarchy pays off when one level's columns, as wide as its largest box, would hold
    // many much smaller boxes (a few huge boxes among many small ones); with sizes spread
    // evenly it costs more entries than it saves tests (measured on the bench's 1:100 and
    // 1:10^4 log-uniform mixes: one level 0.80 and 0.80 ms/frame at 10k, levels 8x apart 1.14
    // and 1.46). So the levels are planned both ways and the cheaper estimate is kept.
    const Bounds bounds{x.lo_y, x.hi_y, x.lo_z, x.hi_z, x.hi_c - x.lo_c};
    Plan levels_plan, flat_plan;
    const double levels_cost =
        planLevels(members, extent_sum, level_count_, level_bits_, top, bounds, levels_plan);
    flat_ = false;
    size_levels_ = level_count_;
    hierarchy_estimate_ = levels_cost;
    one_level_estimate_ = 0;
    if (level_count_ > 1 && level_plan_ == LevelPlan::Cheaper) {
        std::array<std::size_t, kMaxLevels> one{};
        std::array<Real, kMaxLevels> one_sum{};
        for (int k = 0; k < level_count_; ++k) {
            one[0] += members[k];
            one_sum[0] += extent_sum[k];
        }
        one_level_estimate_ = planLevels(one, one_sum, 1, level_bits_, top, bounds, flat_plan);
        flat_ = one_level_estimate_ <= levels_cost;
    }
    if (flat_) level_count_ = 1;
    const Plan& plan = flat_ ? flat_plan : levels_plan;
    for (int k = 0; k < level_count_; ++k) static_cast<Grid&>(levels_[k]) = plan[k];
}

}  // namespace collision
