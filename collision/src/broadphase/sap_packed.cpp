// collision/src/broadphase/sap_packed.cpp -- box pruning on packed float bounds.
// Invariant after findPairs: entries_ holds every present proxy once, sorted by key, and min_x_,
// max_x_, yz_, ids_ and exact_ are its bounds in that order. Why no pair is missed: each float
// bound is the double rounded outward, so the float box contains the double box and the float
// overlap test (closed, like Aabb::overlaps) accepts every pair the double test accepts; the
// double test then decides each candidate unless both float boxes are exact, when the two tests
// are the same comparisons.
#include "broadphase/sap_packed.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <span>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "broadphase/interval_diagram.h"
#include "broadphase/radix_sort.h"
#include "collision/debug_draw.h"

namespace collision {

namespace {

constexpr float kFloatMax = std::numeric_limits<float>::max();
constexpr float kInf = std::numeric_limits<float>::infinity();

/// The next float towards -infinity (f finite or +infinity).
float nextDown(float f) {
    if (f == 0) return -std::numeric_limits<float>::denorm_min();
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(f);
    return std::bit_cast<float>(f > 0 ? bits - 1 : bits + 1);
}

/// The largest float <= x (x finite). Doubles beyond the float range go to -/+infinity or
/// -/+FLT_MAX first: converting them would be undefined.
float roundDown(double x) {
    if (x > double(kFloatMax)) return kFloatMax;
    if (x < -double(kFloatMax)) return -kInf;
    const float f = static_cast<float>(x);
    return double(f) > x ? nextDown(f) : f;
}

/// The smallest float >= x (x finite).
float roundUp(double x) { return -roundDown(-x); }

}  // namespace

void PackedSweepAndPrune::insert(ProxyId id, const ProxyVolumes& v) {
    table_.insert(id, v);
    dirty_ = true;
}

void PackedSweepAndPrune::remove(ProxyId id) {
    table_.remove(id);
    dirty_ = true;
}

void PackedSweepAndPrune::move(ProxyId id, const ProxyVolumes& v) {
    table_.move(id, v);
    ++moved_;
}

void PackedSweepAndPrune::radixSortEntries() {
    // Key bits above, the id below: one LSD radix sort on the 32 key bits (Terdiman, "Radix Sort
    // Revisited", for floats as ordered integers).
    keys_.resize(entries_.size());
    for (std::size_t i = 0; i < entries_.size(); ++i) {
        keys_[i] = (radix::orderedBits(entries_[i].key) << 32) |
                   static_cast<std::uint32_t>(entries_[i].id);
    }
    radix::lsdRadixSort(keys_, scratch_, 32, 32, [&](std::size_t i, std::uint64_t k) {
        const ProxyId id = static_cast<ProxyId>(k & 0xFFFFFFFFu);
        entries_[i] = Entry{roundDown(table_.aabb(id).min.x()), id};
    });
}

void PackedSweepAndPrune::sortEntries(BroadPhaseCounters& counters) {
    if (dirty_) {
        entries_.clear();
        for (ProxyId id = 0; id < table_.capacity(); ++id) {
            if (table_.contains(id)) entries_.push_back(Entry{roundDown(table_.aabb(id).min.x()), id});
        }
        radixSortEntries();
        dirty_ = false;
        return;
    }
    for (Entry& e : entries_) e.key = roundDown(table_.aabb(e.id).min.x());
    // Insertion sort of last frame's order, abandoned for the radix sort once the swaps pass a
    // few per proxy (incoherent motion would make it quadratic).
    const std::int64_t limit = 4 * static_cast<std::int64_t>(entries_.size()) + 64;
    std::int64_t swaps = 0;
    for (std::size_t i = 1; i < entries_.size(); ++i) {
        const Entry x = entries_[i];
        std::size_t j = i;
        while (j > 0 && x.key < entries_[j - 1].key) {
            entries_[j] = entries_[j - 1];
            --j;
        }
        entries_[j] = x;
        swaps += static_cast<std::int64_t>(i - j);
        if (swaps > limit) {
            radixSortEntries();
            break;
        }
    }
    counters.swaps += swaps;
}

void PackedSweepAndPrune::pack() {
    const std::size_t n = entries_.size();
    min_x_.resize(n + 1);
    max_x_.resize(n + 1);
    yz_.resize(n);
    ids_.resize(n);
    exact_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const ProxyId id = entries_[i].id;
        const Aabb& box = table_.aabb(id);
        const float lo_x = entries_[i].key;
        const float hi_x = roundUp(box.max.x());
        const float lo_y = roundDown(box.min.y());
        const float lo_z = roundDown(box.min.z());
        const float hi_y = roundUp(box.max.y());
        const float hi_z = roundUp(box.max.z());
        min_x_[i] = lo_x;
        max_x_[i] = hi_x;
        yz_[i] = PackedYz{{lo_y, lo_z, -hi_y, -hi_z}};
        ids_[i] = id;
        exact_[i] = double(lo_x) == box.min.x() && double(hi_x) == box.max.x() &&
                    double(lo_y) == box.min.y() && double(lo_z) == box.min.z() &&
                    double(hi_y) == box.max.y() && double(hi_z) == box.max.z();
    }
    // No comparison with NaN is true: the sweep stops at the end without a bounds check.
    min_x_[n] = std::numeric_limits<float>::quiet_NaN();
    max_x_[n] = min_x_[n];
}

void PackedSweepAndPrune::dealBands() {
    const std::size_t n = entries_.size();
    bands_ = 1;
    big_.clear();
    // Band width: the median y extent (of a sample), which balances the entries a box adds to
    // each band it meets against the x candidates each entry meets.
    float lo = kInf;
    float hi = -kInf;
    for (std::size_t i = 0; i < n; ++i) {
        lo = std::min(lo, yz_[i].v[0]);
        hi = std::max(hi, -yz_[i].v[2]);
    }
    const float span = hi - lo;
    if (n >= 2 * kMinPerBand && std::isfinite(span) && span > 0) {
        sample_.clear();
        const std::size_t stride = std::max<std::size_t>(1, n / kSample);
        for (std::size_t i = 0; i < n; i += stride) sample_.push_back(-yz_[i].v[2] - yz_[i].v[0]);
        const auto mid = sample_.begin() + static_cast<std::ptrdiff_t>(sample_.size() / 2);
        std::nth_element(sample_.begin(), mid, sample_.end());
        const float width = std::max(*mid * kBandWidth, span / float(kMaxBands));
        const std::size_t most = std::min<std::size_t>(kMaxBands, n / kMinPerBand);
        bands_ = static_cast<int>(std::clamp<float>(std::ceil(span / width), 1, float(most)));
    }
    if (bands_ == 1) return;
    band_lo_ = lo;
    band_scale_ = float(bands_) / span;

    first_band_.resize(n);
    last_band_.resize(n);
    band_start_.assign(static_cast<std::size_t>(bands_) + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
        const int b0 = bandOf(yz_[i].v[0]);
        const int b1 = bandOf(-yz_[i].v[2]);
        if (b1 - b0 >= kBigBands) {
            first_band_[i] = -1;
            big_.push_back(static_cast<std::uint32_t>(i));
            continue;
        }
        first_band_[i] = b0;
        last_band_[i] = b1;
        for (int b = b0; b <= b1; ++b) ++band_start_[static_cast<std::size_t>(b) + 1];
    }
    for (int b = 0; b < bands_; ++b) band_start_[b + 1] += band_start_[b] + 1;  // + sentinel
    const std::size_t total = band_start_[bands_];
    band_min_x_.resize(total);
    band_max_x_.resize(total);
    band_yz_.resize(total);
    band_place_.resize(total);
    std::vector<std::uint32_t>& fill = scratch_fill_;
    fill.assign(band_start_.begin(), band_start_.end() - 1);
    // Dealt in sorted order, so every band is sorted on min x.
    for (std::size_t i = 0; i < n; ++i) {
        if (first_band_[i] < 0) continue;
        for (int b = first_band_[i]; b <= last_band_[i]; ++b) {
            const std::uint32_t k = fill[b]++;
            band_min_x_[k] = min_x_[i];
            band_max_x_[k] = max_x_[i];
            band_yz_[k] = yz_[i];
            band_place_[k] = static_cast<std::uint32_t>(i);
        }
    }
    for (int b = 0; b < bands_; ++b) {
        const std::uint32_t k = band_start_[b + 1] - 1;
        band_min_x_[k] = std::numeric_limits<float>::quiet_NaN();
        band_max_x_[k] = band_min_x_[k];
    }
}

namespace {

#if defined(__SSE2__)
using Yz = __m128;
/// (max y, max z, -min y, -min z) of the box whose packed bounds are `v`: its halves swapped,
/// negated. Another box overlaps it in y and z exactly when its packed bounds are <= these.
inline Yz otherOf(const float* v) {
    const __m128 own = _mm_load_ps(v);
    return _mm_xor_ps(_mm_shuffle_ps(own, own, _MM_SHUFFLE(1, 0, 3, 2)), _mm_set1_ps(-0.0f));
}
inline bool overlapsYz(const float* v, Yz other) {
    return _mm_movemask_ps(_mm_cmple_ps(_mm_load_ps(v), other)) == 0xF;
}
#else
struct Yz {
    float v[4];
};
inline Yz otherOf(const float* v) { return Yz{{-v[2], -v[3], -v[0], -v[1]}}; }
inline bool overlapsYz(const float* v, const Yz& o) {
    return v[0] <= o.v[0] && v[1] <= o.v[1] && v[2] <= o.v[2] && v[3] <= o.v[3];
}
#endif

}  // namespace

void PackedSweepAndPrune::sweepBands(BroadPhaseCounters& counters) {
    std::int64_t tests = 0;
    if (bands_ == 1) {
        const std::size_t n = entries_.size();
        for (std::size_t i = 0; i < n; ++i) {
            const float hi_x = max_x_[i];
            const Yz other = otherOf(yz_[i].v);
            for (std::size_t j = i + 1; min_x_[j] <= hi_x; ++j) {
                ++tests;
                if (overlapsYz(yz_[j].v, other)) confirm(i, j);
            }
        }
        counters.volume_tests += tests;
        return;
    }
    for (int b = 0; b < bands_; ++b) {
        const std::size_t end = band_start_[b + 1] - 1;
        for (std::size_t i = band_start_[b]; i < end; ++i) {
            const float hi_x = band_max_x_[i];
            const Yz other = otherOf(band_yz_[i].v);
            for (std::size_t j = i + 1; band_min_x_[j] <= hi_x; ++j) {
                ++tests;
                if (!overlapsYz(band_yz_[j].v, other)) continue;
                // Report the pair only in the band of the larger min y, which both boxes meet.
                const float lo_y = std::max(band_yz_[i].v[0], band_yz_[j].v[0]);
                if (bandOf(lo_y) == b) confirm(band_place_[i], band_place_[j]);
            }
        }
    }
    counters.volume_tests += tests;
}

void PackedSweepAndPrune::sweepBig(BroadPhaseCounters& counters) {
    if (big_.empty()) return;
    std::int64_t tests = 0;
    // A big box against every box after it in the sorted list (big or not)...
    for (const std::uint32_t g : big_) {
        const float hi_x = max_x_[g];
        const Yz other = otherOf(yz_[g].v);
        for (std::size_t j = g + 1; min_x_[j] <= hi_x; ++j) {
            ++tests;
            if (overlapsYz(yz_[j].v, other)) confirm(g, j);
        }
    }
    // ...and every other box against the big boxes after it.
    const std::size_t n = entries_.size();
    std::size_t first = 0;  // the first big box after place p
    for (std::size_t p = 0; p < n; ++p) {
        while (first < big_.size() && big_[first] <= p) ++first;
        if (first == big_.size()) break;
        if (first_band_[p] < 0) continue;
        const float hi_x = max_x_[p];
        const Yz other = otherOf(yz_[p].v);
        for (std::size_t q = first; q < big_.size() && min_x_[big_[q]] <= hi_x; ++q) {
            ++tests;
            if (overlapsYz(yz_[big_[q]].v, other)) confirm(p, big_[q]);
        }
    }
    counters.volume_tests += tests;
}

void PackedSweepAndPrune::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    counters.volumes_updated += moved_;
    moved_ = 0;
    sortEntries(counters);
    pack();
    dealBands();
    shift_ = radix::bitsFor(static_cast<std::uint64_t>(table_.capacity()) + 1);
    keys_.clear();
    sweepBands(counters);
    sweepBig(counters);
    radix::keysToSortedPairs(keys_, scratch_, shift_, pairs, /*order_ids=*/true);
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void PackedSweepAndPrune::draw(DebugDraw& draw, const Aabb& bounds) const {
    // The x intervals as the sweep saw them (float, rounded outward), sorted, as a 1-D interval
    // diagram; the intervals of proxies in an overlapping pair marked.
    const std::size_t n = entries_.size();
    if (n == 0 || ids_.size() != n) return;
    std::vector<DiagramInterval> intervals(n);
    for (std::size_t i = 0; i < n; ++i) {
        intervals[i] = DiagramInterval{Real(min_x_[i]), Real(max_x_[i]), false};
    }
    for (std::size_t i = 0; i < n; ++i) {
        const Aabb& box = table_.aabb(ids_[i]);
        for (std::size_t j = i + 1; j < n && min_x_[j] <= max_x_[i]; ++j) {
            if (box.overlaps(table_.aabb(ids_[j]))) intervals[i].marked = intervals[j].marked = true;
        }
    }
    const Color& color = kStructurePalette[0];
    const Color& marked = kStructurePalette[1];
    drawIntervalDiagram(draw, bounds, 0, intervals, color, marked);
    draw.legend("sap-packed float intervals on x (the sort axis), sorted, " +
                    intervalDiagramPlace(0),
                color);
    draw.legend("interval of a proxy in an overlapping pair", marked);
}

std::string PackedSweepAndPrune::validate() const {
    if (dirty_) return {};
    if (entries_.size() != static_cast<std::size_t>(table_.count())) return "entry count mismatch";
    for (std::size_t i = 1; i < entries_.size(); ++i) {
        if (entries_[i].key < entries_[i - 1].key) return "entries out of order";
    }
    for (const Entry& e : entries_) {
        if (!table_.contains(e.id)) return "entry for an absent proxy";
    }
    return {};
}

}  // namespace collision
