// collision/src/broadphase/sap_packed_fat.cpp -- sap-packed's coherence between frames: each
// box's fat box (led in the direction it moves, margin learnt from how far the last lead
// missed), and the look-ups of the boxes that left theirs, in the last dealt bands and in the
// list of boxes re-fattened since. The invariants are at the top of sap_packed.cpp.
#include <algorithm>
#include <cmath>
#include <span>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "broadphase/float_bounds.h"
#include "broadphase/radix_sort.h"
#include "broadphase/sap_packed.h"

namespace collision {

using float_bounds::roundDown;
using float_bounds::roundUp;

void PackedSweepAndPrune::fatten(ProxyId id, float share, bool learn) {
    // Margins as Box2D's dynamic tree fattens a moving proxy's box (Catto, Box2D: b2_aabbMargin
    // plus the predicted displacement): a margin on every side, and on the side each axis moves
    // towards a lead of kLead frames of the box's mean velocity over its last fat box's lifetime.
    // The margin is learnt from how far that lifetime's lead missed (twice the miss, at least
    // kMinMargin and at most kMargin times the recent step): a box moving steadily is led and
    // gets a thin margin, one jittering about a place no lead and the full margin. A box whose
    // mean speed over the lifetime is about its step per frame (kSteady) moves steadily: it is
    // led twice as far (kSteadyLead), so it escapes half as often, and a large miss of its lead
    // is a turn (a bounce), which the next lead follows, so its margin stays at most
    // kSteadyMargin steps (a full one would hold every neighbour of its long lead for a
    // lifetime). A random walk's mean speed falls as its lifetime grows: it keeps the full
    // margin and the short lead. Without a lifetime to learn from (a rebuild) the margin is
    // full and there is no lead.
    const Aabb& box = table_.aabb(id);
    const std::size_t k = static_cast<std::size_t>(id);
    if (share == 0) {
        // No margins (the one-shot path): nothing to lead or learn from; the next fat box
        // with margins is made by a rebuild, which learns nothing either.
        setFat(k, box.min.x(), box.min.y(), box.min.z(), box.max.x(), box.max.y(), box.max.z());
        return;
    }
    const Vec3 centre = (box.min + box.max) / 2;
    const Real step = motion_[k];
    bool steady = false;
    if (learn && frame_ > fat_frame_[k]) {
        const Real lived = Real(frame_ - fat_frame_[k]);
        const Vec3 moved = centre - fat_centre_[k];
        const Real miss = (moved - lived * lead_velocity_[k]).cwiseAbs().maxCoeff();
        const Vec3 velocity = moved / lived;
        steady = velocity.cwiseAbs().maxCoeff() >= kSteady * step;
        const Real most = steady ? kSteadyMargin : kMargin;
        margin_[k] = std::isfinite(miss)
                         ? std::clamp<Real>(2 * miss, kMinMargin * step, most * step)
                         : kMargin * step;
        lead_velocity_[k] = velocity.allFinite() ? velocity : Vec3::Zero();
    } else {
        margin_[k] = kMargin * step;
        lead_velocity_[k] = Vec3::Zero();
    }
    fat_centre_[k] = centre;
    fat_frame_[k] = frame_;
    const Real base = Real(share) * margin_[k];
    const Vec3 led = Real(share) * (steady ? kSteadyLead : kLead) * lead_velocity_[k];
    const Vec3 lead = led.allFinite() ? led : Vec3::Zero();
    setFat(k, box.min.x() - (base + std::max<Real>(0, -lead.x())),
           box.min.y() - (base + std::max<Real>(0, -lead.y())),
           box.min.z() - (base + std::max<Real>(0, -lead.z())),
           box.max.x() + (base + std::max<Real>(0, lead.x())),
           box.max.y() + (base + std::max<Real>(0, lead.y())),
           box.max.z() + (base + std::max<Real>(0, lead.z())));
}

void PackedSweepAndPrune::setFat(std::size_t k, Real lo_x, Real lo_y, Real lo_z, Real hi_x,
                                 Real hi_y, Real hi_z) {
    fat_.min_x[k] = roundDown(lo_x);
    fat_.max_x[k] = roundUp(hi_x);
    fat_.min_y[k] = roundDown(lo_y);
    fat_.min_z[k] = roundDown(lo_z);
    fat_.neg_max_y[k] = -roundUp(hi_y);
    fat_.neg_max_z[k] = -roundUp(hi_z);
}


std::size_t PackedSweepAndPrune::queryRange(const Lanes& lanes, std::size_t j,
                                            const float (&box)[6], bool stop_past_x,
                                            std::uint32_t* hits, std::int64_t& tests) {
    // box: min x, max x, min y, max y, min z, max z. From place j (a multiple of nothing in
    // particular), four lanes at a time, to the first group holding a box past max x
    // (stop_past_x: the lanes are sorted on min x) or a NaN sentinel. Each group's four places
    // are written and kept by their overlap bits, with no branch on them: whether a group holds
    // a hit is data, and branching on it was the look-ups' most mispredicted branch (callgrind,
    // 10k mixed: over a third of queryEscaped's mispredictions).
    std::size_t count = 0;
#if defined(__SSE2__)
    const __m128 hi_x = _mm_set1_ps(box[1]);
    const __m128 lo_x = _mm_set1_ps(box[0]);
    const __m128 hi_y = _mm_set1_ps(box[3]);
    const __m128 hi_z = _mm_set1_ps(box[5]);
    const __m128 neg_lo_y = _mm_set1_ps(-box[2]);
    const __m128 neg_lo_z = _mm_set1_ps(-box[4]);
    for (;; j += 4) {
        const __m128 min_x = _mm_loadu_ps(lanes.min_x.data() + j);
        const __m128 in_x = _mm_cmple_ps(min_x, hi_x);
        __m128 m = _mm_and_ps(in_x, _mm_cmple_ps(lo_x, _mm_loadu_ps(lanes.max_x.data() + j)));
        m = _mm_and_ps(m, _mm_cmple_ps(_mm_loadu_ps(lanes.min_y.data() + j), hi_y));
        m = _mm_and_ps(m, _mm_cmple_ps(_mm_loadu_ps(lanes.min_z.data() + j), hi_z));
        m = _mm_and_ps(m, _mm_cmple_ps(_mm_loadu_ps(lanes.neg_max_y.data() + j), neg_lo_y));
        m = _mm_and_ps(m, _mm_cmple_ps(_mm_loadu_ps(lanes.neg_max_z.data() + j), neg_lo_z));
        tests += 4;
        const auto bits = static_cast<unsigned>(_mm_movemask_ps(m));
        for (unsigned k = 0; k < 4; ++k) {
            hits[count] = static_cast<std::uint32_t>(j + k);
            count += (bits >> k) & 1u;
        }
        const int x_bits = _mm_movemask_ps(stop_past_x ? in_x : _mm_cmpord_ps(min_x, min_x));
        if (x_bits != 0xF) break;
    }
#else
    for (; stop_past_x ? lanes.min_x[j] <= box[1] : lanes.min_x[j] == lanes.min_x[j]; ++j) {
        ++tests;
        hits[count] = static_cast<std::uint32_t>(j);
        count += box[0] <= lanes.max_x[j] && lanes.min_x[j] <= box[1] &&
                 lanes.min_y[j] <= box[3] && lanes.min_z[j] <= box[5] &&
                 lanes.neg_max_y[j] <= -box[2] && lanes.neg_max_z[j] <= -box[4];
    }
#endif
    return count;
}

std::size_t PackedSweepAndPrune::firstReaching(const std::vector<float>& reach, std::size_t begin,
                                               std::size_t end, float lo_x) {
    // std::lower_bound, with the halving chosen by a select rather than a branch: which half
    // holds the answer is data (callgrind, 10k mixed, 30 frames: 45k fewer mispredictions in the
    // look-ups than std::lower_bound). The window [base, base + n) always holds the last place
    // before the answer or the answer itself.
    if (begin >= end) return begin;
    const float* base = reach.data() + begin;
    std::size_t n = end - begin;
    while (n > 1) {
        const std::size_t half = n / 2;
        base = base[half] < lo_x ? base + half : base;
        n -= half;
    }
    return static_cast<std::size_t>(base - reach.data()) + std::size_t(*base < lo_x);
}

void PackedSweepAndPrune::restale() {
    // The stale boxes that did not escape this frame keep their fat boxes, hence their order;
    // this frame's escaped boxes, sorted, are merged in (ties by id: deterministic).
    std::sort(escaped_.begin(), escaped_.end(), [this](ProxyId a, ProxyId b) {
        const float ka = fat_.min_x[static_cast<std::size_t>(a)];
        const float kb = fat_.min_x[static_cast<std::size_t>(b)];
        return ka < kb || (ka == kb && a < b);
    });
    merged_ids_.clear();
    std::size_t e = 0;
    const auto before = [this](ProxyId a, ProxyId b) {
        const float ka = fat_.min_x[static_cast<std::size_t>(a)];
        const float kb = fat_.min_x[static_cast<std::size_t>(b)];
        return ka < kb || (ka == kb && a < b);
    };
    for (const ProxyId id : stale_ids_) {
        if (escaped_flag_[id]) continue;
        while (e < escaped_.size() && before(escaped_[e], id)) merged_ids_.push_back(escaped_[e++]);
        merged_ids_.push_back(id);
    }
    merged_ids_.insert(merged_ids_.end(), escaped_.begin() + static_cast<std::ptrdiff_t>(e),
                       escaped_.end());
    stale_ids_.swap(merged_ids_);
    for (const ProxyId id : escaped_) stale_[id] = 1;
    const std::size_t count = stale_ids_.size();
    stale_lanes_.resize(count + kPad);
    for (std::size_t i = 0; i < count; ++i) {
        stale_lanes_.copy(i, fat_, static_cast<std::size_t>(stale_ids_[i]));
    }
    prefixMaxX(stale_lanes_, 0, count, stale_reach_);
    stale_lanes_.pad(count);
}

void PackedSweepAndPrune::queryEscaped(std::vector<ProxyPair>* exact_pairs,
                                       BroadPhaseCounters& counters) {
    // The sorted bands, as last dealt, still hold every box that has not been re-fattened
    // since (not stale): an escaped box is looked up in the bands its y range meets, from the
    // first box whose running maximum of max x reaches its min x (binary search: every box
    // before it ends short of it); the stale boxes' current fat boxes are kept apart
    // (stale_lanes_, sorted on min x) and looked up the same way. A
    // pair of two escaped boxes is taken from the lower id only; a pair met in several bands
    // only in the band of the larger min y (as in the full sweep).
    std::int64_t tests = 0;
    const std::size_t n = entries_.size();
    const bool one = bands_ == 1;
    const Lanes& lanes = one ? all_ : band_;
    // Room for every place of the longest lanes: no look-up can write more hits.
    hits_.resize(std::max({lanes.min_x.size(), big_lanes_.min_x.size(),
                           stale_lanes_.min_x.size()}) +
                 4);
    std::uint32_t* const hits = hits_.data();
    std::size_t count = 0;  // keys written
    // Each hit's key is written and kept by its conditions, with no branch on them.
    const auto room = [&](std::size_t more) {
        if (keys_.size() < count + more) keys_.resize(std::max(2 * keys_.size(), count + more));
    };
    for (const ProxyId e : escaped_) {
        const std::size_t k = static_cast<std::size_t>(e);
        const float box[6] = {fat_.min_x[k],      fat_.max_x[k], fat_.min_y[k],
                              -fat_.neg_max_y[k], fat_.min_z[k], -fat_.neg_max_z[k]};
        const std::uint64_t high = static_cast<std::uint64_t>(e) << shift_;
        const int fe = one ? 0 : bandOf(box[2]);
        const int le = one ? 0 : bandOf(box[3]);
        for (int b = fe; b <= le; ++b) {
            const std::size_t begin = one ? 0 : band_start_[b];
            const std::size_t end = one ? n : band_start_[b + 1] - kPad;
            const std::vector<float>& reach = one ? all_reach_ : band_reach_;
            const std::size_t j = firstReaching(reach, begin, end, box[0]);
            const std::size_t found = queryRange(lanes, j, box, true, hits, tests);
            room(found);
            for (std::size_t h = 0; h < found; ++h) {
                const std::uint32_t at = hits[h];
                // Met in the band of the larger first band of the two only.
                const bool owner = one || b == std::max(fe, band_first_[at]);
                const ProxyId other = ids_[one ? at : band_place_[at]];
                keys_[count] = high | static_cast<std::uint64_t>(other);
                count += owner & !stale_[other];
            }
        }
        const std::size_t found_big = queryRange(big_lanes_, 0, box, false, hits, tests);
        room(found_big);
        for (std::size_t h = 0; h < found_big; ++h) {
            const ProxyId other = ids_[big_[hits[h]]];
            keys_[count] = high | static_cast<std::uint64_t>(other);
            count += !stale_[other];
        }
        const std::size_t from = firstReaching(stale_reach_, 0, stale_ids_.size(), box[0]);
        const std::size_t found_stale = queryRange(stale_lanes_, from, box, true, hits, tests);
        room(found_stale);
        for (std::size_t h = 0; h < found_stale; ++h) {
            const ProxyId other = stale_ids_[hits[h]];
            // A pair of two escaped boxes is taken from the lower id only.
            const bool skip = other == e || (escaped_flag_[other] && other < e);
            keys_[count] = high | static_cast<std::uint64_t>(other);
            count += !skip;
        }
    }
    counters.volume_tests += tests;
    radix::keysToSortedPairs(std::span(keys_.data(), count), scratch_, shift_, fresh_,
                             /*order_ids=*/true);
    if (exact_pairs == nullptr) {
        mergeFresh<false>(nullptr);
    } else {
        mergeFresh<true>(exact_pairs);
    }
}

template <bool kExact>
void PackedSweepAndPrune::mergeFresh(std::vector<ProxyPair>* exact_pairs) {
    // The kept candidates (no escaped member) and the fresh ones, both sorted, merged; with
    // kExact, the same walk writes the exact pairs (see exactPairs): one walk over the
    // candidates, not two. Every candidate is written to each list, the merged count advances
    // for a kept one, the exact count for a kept one whose boxes overlap. A pair is compared as
    // one 64-bit key (a above b: the (a, b) order) with the next fresh one's, held in a
    // register (all ones past the last). Fresh pairs are few among the candidates, so the one
    // branch, taken at a kept candidate past the next fresh pair, is seldom taken: a fifth
    // fewer mispredicted branches in queryEscaped than testing the fresh list at every kept
    // candidate (callgrind, 1k mixed and 10k uniform). No fresh pair is a kept candidate (each
    // has an escaped member).
    const char* flag = escaped_flag_.data();
    const auto keyOf = [](const ProxyPair& p) {
        return (std::uint64_t(std::uint32_t(p.a)) << 32) | std::uint32_t(p.b);
    };
    constexpr std::uint64_t kNone = ~std::uint64_t(0);
    const ProxyPair* fresh = fresh_.data();
    const std::size_t n_fresh = fresh_.size();
    merged_.resize(candidates_.size() + n_fresh);
    ProxyPair* merged = merged_.data();
    ProxyPair* exact = nullptr;
    if constexpr (kExact) {
        if (exact_.size() < merged_.size()) exact_.resize(merged_.size());
        exact = exact_.data();
    }
    std::size_t kept = 0;
    std::size_t count = 0;
    const auto takeFresh = [&](const ProxyPair& q) {
        merged[kept++] = q;
        if constexpr (kExact) {
            exact[count] = q;
            count += static_cast<std::size_t>(overlapsExactly(q));
        }
    };
    std::size_t f = 0;
    std::uint64_t next = n_fresh > 0 ? keyOf(fresh[0]) : kNone;
    for (const ProxyPair& p : candidates_) {
        const int keep = int((flag[p.a] | flag[p.b]) == 0);
        const std::uint64_t key = keyOf(p);
        if ((key > next) & (keep != 0)) {
            do {
                takeFresh(fresh[f++]);
                next = f < n_fresh ? keyOf(fresh[f]) : kNone;
            } while (next < key);
        }
        merged[kept] = p;
        kept += static_cast<std::size_t>(keep);
        if constexpr (kExact) {
            exact[count] = p;
            count += static_cast<std::size_t>(keep & overlapsExactly(p));
        }
    }
    for (; f < n_fresh; ++f) takeFresh(fresh[f]);
    merged_.resize(kept);
    if constexpr (kExact) exact_pairs->assign(exact, exact + count);
    candidates_.swap(merged_);
}

}  // namespace collision
