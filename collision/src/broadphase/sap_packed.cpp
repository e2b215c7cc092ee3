// collision/src/broadphase/sap_packed.cpp -- box pruning on packed float bounds.
// Invariant after findPairs: every present proxy's exact AABB lies inside its fat box (fat_,
// floats), and candidates_ holds, sorted and once each, exactly the pairs whose fat boxes overlap
// (closed test). Why no pair is missed: a fat box is the double box grown by a margin >= 0 and
// rounded outward, so it contains the exact box, and two exact boxes that overlap have fat boxes
// that overlap; the pairs are the candidates that pass the exact double test. Between frames a
// pair whose two fat boxes did not change keeps its status, so only the boxes that left their
// fat box are re-queried and their old candidates dropped. The bands (band_, big_) hold the fat
// boxes as they were when last dealt; a box re-fattened since is stale (stale_),
// its band entry ignored and its current fat box kept in stale_lanes_ instead.
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

#include "broadphase/float_bounds.h"
#include "broadphase/interval_diagram.h"
#include "broadphase/radix_sort.h"
#include "collision/broadphase/loose_broad_phase.h"
#include "collision/debug_draw.h"

namespace collision {

using float_bounds::kFloatMax;
using float_bounds::kInf;

void PackedSweepAndPrune::insert(ProxyId id, const ProxyVolumes& v) {
    table_.insert(id, v);
    dirty_ = true;
}

void PackedSweepAndPrune::insertMany(ProxyId first, std::span<const ProxyVolumes> v) {
    table_.insertMany(first, v);
    dirty_ = true;
}

void PackedSweepAndPrune::insertBoxes(ProxyId first, std::span<const Aabb> boxes) {
    table_.insertBoxes(first, boxes);
    dirty_ = true;
}

void PackedSweepAndPrune::remove(ProxyId id) {
    table_.remove(id);
    dirty_ = true;
}

[[gnu::always_inline]] inline void PackedSweepAndPrune::moveBox(ProxyId id, const Aabb& box) {
    // How far the box moves per frame, remembered with a slow decay: the fattening margin. A
    // step that is not finite leaves the decayed value (>= 0, as every motion is).
    const Vec3 shift = (box.min + box.max - table_.aabb(id).min - table_.aabb(id).max) / 2;
    const Real step = shift.cwiseAbs().maxCoeff();
    if (static_cast<std::size_t>(id) < motion_.size()) {
        const float decayed = motion_[id] * kMotionDecay;
        const float capped = float(std::min<Real>(step, kFloatMax));
        motion_[id] = std::max(decayed, step < kInf ? capped : 0.0f);
    }
    table_.moveBox(id, box);
    ++moved_;
    // Whether it left its fat box, tested here while the box is at hand (a proxy set changed
    // since the last findPairs is rebuilt whole: nothing to note, and new ids have no fat box).
    if (dirty_) return;
    if (output_ == Output::Exact) setNear(id, box);
    const bool outside = !insideFat(id, box);
    if (outside && !escaped_flag_[id]) {
        escaped_flag_[id] = 1;
        escaped_.push_back(id);
    }
}

void PackedSweepAndPrune::move(ProxyId id, const ProxyVolumes& v) { moveBox(id, v.aabb); }

void PackedSweepAndPrune::moveBoxes(ProxyId first, std::span<const Aabb> boxes) {
    for (std::size_t i = 0; i < boxes.size(); ++i) {
        moveBox(first + static_cast<ProxyId>(i), boxes[i]);
    }
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
        const auto bits = static_cast<std::uint32_t>(k >> 32);
        // orderedBits inverted: a set top bit marks a non-negative float.
        const std::uint32_t f = (bits >> 31) ? (bits & 0x7FFFFFFFu) : ~bits;
        entries_[i] = Entry{std::bit_cast<float>(f), static_cast<ProxyId>(k & 0xFFFFFFFFu)};
    });
}

void PackedSweepAndPrune::sortEntries(BroadPhaseCounters& counters) {
    if (dirty_) {
        entries_.clear();
        for (ProxyId id = 0; id < table_.capacity(); ++id) {
            if (table_.contains(id)) entries_.push_back(Entry{fat_.min_x[id], id});
        }
        radixSortEntries();
        return;
    }
    for (Entry& e : entries_) e.key = fat_.min_x[e.id];
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

void PackedSweepAndPrune::Lanes::resize(std::size_t n) {
    for (std::vector<float>* v : {&min_x, &max_x, &min_y, &min_z, &neg_max_y, &neg_max_z}) {
        v->resize(n);
    }
}

void PackedSweepAndPrune::Lanes::copy(std::size_t to, const Lanes& from, std::size_t at) {
    min_x[to] = from.min_x[at];
    max_x[to] = from.max_x[at];
    min_y[to] = from.min_y[at];
    min_z[to] = from.min_z[at];
    neg_max_y[to] = from.neg_max_y[at];
    neg_max_z[to] = from.neg_max_z[at];
}

void PackedSweepAndPrune::Lanes::pad(std::size_t at) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::size_t k = at; k < at + kPad; ++k) {
        min_x[k] = max_x[k] = min_y[k] = min_z[k] = neg_max_y[k] = neg_max_z[k] = nan;
    }
}

void PackedSweepAndPrune::pack() {
    const std::size_t n = entries_.size();
    all_.resize(n + kPad);
    ids_.resize(n);
    float lo_y = kInf;
    float hi_y = -kInf;
    for (std::size_t i = 0; i < n; ++i) {
        const ProxyId id = entries_[i].id;
        all_.copy(i, fat_, static_cast<std::size_t>(id));
        lo_y = std::min(lo_y, all_.min_y[i]);
        hi_y = std::max(hi_y, -all_.neg_max_y[i]);
        ids_[i] = id;
    }
    all_.pad(n);
    lo_y_ = lo_y;
    hi_y_ = hi_y;
}

void PackedSweepAndPrune::resnapshot(BroadPhaseCounters& counters) {
    for (const ProxyId id : stale_ids_) stale_[id] = 0;
    stale_ids_.clear();
    stale_lanes_.resize(kPad);
    stale_lanes_.pad(0);
    sortEntries(counters);
    pack();
    dealBands();
}

void PackedSweepAndPrune::fullSweep(BroadPhaseCounters& counters) {
    resnapshot(counters);
    keys_.clear();
    sweepBands(counters);
    sweepBig(counters);
    radix::keysToSortedPairs(keys_, scratch_, shift_, candidates_, /*order_ids=*/true);
}

void PackedSweepAndPrune::rebuild() {
    const std::size_t capacity = static_cast<std::size_t>(table_.capacity());
    const std::size_t lanes = (capacity + 3) / 4 * 4 + kPad;
    fat_.resize(lanes);
    fat_.pad(capacity);  // NaN from capacity on; absent ids below are set here too
    for (std::size_t k = capacity; k < lanes; ++k) {
        fat_.min_x[k] = fat_.max_x[k] = fat_.min_y[k] = fat_.min_z[k] = fat_.neg_max_y[k] =
            fat_.neg_max_z[k] = std::numeric_limits<float>::quiet_NaN();
    }
    escaped_flag_.assign(capacity, 0);
    stale_.assign(capacity, 0);
    stale_ids_.clear();
    motion_.resize(capacity, 0);
    margin_.resize(capacity, 0);
    lead_velocity_.resize(capacity, Vec3::Zero());
    fat_centre_.resize(capacity, Vec3::Zero());
    fat_frame_.resize(capacity, 0);
    present_.clear();
    if (output_ == Output::Exact) near_.resize(capacity);
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (!table_.contains(id)) {
            const std::size_t k = static_cast<std::size_t>(id);
            fat_.min_x[k] = fat_.max_x[k] = fat_.min_y[k] = fat_.min_z[k] = fat_.neg_max_y[k] =
                fat_.neg_max_z[k] = std::numeric_limits<float>::quiet_NaN();
            continue;
        }
        present_.push_back(id);
        if (output_ == Output::Exact) setNear(id, table_.aabb(id));
        // Margins given to all boxes at once would run out at once, and again every lifetime
        // after (boxes moving steadily escape after about as many frames): each box's first
        // margin is a fraction of the full one, spread over (0, 1] by a hash of its id, so the
        // escapes spread evenly over the frames of a lifetime.
        const std::uint32_t hash = static_cast<std::uint32_t>(id) * 0x9E3779B9u;
        const float share = float((hash >> 8) + 1) * 0x1.0p-24f;
        fatten(id, margins_on_ ? share : 0.0f, false);
    }
    shift_ = radix::bitsFor(static_cast<std::uint64_t>(capacity) + 1);
}

void PackedSweepAndPrune::dealBands() {
    const std::size_t n = entries_.size();
    bands_ = 1;
    big_.clear();
    big_lanes_.resize(kPad);
    big_lanes_.pad(0);
    // Band width: a few median y extents (of a sample). Narrower bands give each box fewer x
    // candidates but put it in more bands, and leave shorter sweeps.
    const float span = hi_y_ - lo_y_;
    if (n >= 2 * kMinPerBand && std::isfinite(span) && span > 0) {
        sample_.clear();
        const std::size_t stride = std::max<std::size_t>(1, n / kSample);
        for (std::size_t i = 0; i < n; i += stride) {
            sample_.push_back(-all_.neg_max_y[i] - all_.min_y[i]);
        }
        const auto mid = sample_.begin() + static_cast<std::ptrdiff_t>(sample_.size() / 2);
        std::nth_element(sample_.begin(), mid, sample_.end());
        const float width = std::max(*mid * kBandWidth, span / float(kMaxBands));
        const std::size_t most = std::min<std::size_t>(kMaxBands, n / kMinPerBand);
        bands_ = static_cast<int>(std::clamp<float>(std::ceil(span / width), 1, float(most)));
    }
    if (bands_ == 1) {
        prefixMaxX(all_, 0, n, all_reach_);
        return;
    }
    band_lo_ = lo_y_;
    band_scale_ = float(bands_) / span;

    first_band_.resize(n);
    last_band_.resize(n);
    band_start_.assign(static_cast<std::size_t>(bands_) + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
        const int b0 = bandOf(all_.min_y[i]);
        const int b1 = bandOf(-all_.neg_max_y[i]);
        if (b1 - b0 >= kBigBands) {
            first_band_[i] = -1;
            big_.push_back(static_cast<std::uint32_t>(i));
            continue;
        }
        first_band_[i] = b0;
        last_band_[i] = b1;
        for (int b = b0; b <= b1; ++b) ++band_start_[static_cast<std::size_t>(b) + 1];
    }
    for (int b = 0; b < bands_; ++b) band_start_[b + 1] += band_start_[b] + kPad;  // sentinels
    const std::size_t total = band_start_[bands_];
    band_.resize(total);
    band_place_.resize(total);
    band_first_.resize(total);
    fill_.assign(band_start_.begin(), band_start_.end() - 1);
    // Dealt in sorted order, so every band is sorted on min x.
    for (std::size_t i = 0; i < n; ++i) {
        if (first_band_[i] < 0) continue;
        for (int b = first_band_[i]; b <= last_band_[i]; ++b) {
            const std::uint32_t k = fill_[b]++;
            band_.copy(k, all_, i);
            band_place_[k] = static_cast<std::uint32_t>(i);
            band_first_[k] = first_band_[i];
        }
    }
    big_lanes_.resize(big_.size() + kPad);
    for (std::size_t g = 0; g < big_.size(); ++g) big_lanes_.copy(g, all_, big_[g]);
    big_lanes_.pad(big_.size());
    band_reach_.resize(total);
    for (int b = 0; b < bands_; ++b) {
        const std::uint32_t at = band_start_[b + 1] - kPad;
        prefixMaxX(band_, band_start_[b], at, band_reach_);
        band_.pad(at);
        for (std::uint32_t k = at; k < at + kPad; ++k) {
            band_place_[k] = 0;
            band_first_[k] = 0;
        }
    }
}

void PackedSweepAndPrune::prefixMaxX(const Lanes& lanes, std::size_t begin, std::size_t end,
                                     std::vector<float>& reach) {
    // std::max(x, NaN) keeps x: a NaN bound neither raises nor spoils the running maximum.
    reach.resize(std::max(reach.size(), end));
    float most = -kInf;
    for (std::size_t i = begin; i < end; ++i) {
        most = std::max(most, lanes.max_x[i]);
        reach[i] = most;
    }
}

/// Sweeps the sorted boxes [begin, end) of `lanes` (followed by kPad NaN sentinels): for each
/// box, the boxes after it whose min x is within its x range get the y/z test, four at a time;
/// hit(i, j) sees the places of each pair whose float boxes overlap. Returns the tests made.
template <typename Hit>
std::int64_t PackedSweepAndPrune::sweepRange(const Lanes& lanes, std::size_t begin, std::size_t end,
                                             Hit&& hit) {
    const float* min_x = lanes.min_x.data();
    const float* max_x = lanes.max_x.data();
    const float* min_y = lanes.min_y.data();
    const float* min_z = lanes.min_z.data();
    const float* neg_max_y = lanes.neg_max_y.data();
    const float* neg_max_z = lanes.neg_max_z.data();
    std::int64_t tests = 0;
    for (std::size_t i = begin; i < end; ++i) {
        std::size_t j = i + 1;
#if defined(__SSE2__)
        // Box j overlaps box i when min x_j <= max x_i (min x_i <= min x_j by the sort),
        // min y_j <= max y_i, -max y_j <= -min y_i, and the same in z.
        const __m128 lim_x = _mm_set1_ps(max_x[i]);
        const __m128 lim_y = _mm_set1_ps(-neg_max_y[i]);
        const __m128 lim_z = _mm_set1_ps(-neg_max_z[i]);
        const __m128 lim_ny = _mm_set1_ps(-min_y[i]);
        const __m128 lim_nz = _mm_set1_ps(-min_z[i]);
        for (;; j += 4) {
            const __m128 in_x = _mm_cmple_ps(_mm_loadu_ps(min_x + j), lim_x);
            __m128 m = _mm_and_ps(in_x, _mm_cmple_ps(_mm_loadu_ps(min_y + j), lim_y));
            m = _mm_and_ps(m, _mm_cmple_ps(_mm_loadu_ps(min_z + j), lim_z));
            m = _mm_and_ps(m, _mm_cmple_ps(_mm_loadu_ps(neg_max_y + j), lim_ny));
            m = _mm_and_ps(m, _mm_cmple_ps(_mm_loadu_ps(neg_max_z + j), lim_nz));
            for (int bits = _mm_movemask_ps(m); bits != 0; bits &= bits - 1) {
                hit(i, j + static_cast<std::size_t>(std::countr_zero(unsigned(bits))));
            }
            // The boxes are sorted on min x (the sentinels are NaN): once one of the four is
            // past box i's end, so is every later one.
            if (_mm_movemask_ps(in_x) != 0xF) break;
        }
#else
        const float lim_x = max_x[i];
        for (; min_x[j] <= lim_x; ++j) {
            if (min_y[j] <= -neg_max_y[i] && min_z[j] <= -neg_max_z[i] &&
                neg_max_y[j] <= -min_y[i] && neg_max_z[j] <= -min_z[i]) {
                hit(i, j);
            }
        }
#endif
        tests += static_cast<std::int64_t>(j - i);
    }
    return tests;
}

void PackedSweepAndPrune::sweepBands(BroadPhaseCounters& counters) {
    if (bands_ == 1) {
        counters.volume_tests += sweepRange(
            all_, 0, entries_.size(), [this](std::size_t i, std::size_t j) { confirm(i, j); });
        return;
    }
    const std::uint32_t* place = band_place_.data();
    const int* first = band_first_.data();
    for (int b = 0; b < bands_; ++b) {
        counters.volume_tests += sweepRange(band_, band_start_[b], band_start_[b + 1] - kPad,
                                            [&](std::size_t i, std::size_t j) {
                                                // Report the pair only in the band of the larger
                                                // min y, max(first band of each), which both boxes
                                                // meet: both start at or before b, so one starts in
                                                // b.
                                                if (first[i] == b || first[j] == b)
                                                    confirm(place[i], place[j]);
                                            });
    }
}

void PackedSweepAndPrune::sweepBig(BroadPhaseCounters& counters) {
    if (big_.empty()) return;
    std::int64_t tests = 0;
    // A big box against every box after it in the sorted list (big or not)...
    for (const std::uint32_t g : big_) {
        tests +=
            sweepRange(all_, g, g + 1, [this](std::size_t i, std::size_t j) { confirm(i, j); });
    }
    // ...and every other box against the big boxes after it.
    const std::size_t n = entries_.size();
    std::size_t first = 0;  // the first big box after place p
    for (std::size_t p = 0; p < n; ++p) {
        while (first < big_.size() && big_[first] <= p) ++first;
        if (first == big_.size()) break;
        if (first_band_[p] < 0) continue;
        const float hi_x = all_.max_x[p];
        for (std::size_t q = first; q < big_.size() && all_.min_x[big_[q]] <= hi_x; ++q) {
            ++tests;
            const std::size_t g = big_[q];
            if (all_.min_y[g] <= -all_.neg_max_y[p] && all_.min_z[g] <= -all_.neg_max_z[p] &&
                all_.neg_max_y[g] <= -all_.min_y[p] && all_.neg_max_z[g] <= -all_.min_z[p]) {
                confirm(p, g);
            }
        }
    }
    counters.volume_tests += tests;
}

void PackedSweepAndPrune::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    if (output_ == Output::Loose) {
        // The candidates themselves, sorted and unique: a superset of the exact pairs.
        update(nullptr, counters);
        pairs.assign(candidates_.begin(), candidates_.end());
    } else if (!update(&pairs, counters)) {
        // The exact answer: every candidate (fat boxes overlap) tested as the double AABBs
        // decide (overlapsExactly).
        // Candidates are sorted, so the pairs are. Branch-free: every candidate is written, and
        // the count advances only for an overlap (about half the candidates do, so a branch
        // would be mispredicted as often as not).
        if (exact_.size() < candidates_.size()) exact_.resize(candidates_.size());
        ProxyPair* exact = exact_.data();
        std::size_t count = 0;
        for (const ProxyPair& p : candidates_) {
            exact[count] = p;
            count += static_cast<std::size_t>(overlapsExactly(p));
        }
        pairs.assign(exact, exact + count);
    }
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void PackedSweepAndPrune::updatePairs(BroadPhaseCounters& counters) {
    update(nullptr, counters);
    counters.pairs_flagged += static_cast<std::int64_t>(candidates_.size());
}

bool PackedSweepAndPrune::update(std::vector<ProxyPair>* exact, BroadPhaseCounters& counters) {
    counters.volumes_updated += moved_;
    moved_ = 0;
    ++frame_;
    bool exact_done = false;
    if (dirty_) {
        // A new proxy set: exact bounds (no margin) and a full sweep, the one-shot path.
        margins_on_ = false;
        retry_in_ = 1;
        rebuild();
        fullSweep(counters);
        dirty_ = false;
    } else {
        // escaped_ (flagged in escaped_flag_): the boxes that move() found outside their fat box.
        // Past this many escaped boxes, their sweep costs about as much as a full one.
        const std::size_t limit = present_.size() / kEscapeShare + 1;
        if (escaped_.empty()) {
        } else if (margins_on_ && escaped_.size() <= limit) {
            for (const ProxyId e : escaped_) fatten(e, 1.0f, true);
            restale();
            queryEscaped(exact, counters);
            exact_done = exact != nullptr;
            // The candidates are complete; once many boxes are stale, their list is long and
            // the bands are sorted and dealt again from the current fat boxes (no sweep).
            if (stale_ids_.size() > present_.size() / kStaleShare) resnapshot(counters);
        } else if (margins_on_ && escaped_.size() <= present_.size() / 2) {
            // Many escaped at once: re-fatten them and sweep every fat box. The others keep
            // theirs, so the escapes stay spread over frames.
            for (const ProxyId e : escaped_) fatten(e, 1.0f, true);
            fullSweep(counters);
        } else {
            // Most left their fat boxes: margins do not pay here (or not yet). Sweep
            // everything, now and then trying margins again.
            if (margins_on_) {
                margins_on_ = false;
                retry_in_ = kRetryFrames;
            } else if (--retry_in_ <= 0) {
                margins_on_ = true;
            }
            rebuild();
            fullSweep(counters);
        }
    }
    for (const ProxyId e : escaped_) escaped_flag_[e] = 0;
    escaped_.clear();
    return exact_done;
}

void PackedSweepAndPrune::draw(DebugDraw& draw, const Aabb& bounds) const {
    // The x intervals in the order of the last sort, as a 1-D interval diagram; the intervals
    // of proxies in an overlapping pair marked.
    const std::size_t n = entries_.size();
    if (n == 0 || dirty_) return;
    std::vector<DiagramInterval> intervals(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Aabb& box = table_.aabb(entries_[i].id);
        intervals[i] = DiagramInterval{box.min.x(), box.max.x(), false};
    }
    for (std::size_t i = 0; i < n; ++i) {
        const Aabb& box = table_.aabb(entries_[i].id);
        for (std::size_t j = i + 1; j < n && intervals[j].lo <= intervals[i].hi; ++j) {
            if (box.overlaps(table_.aabb(entries_[j].id))) {
                intervals[i].marked = intervals[j].marked = true;
            }
        }
    }
    const Color& color = kStructurePalette[0];
    const Color& marked = kStructurePalette[1];
    drawIntervalDiagram(draw, bounds, 0, intervals, color, marked);
    draw.legend("sap-packed intervals on x (the sort axis), sorted, " + intervalDiagramPlace(0),
                color);
    draw.legend("interval of a proxy in an overlapping pair", marked);
}

bool PackedSweepAndPrune::fatBoxesOverlap(ProxyId a, ProxyId b) const {
    const std::size_t i = static_cast<std::size_t>(a);
    const std::size_t j = static_cast<std::size_t>(b);
    if (dirty_ || !table_.contains(a) || !table_.contains(b)) return false;
    return fat_.min_x[i] <= fat_.max_x[j] && fat_.min_x[j] <= fat_.max_x[i] &&
           fat_.min_y[i] <= -fat_.neg_max_y[j] && fat_.min_y[j] <= -fat_.neg_max_y[i] &&
           fat_.min_z[i] <= -fat_.neg_max_z[j] && fat_.min_z[j] <= -fat_.neg_max_z[i];
}

std::string PackedSweepAndPrune::validate() const {
    if (dirty_) return {};
    if (entries_.size() != static_cast<std::size_t>(table_.count())) return "entry count mismatch";
    for (std::size_t i = 1; i < entries_.size(); ++i) {
        if (entries_[i].key < entries_[i - 1].key) return "entries out of order";
    }
    for (const Entry& e : entries_) {
        if (!table_.contains(e.id)) return "entry for an absent proxy";
        if (!escaped_flag_[e.id] && !insideFat(e.id)) return "a box outside its fat box";
        if (output_ == Output::Exact) {
            const Aabb& box = table_.aabb(e.id);
            const NearBox& n = near_[static_cast<std::size_t>(e.id)];
            for (int k = 0; k < 3; ++k) {
                // Compared as bits: a NaN bound must be copied as NaN too.
                if (std::bit_cast<std::uint32_t>(n.lo[k]) !=
                        std::bit_cast<std::uint32_t>(float(box.min[k])) ||
                    std::bit_cast<std::uint32_t>(n.hi[k]) !=
                        std::bit_cast<std::uint32_t>(float(box.max[k]))) {
                    return "a box's float copy is not its box rounded to nearest";
                }
            }
        }
    }
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
        const ProxyPair& p = candidates_[k];
        if (!(p.a < p.b)) return "a candidate (a, b) with a >= b";
        if (k > 0 && !(candidates_[k - 1] < p)) return "candidates unsorted or repeated";
        if (!fatBoxesOverlap(p.a, p.b)) return "a candidate whose fat boxes do not overlap";
    }
    return {};
}

std::unique_ptr<LooseBroadPhase> createLoosePackedSweepAndPrune() {
    return std::make_unique<PackedSweepAndPrune>(PackedSweepAndPrune::Output::Loose);
}

}  // namespace collision
