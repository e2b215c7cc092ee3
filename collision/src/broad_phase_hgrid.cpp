// collision/src/broad_phase_hgrid.cpp -- hierarchical grid of sorted columns, rebuilt each frame.
// Completeness and uniqueness, same level: members' extents are <= the column width w (cells
// are s_top / 8^k, widened by 2^-20 so rounding of floor((v - o) / w) cannot split two values
// less than a cell apart by two columns); so overlapping a, b sit in columns at most one apart in
// y and in z. Each pair of such columns is swept once (sweepLevel), and the box of the pair
// that comes first in min x finds the other. Across levels: a at a finer level scans, in each coarser level j, the columns
// within that level's largest extent E_j of its box and the min-x window [min_a.x - E_j,
// max_a.x], widened by a few ulps; a pair across levels is found only from its finer member.
#include "broad_phase_hgrid.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>
#include <type_traits>
#include <sstream>

#include "collision/debug_draw.h"
#include "radix_sort.h"

namespace collision {

using radix::bitsFor;
using radix::orderedBits;
using radix::radixSortIndices;

std::int64_t HierarchicalGrid::column(const Level& level, int axis, Real v) const {
    const Real origin = axis == 1 ? level.origin_y : level.origin_z;
    const std::int64_t n = axis == 1 ? level.ny : level.nz;
    const Real c = std::floor((v - origin) / level.cell);
    return static_cast<std::int64_t>(std::clamp(c, Real(0), Real(n - 1)));
}

void HierarchicalGrid::buildLevel(Level& level, const std::vector<ProxyId>& members) {
    const std::size_t n = members.size();
    level.count = n;
    Real lo_y = std::numeric_limits<Real>::max(), hi_y = std::numeric_limits<Real>::lowest();
    Real lo_z = lo_y, hi_z = hi_y;
    level.top_extent = 0;
    for (ProxyId id : members) {
        const Aabb& b = table_.aabb(id);
        lo_y = std::min(lo_y, b.min.y());
        hi_y = std::max(hi_y, b.min.y());
        lo_z = std::min(lo_z, b.min.z());
        hi_z = std::max(hi_z, b.min.z());
        level.top_extent = std::max(level.top_extent, b.extents().maxCoeff());
    }
    level.origin_y = lo_y;
    level.origin_z = lo_z;
    // Widen the columns a little (see the file comment); at most ~2 columns per member, else
    // coarser columns (still >= every extent, so still correct).
    level.cell *= Real(1) + std::ldexp(Real(1), -20);
    const Real limit = std::max<Real>(64, 2 * Real(n));
    for (;;) {
        const Real ny = std::floor((hi_y - lo_y) / level.cell) + 1;
        const Real nz = std::floor((hi_z - lo_z) / level.cell) + 1;
        if (ny * nz <= limit) {
            level.ny = static_cast<std::int64_t>(ny);
            level.nz = static_cast<std::int64_t>(nz);
            break;
        }
        level.cell *= 2;
    }
    const std::size_t columns = static_cast<std::size_t>(level.ny * level.nz);

    // Sort by min x (stable over the id order members come in), then stably by column.
    sort_keys_.resize(n);
    order_.resize(n);
    column_of_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Aabb& b = table_.aabb(members[i]);
        sort_keys_[i] = orderedBits(b.min.x());
        order_[i] = static_cast<std::uint32_t>(i);
        column_of_[i] =
            static_cast<std::uint32_t>(column(level, 2, b.min.z()) * level.ny + column(level, 1, b.min.y()));
    }
    radixSortIndices(order_, order_scratch_, sort_keys_);
    level.start.assign(columns + 1, 0);
    for (std::size_t i = 0; i < n; ++i) ++level.start[column_of_[i] + 1];
    for (std::size_t c = 0; c < columns; ++c) level.start[c + 1] += level.start[c];
    level.id.resize(n);
    level.box.resize(n);
    for (std::uint32_t i : order_) {
        const std::uint32_t slot = level.start[column_of_[i]]++;
        const Aabb& b = table_.aabb(members[i]);
        level.id[slot] = members[i];
        level.box[slot] =
            PackedBox{b.min.x(), b.max.x(), b.min.y(), b.max.y(), b.min.z(), b.max.z()};
    }
    for (std::size_t c = columns; c > 0; --c) level.start[c] = level.start[c - 1];
    level.start[0] = 0;
}

namespace {

// The boxes of `from` in [q, end) whose min x lies within `a`'s x interval overlap `a` in x
// (their min x >= a's, by the sweep order); emit those that also overlap in y and z.
inline void scanForward(const HierarchicalGrid::PackedBox& a, ProxyId a_id,
                        const HierarchicalGrid::PackedBox* box, const ProxyId* ids,
                        std::uint32_t q, std::uint32_t end, int id_shift,
                        std::vector<std::uint64_t>& keys, std::int64_t& tests) {
    for (; q < end && box[q].min_x <= a.max_x; ++q) {
        ++tests;
        const HierarchicalGrid::PackedBox& b = box[q];
        const bool hit = (b.min_y <= a.max_y) & (a.min_y <= b.max_y) & (b.min_z <= a.max_z) &
                         (a.min_z <= b.max_z);
        if (hit) {
            const ProxyId b_id = ids[q];
            const ProxyId lo = std::min(a_id, b_id);
            const ProxyId hi = std::max(a_id, b_id);
            keys.push_back((std::uint64_t(lo) << id_shift) | std::uint64_t(hi));
        }
    }
}

}  // namespace

void HierarchicalGrid::sweepLevel(const Level& lv, BroadPhaseCounters& counters) {
    // Each unordered pair of columns at most one apart is visited once: a column with itself
    // (one sorted list swept forward), then with its four "forward" neighbours (+y; -y+z; +z;
    // +y+z) by merging the two sorted lists: whichever box comes first in min x (ties: the
    // column's own) scans the other list forward, so a pair is met exactly once, from the
    // box that starts first (Baraff 1992 sort and sweep, two lists at a time).
    const PackedBox* const box = lv.box.data();
    const ProxyId* const ids = lv.id.data();
    const std::uint32_t* const start = lv.start.data();
    std::int64_t tests = 0;  // a local, so the pushes below cannot force it through memory
    constexpr std::array<std::array<int, 2>, 4> kForward{{{1, 0}, {-1, 1}, {0, 1}, {1, 1}}};
    for (std::int64_t cz = 0; cz < lv.nz; ++cz) {
        for (std::int64_t cy = 0; cy < lv.ny; ++cy) {
            const std::int64_t c = cz * lv.ny + cy;
            const std::uint32_t c0 = start[c];
            const std::uint32_t c1 = start[c + 1];
            if (c0 == c1) continue;
            for (std::uint32_t i = c0; i < c1; ++i) {
                scanForward(box[i], ids[i], box, ids, i + 1, c1, id_shift_, keys_, tests);
            }
            for (const auto& [oy, oz] : kForward) {
                const std::int64_t dy = cy + oy;
                const std::int64_t dz = cz + oz;
                if (dy < 0 || dy >= lv.ny || dz >= lv.nz) continue;
                const std::int64_t d = dz * lv.ny + dy;
                std::uint32_t i = c0;
                std::uint32_t j = start[d];
                const std::uint32_t d1 = start[d + 1];
                while (i < c1 && j < d1) {
                    if (box[i].min_x <= box[j].min_x) {
                        scanForward(box[i], ids[i], box, ids, j, d1, id_shift_, keys_, tests);
                        ++i;
                    } else {
                        scanForward(box[j], ids[j], box, ids, i, c1, id_shift_, keys_, tests);
                        ++j;
                    }
                }
            }
        }
    }
    counters.volume_tests += tests;
}

void HierarchicalGrid::queryCoarser(const PackedBox& a, ProxyId a_id, const Level& lv,
                                    BroadPhaseCounters& counters) {
    const Real e = lv.top_extent;
    // A few ulps of the coordinates, so rounding never narrows the scanned window.
    const Real slack =
        4 * kEpsilon * (e + std::abs(a.min_x) + std::abs(a.min_y) + std::abs(a.min_z));
    const std::int64_t y0 = column(lv, 1, a.min_y - e - slack);
    const std::int64_t y1 = column(lv, 1, a.max_y);
    const std::int64_t z0 = column(lv, 2, a.min_z - e - slack);
    const std::int64_t z1 = column(lv, 2, a.max_z);
    const Real x_from = a.min_x - e - slack;
    const PackedBox* const box = lv.box.data();
    for (std::int64_t z = z0; z <= z1; ++z) {
        for (std::int64_t y = y0; y <= y1; ++y) {
            const std::int64_t d = z * lv.ny + y;
            const PackedBox* first = box + lv.start[d];
            const PackedBox* last = box + lv.start[d + 1];
            const PackedBox* q = std::partition_point(
                first, last, [x_from](const PackedBox& b) { return b.min_x < x_from; });
            for (; q < last && q->min_x <= a.max_x; ++q) {
                ++counters.volume_tests;
                const bool hit = (q->min_x <= a.max_x) & (a.min_x <= q->max_x) &
                                 (q->min_y <= a.max_y) & (a.min_y <= q->max_y) &
                                 (q->min_z <= a.max_z) & (a.min_z <= q->max_z);
                if (hit) {
                    const ProxyId b_id = lv.id[static_cast<std::size_t>(q - box)];
                    const ProxyId lo = std::min(a_id, b_id);
                    const ProxyId hi = std::max(a_id, b_id);
                    keys_.push_back((std::uint64_t(lo) << id_shift_) | std::uint64_t(hi));
                }
            }
        }
    }
}

void HierarchicalGrid::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    counters.volumes_updated += moved_;
    moved_ = 0;
    pairs.clear();
    level_count_ = 0;
    if (table_.count() == 0) return;

    // Levels: cells s_top / 8^k, down to the smallest extent (at most kMaxLevels).
    Real largest = 0;
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (table_.contains(id)) largest = std::max(largest, table_.aabb(id).extents().maxCoeff());
    }
    const Real top = largest > 0 ? largest : Real(1);
    for (auto& m : members_) m.clear();
    int finest = 0;
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (!table_.contains(id)) continue;
        const Real e = table_.aabb(id).extents().maxCoeff();
        int k = kMaxLevels - 1;  // zero-size boxes: the finest level
        if (e > 0) {
            int exponent = 0;
            std::frexp(top / e, &exponent);  // top / e in [2^(exponent-1), 2^exponent)
            k = std::clamp((exponent - 1) / kLevelBits, 0, kMaxLevels - 1);
            while (k > 0 && std::ldexp(top, -kLevelBits * k) < e) --k;  // guard: cell >= extent
        }
        members_[k].push_back(id);
        finest = std::max(finest, k);
    }
    level_count_ = finest + 1;
    for (int k = 0; k < level_count_; ++k) {
        levels_[k].cell = std::ldexp(top, -kLevelBits * k);
        levels_[k].count = 0;
        if (!members_[k].empty()) buildLevel(levels_[k], members_[k]);
    }

    // Pair keys pack (a, b) into 2 x id_shift_ bits, so the final radix sort makes as few
    // passes as the ids need (3 passes of 11 bits for up to 2^16 proxies).
    id_shift_ = bitsFor(static_cast<std::uint64_t>(table_.capacity()));
    keys_.clear();
    for (int k = 0; k < level_count_; ++k) {
        const Level& own = levels_[k];
        if (own.count == 0) continue;
        sweepLevel(own, counters);
        for (int j = k - 1; j >= 0; --j) {
            if (levels_[j].count == 0) continue;
            for (std::size_t i = 0; i < own.count; ++i) {
                queryCoarser(own.box[i], own.id[i], levels_[j], counters);
            }
        }
    }
    // (a, b) order: one radix sort of the packed keys.
    radix::keysToSortedPairs(keys_, scratch_, id_shift_, pairs);
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void HierarchicalGrid::draw(DebugDraw& draw) const {
    // Occupied columns' cells (one cell tall at each member), coloured by level: coarse levels
    // orange, fine levels blue.
    for (int k = 0; k < level_count_; ++k) {
        const Level& lv = levels_[k];
        const float t = level_count_ > 1 ? float(k) / float(level_count_ - 1) : 0.0f;
        const Color color{1.0f - 0.7f * t, 0.55f, 0.3f + 0.7f * t, 1};
        for (std::size_t i = 0; i < lv.count; ++i) {
            const PackedBox& b = lv.box[i];
            const Real y = lv.origin_y + Real(column(lv, 1, b.min_y)) * lv.cell;
            const Real z = lv.origin_z + Real(column(lv, 2, b.min_z)) * lv.cell;
            const Real x = std::floor(b.min_x / lv.cell) * lv.cell;
            const Vec3 lo(x, y, z);
            draw.drawAabb(Aabb{lo, lo + Vec3::Constant(lv.cell)}, color);
        }
    }
}

std::string HierarchicalGrid::validate() const {
    std::ostringstream out;
    std::size_t total = 0;
    for (int k = 0; k < level_count_; ++k) {
        const Level& lv = levels_[k];
        total += lv.count;
        for (std::size_t i = 0; i < lv.count; ++i) {
            const ProxyId id = lv.id[i];
            if (!table_.contains(id)) {
                out << "level " << k << " holds absent proxy " << id << "; ";
                continue;
            }
            if (table_.aabb(id).extents().maxCoeff() > lv.cell) {
                out << "proxy " << id << " larger than its level's cells; ";
            }
            if (i > 0 && lv.box[i].min_x < lv.box[i - 1].min_x &&
                column(lv, 1, lv.box[i].min_y) == column(lv, 1, lv.box[i - 1].min_y) &&
                column(lv, 2, lv.box[i].min_z) == column(lv, 2, lv.box[i - 1].min_z)) {
                out << "level " << k << " column out of x order at " << i << "; ";
            }
        }
    }
    if (level_count_ > 0 && total != static_cast<std::size_t>(table_.count())) {
        out << "levels hold " << total << " proxies of " << table_.count() << "; ";
    }
    return out.str();
}

}  // namespace collision
