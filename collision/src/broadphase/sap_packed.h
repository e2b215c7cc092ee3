// collision/src/broadphase/sap_packed.h -- single-axis sort and sweep on packed float bounds,
// the y/z overlap of each candidate tested four floats at a time with SSE2.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "broadphase/proxy_table.h"
#include "collision/broadphase/loose_broad_phase.h"

namespace collision {

/// Box pruning (Terdiman, "Box pruning revisited", 2017; Baraff 1992 for the sort and sweep):
/// each frame the proxies are sorted once on their minimum x. Like Terdiman's buckets, the
/// sorted boxes are then dealt, in order, into bands along y (each box into every band its y
/// range meets, so each band stays sorted on x) and every band is swept along x on its own; a
/// pair is kept only in the band holding the larger of the two minimum y, which both boxes meet,
/// so it is reported once. Boxes meeting more than a few bands are swept against the whole
/// sorted list instead (so one huge box costs one sweep, not one per band). The bounds are
/// copied into float form, each double rounded outward (minimum down, maximum up), so the float
/// test never rejects a pair the double test accepts; every candidate is confirmed as the double
/// AABBs decide (overlapsExactly). The bounds are stored one array per bound, and the sweep tests
/// four consecutive boxes at once with SSE2 (x, y and z in five four-wide comparisons), leaving
/// the sweep when one of the four starts past the box's end. The sort is an LSD radix sort on the
/// float keys after a change of the proxy set, and an insertion sort of last frame's order
/// otherwise (O(n + swaps) when motion is coherent; it falls back to the radix sort when the order
/// changed too much).
///
/// Coherence (as Bullet's DBVT and Box2D's tree fatten leaves): the swept boxes are fat, the exact
/// box grown by a margin and led in the direction it moves (fatten()), and the candidate pairs
/// (fat boxes overlap) are kept between frames. A frame where few boxes left their fat box
/// re-fattens only those and looks each up in the last sorted bands (binary search on the running
/// maximum of max x, O(log n + k) per band), which still hold every box not re-fattened since
/// (the big boxes in a list of their own, tested four at a time); the re-fattened
/// ("stale") boxes are looked up in a sorted list of their own. Once many are stale, the bands
/// are sorted and dealt again (no sweep: the candidates are complete). When many escape in one
/// frame every fat box is swept again (margins kept); when most do, margins are not paying and
/// everything is swept with exact boxes, margins tried again kRetryFrames later. A new proxy set
/// (insert, remove) is swept with exact boxes: the one-shot path.
class PackedSweepAndPrune : public LooseBroadPhase {
public:
    /// What findPairs writes.
    enum class Output {
        Exact,  ///< the overlapping pairs, as every registry broad phase (the default)
        /// the candidate pairs: every pair whose fat boxes overlap, sorted by (a, b), unique,
        /// with no exact confirm. A superset of the overlapping pairs, as Bullet's pair cache
        /// is, for a caller that tests the exact boxes itself. Never in the registry (whose
        /// entries equal brute force); reached through createLoosePackedSweepAndPrune().
        Loose,
    };
    explicit PackedSweepAndPrune(Output output = Output::Exact) : output_(output) {}
    std::string_view name() const override {
        return output_ == Output::Loose ? "sap-packed-loose" : "sap-packed";
    }
    std::unique_ptr<BroadPhase> clone() const override {
        return std::make_unique<PackedSweepAndPrune>(*this);
    }
    void insert(ProxyId id, const ProxyVolumes& v) override;
    void insertMany(ProxyId first, std::span<const ProxyVolumes> v) override;
    void insertBoxes(ProxyId first, std::span<const Aabb> boxes) override;
    void remove(ProxyId id) override;
    void move(ProxyId id, const ProxyVolumes& v) override;
    void moveBoxes(ProxyId first, std::span<const Aabb> boxes) override;
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    /// findPairs() without writing pairs: the candidates brought up to date, none confirmed.
    void updatePairs(BroadPhaseCounters& counters) override;
    /// The candidates of the last findPairs() or updatePairs() (either output): every pair whose
    /// fat boxes overlap, sorted, unique.
    std::span<const ProxyPair> heldPairs() const override { return candidates_; }
    void draw(DebugDraw& draw, const Aabb& bounds) const override;
    /// Checks the entries' order, and the invariant at the top of sap_packed.cpp: candidates
    /// sorted, unique, each a pair of overlapping fat boxes, and every present box inside its fat
    /// box unless move() flagged it as escaped. O(n + candidates).
    std::string validate() const override;
    /// Whether the fat boxes of present proxies a and b overlap (closed test on the floats), as
    /// of the last findPairs: the test a loose output's pairs pass. For tests and checks.
    bool fatBoxesOverlap(ProxyId a, ProxyId b) const;

    /// The first place in [begin, end) whose reach (non-decreasing there) is at least lo_x, end
    /// if none: std::lower_bound. Public for its test.
    static std::size_t firstReaching(const std::vector<float>& reach, std::size_t begin,
                                     std::size_t end, float lo_x);

private:
    static constexpr std::size_t kSample = 255;     ///< boxes sampled for the band width
    static constexpr std::size_t kMinPerBand = 16;  ///< fewer bands than n / this
    static constexpr int kMaxBands = 1024;
    static constexpr float kBandWidth = 3.0f;  ///< band width / median y extent
    static constexpr int kBigBands = 4;        ///< a box meeting more bands than this is big
    static constexpr std::size_t kPad = 4;     ///< NaN sentinels after each swept list
    static constexpr float kMargin = 16.0f;    ///< most fat margin / recent motion per frame
    static constexpr float kMinMargin = 1.0f;  ///< least fat margin / recent motion per frame
    static constexpr float kLead = 32.0f;      ///< fat lead / mean velocity, on the side it leads
    /// A box moving steadily: mean speed over its last fat box's lifetime at least kSteady of
    /// its recent step. Its lead does the work: a longer one, and a thinner most margin.
    static constexpr float kSteady = 0.9f;
    static constexpr float kSteadyLead = 64.0f;
    static constexpr float kSteadyMargin = 2.0f;
    static constexpr float kMotionDecay = 0.95f;
    static constexpr std::size_t kEscapeShare = 4;  ///< a full sweep when n / this escape at once

    /// move() of a box: move() and moveBoxes() share it, inlined in the loop of the second.
    void moveBox(ProxyId id, const Aabb& box);
    static constexpr std::size_t kStaleShare = 4;   ///< bands dealt again past n / this stale
    static constexpr int kRetryFrames = 32;

    /// Float bounds of a sorted list of boxes, one array per bound (structure of arrays), so
    /// four consecutive boxes load as one SSE register per bound. Maxima of y and z are stored
    /// negated, so every test of the sweep is "lane <= limit".
    struct Lanes {
        std::vector<float> min_x, max_x, min_y, min_z, neg_max_y, neg_max_z;
        void resize(std::size_t n);
        void copy(std::size_t to, const Lanes& from, std::size_t at);
        /// Entries [at, at + kPad): NaN minimum x ends every sweep that reaches them.
        void pad(std::size_t at);
    };
    struct Entry {
        float key;  ///< min x rounded down
        ProxyId id;
    };

    void sortEntries(BroadPhaseCounters& counters);
    void radixSortEntries();
    void pack();
    void dealBands();
    void sweepBands(BroadPhaseCounters& counters);
    void sweepBig(BroadPhaseCounters& counters);
    /// reach[i] for i in [begin, end): the largest max x of lanes [begin, i] (see band_reach_).
    static void prefixMaxX(const Lanes& lanes, std::size_t begin, std::size_t end,
                           std::vector<float>& reach);
    template <typename Hit>
    static std::int64_t sweepRange(const Lanes& lanes, std::size_t begin, std::size_t end,
                                   Hit&& hit);
    /// Tests `box` against lanes from place j on, four at a time, writing the place of each
    /// overlap to hits (room for one per place from j to the end, plus 4) and returning how
    /// many; stops at the first group with a box past max x (stop_past_x) or a NaN. Adds the
    /// boxes tested to `tests`.
    static std::size_t queryRange(const Lanes& lanes, std::size_t j, const float (&box)[6],
                                  bool stop_past_x, std::uint32_t* hits, std::int64_t& tests);
    int bandOf(float y) const {
        const float t = (y - band_lo_) * band_scale_;
        // Compare before converting: a NaN or huge t must not reach the integer conversion.
        if (!(t > 0)) return 0;
        if (t >= float(bands_ - 1)) return bands_ - 1;
        return static_cast<int>(t);
    }
    /// Records the candidate pair of sorted places i and j (their fat boxes overlap).
    void confirm(std::size_t i, std::size_t j) {
        keys_.push_back((static_cast<std::uint64_t>(ids_[i]) << shift_) |
                        static_cast<std::uint64_t>(ids_[j]));
    }
    /// Sets the fat box of `id`: its exact box grown by `share` of its margins and rounded
    /// outward; `learn`: the margins learnt from the fat box's lifetime just ended (see .cpp).
    void fatten(ProxyId id, float share, bool learn);
    /// Stores the fat box of id k from double bounds, rounded outward to float.
    void setFat(std::size_t k, Real lo_x, Real lo_y, Real lo_z, Real hi_x, Real hi_y, Real hi_z);
    bool insideFat(ProxyId id) const { return insideFat(id, table_.aabb(id)); }
    /// Whether `box` lies inside id's fat box: every side tested, with no branch between them
    /// (move() asks for every box of every frame).
    bool insideFat(ProxyId id, const Aabb& box) const {
        const auto k = static_cast<std::size_t>(id);
        return (int(double(fat_.min_x[k]) <= box.min.x()) &
                int(box.max.x() <= double(fat_.max_x[k])) &
                int(double(fat_.min_y[k]) <= box.min.y()) &
                int(box.max.y() <= -double(fat_.neg_max_y[k])) &
                int(double(fat_.min_z[k]) <= box.min.z()) &
                int(box.max.z() <= -double(fat_.neg_max_z[k]))) != 0;
    }
    void rebuild();
    /// Sorts, packs and deals the current fat boxes into bands; none stale after.
    void resnapshot(BroadPhaseCounters& counters);
    void fullSweep(BroadPhaseCounters& counters);
    void restale();
    /// Brings candidates_ up to date with the current boxes. Given `exact`, a frame that walks
    /// the candidates anyway also writes the exact pairs there; returns whether it did.
    bool update(std::vector<ProxyPair>* exact, BroadPhaseCounters& counters);
    /// Looks up the escaped boxes and updates candidates_; given `exact`, also writes the exact
    /// pairs there (in the same walk over the candidates).
    void queryEscaped(std::vector<ProxyPair>* exact, BroadPhaseCounters& counters);
    /// The candidates with no escaped member and the fresh ones (fresh_), both sorted, merged
    /// into candidates_; with kExact, the exact pairs among them written to *exact_pairs.
    /// Out of line: inlined into queryEscaped, the walk's state did not stay in registers.
    template <bool kExact>
    [[gnu::noinline]] void mergeFresh(std::vector<ProxyPair>* exact_pairs);
    /// Whether the candidate's AABBs overlap, as Aabb::overlaps decides on the double bounds
    /// (closed test). Inline: it runs once per candidate per frame. Decided on the boxes rounded
    /// to nearest float (near_), which rounding keeps in order (x <= y gives f(x) <= f(y)), so
    /// f(x) < f(y) proves x < y and f(x) > f(y) proves x > y: every comparison strict on the
    /// floats is decided there, and only a pair with some bounds equal as floats (touching to
    /// within a float's precision, or a bound past float range, or NaN) is tested on the doubles.
    int overlapsExactly(const ProxyPair& p) const {
#if defined(__SSE2__)
        const NearBox& a = near_[static_cast<std::size_t>(p.a)];
        const NearBox& b = near_[static_cast<std::size_t>(p.b)];
        const __m128 a_lo = _mm_load_ps(a.lo);
        const __m128 a_hi = _mm_load_ps(a.hi);
        const __m128 b_lo = _mm_load_ps(b.lo);
        const __m128 b_hi = _mm_load_ps(b.hi);
        const int sure = _mm_movemask_ps(
            _mm_and_ps(_mm_cmplt_ps(a_lo, b_hi), _mm_cmplt_ps(b_lo, a_hi)));
        const int maybe = _mm_movemask_ps(
            _mm_and_ps(_mm_cmple_ps(a_lo, b_hi), _mm_cmple_ps(b_lo, a_hi)));
        if (maybe != sure) [[unlikely]] return overlapsOnDoubles(p);
        return int(sure == 0xF);
#else
        return overlapsOnDoubles(p);
#endif
    }
    int overlapsOnDoubles(const ProxyPair& p) const {
        const Aabb& a = table_.aabb(p.a);
        const Aabb& b = table_.aabb(p.b);
        return int(a.min.x() <= b.max.x()) & int(b.min.x() <= a.max.x()) &
               int(a.min.y() <= b.max.y()) & int(b.min.y() <= a.max.y()) &
               int(a.min.z() <= b.max.z()) & int(b.min.z() <= a.max.z());
    }
    /// A box's bounds rounded to nearest float, x y z and a fourth lane that always passes.
    struct alignas(16) NearBox {
        float lo[4];
        float hi[4];
    };
    void setNear(ProxyId id, const Aabb& box) {
        NearBox& n = near_[static_cast<std::size_t>(id)];
        n = NearBox{{float(box.min.x()), float(box.min.y()), float(box.min.z()), 0.0f},
                    {float(box.max.x()), float(box.max.y()), float(box.max.z()), 1.0f}};
    }

    Output output_;
    ProxyTable table_;
    std::vector<Entry> entries_;  ///< present proxies sorted by key (ties: unspecified)
    Lanes all_;                   ///< every box in sorted order, then kPad sentinels
    std::vector<ProxyId> ids_;    ///< per sorted place
    // Fat boxes by id (absent ids NaN): the exact box grown by the margins of fatten() and
    // rounded outward; candidates_ holds every pair whose fat boxes overlap.
    Lanes fat_;
    std::vector<NearBox> near_;  ///< by id, the exact boxes as floats (Output::Exact only)
    std::vector<float> motion_;  ///< recent largest centre step per frame, by id
    // Per id, of its current fat box: the margin on every side, the velocity it leads by, and
    // the centre and frame it was made at.
    std::vector<Real> margin_;
    std::vector<Vec3> lead_velocity_;
    std::vector<Vec3> fat_centre_;
    std::vector<std::int64_t> fat_frame_;
    std::int64_t frame_ = 0;  ///< findPairs calls so far
    std::vector<ProxyId> present_;
    std::vector<ProxyId> escaped_;
    std::vector<char> stale_;         ///< by id: re-fattened since the bands were dealt
    std::vector<ProxyId> stale_ids_;  ///< the stale ids, sorted on fat min x
    std::vector<ProxyId> merged_ids_;
    Lanes stale_lanes_;  ///< their fat boxes in that order, then kPad NaN
    // Running maxima of max x along a sorted list: reach[i] = the largest max x of its entries
    // up to i. Boxes before the first entry reaching a min x all end short of it.
    std::vector<float> stale_reach_;  ///< along stale_lanes_
    std::vector<float> band_reach_;   ///< along band_, each band from its start
    std::vector<float> all_reach_;    ///< along all_ (kept when there is one band)
    std::vector<char> escaped_flag_;
    std::vector<ProxyPair> candidates_;
    std::vector<ProxyPair> fresh_;
    std::vector<ProxyPair> merged_;
    /// The exact pairs written branch-free (every candidate written, the count advanced for an
    /// overlap) before their copy to the caller's list: kept at its largest size, so no frame
    /// pays to value-initialise room for every candidate in the caller's list.
    std::vector<ProxyPair> exact_;
    bool margins_on_ = false;
    int retry_in_ = 1;
    float lo_y_ = 0;  ///< lowest min y and highest max y (float)
    float hi_y_ = 0;
    // Bands along y: band b covers [band_lo_ + b / band_scale_, ...); the last is open above.
    int bands_ = 1;
    float band_lo_ = 0;
    float band_scale_ = 0;
    std::vector<int> first_band_;  ///< per sorted place; -1 for a big box (swept against all)
    std::vector<int> last_band_;
    std::vector<std::uint32_t> band_start_;  ///< band b's entries: [start[b], start[b+1] - kPad)
    Lanes band_;                             ///< the bands' entries, each band sorted
    std::vector<std::uint32_t> band_place_;  ///< the entry's sorted place
    std::vector<int> band_first_;            ///< the entry's box's first band
    std::vector<std::uint32_t> big_;         ///< sorted places of the big boxes, in order
    Lanes big_lanes_;                        ///< their boxes in that order, then kPad NaN
    std::vector<float> sample_;
    std::vector<std::uint32_t> fill_;
    std::vector<std::uint64_t> keys_;
    std::vector<std::uint32_t> hits_;  ///< queryRange's output
    std::vector<std::uint64_t> scratch_;
    int shift_ = 1;
    bool dirty_ = true;
    std::int64_t moved_ = 0;
};

}  // namespace collision
