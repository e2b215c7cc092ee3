// collision/src/broadphase/sap_packed.h -- single-axis sort and sweep on packed float bounds,
// the y/z overlap of each candidate tested four floats at a time with SSE2.
#pragma once

#include <cstdint>
#include <vector>

#include "broadphase/proxy_table.h"
#include "collision/broadphase/broad_phase.h"

namespace collision {

/// Box pruning (Terdiman, "Box pruning revisited", 2017; Baraff 1992 for the sort and sweep):
/// each frame the proxies are sorted once on their minimum x. Like Terdiman's buckets, the
/// sorted boxes are then dealt, in order, into bands along y (each box into every band its y
/// range meets, so each band stays sorted on x) and every band is swept along x on its own; a
/// pair is kept only in the band holding the larger of the two minimum y, which both boxes meet,
/// so it is reported once. Boxes meeting more than a few bands are swept against the whole
/// sorted list instead (so one huge box costs one sweep, not one per band). The bounds are
/// copied into structure-of-arrays float form, each double rounded outward (minimum down, maximum
/// up), so the float test never rejects a pair the double test accepts; a candidate whose float
/// bounds were not exact is confirmed on the double AABBs. The y/z test of a candidate is one
/// four-wide comparison: (min y, min z, -max y, -max z) of one box against (max y, max z, -min y,
/// -min z) of the other. The sort is an LSD radix sort on the float keys after a change of the
/// proxy set, and an insertion sort of last frame's order otherwise (O(n + swaps) when motion is
/// coherent; it falls back to the radix sort when the order changed too much).
class PackedSweepAndPrune : public BroadPhase {
public:
    std::string_view name() const override { return "sap-packed"; }
    void insert(ProxyId id, const ProxyVolumes& v) override;
    void remove(ProxyId id) override;
    void move(ProxyId id, const ProxyVolumes& v) override;
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    void draw(DebugDraw& draw, const Aabb& bounds) const override;
    std::string validate() const override;

private:
    static constexpr std::size_t kSample = 255;     ///< boxes sampled for the band width
    static constexpr std::size_t kMinPerBand = 16;  ///< fewer bands than n / this
    static constexpr int kMaxBands = 1024;
    static constexpr float kBandWidth = 1.0f;  ///< band width / median y extent
    static constexpr int kBigBands = 4;        ///< a box meeting more bands than this is big
    /// One box's y and z bounds as (min y, min z, -max y, -max z), rounded outward.
    struct alignas(16) PackedYz {
        float v[4];
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
    int bandOf(float y) const {
        const float t = (y - band_lo_) * band_scale_;
        // Compare before converting: a NaN or huge t must not reach the integer conversion.
        if (!(t > 0)) return 0;
        if (t >= float(bands_ - 1)) return bands_ - 1;
        return static_cast<int>(t);
    }
    /// Keeps the pair of sorted places i and j when its double AABBs overlap.
    void confirm(std::size_t i, std::size_t j) {
        const ProxyId a = ids_[i];
        const ProxyId b = ids_[j];
        if ((exact_[i] & exact_[j]) || table_.aabb(a).overlaps(table_.aabb(b))) {
            keys_.push_back((static_cast<std::uint64_t>(a) << shift_) |
                            static_cast<std::uint64_t>(b));
        }
    }

    ProxyTable table_;
    std::vector<Entry> entries_;  ///< present proxies sorted by key (ties: unspecified)
    std::vector<float> min_x_;    ///< in sorted order, plus a NaN sentinel that ends every sweep
    std::vector<float> max_x_;
    std::vector<PackedYz> yz_;
    std::vector<ProxyId> ids_;
    std::vector<char> exact_;  ///< 1 when the float bounds equal the double AABB
    // Bands along y: band b covers [band_lo_ + b / band_scale_, ...); the last is open above.
    int bands_ = 1;
    float band_lo_ = 0;
    float band_scale_ = 0;
    std::vector<int> first_band_;  ///< per sorted place; -1 for a big box (swept against all)
    std::vector<int> last_band_;
    std::vector<std::uint32_t> band_start_;  ///< band b's entries: [start[b], start[b+1] - 1)
    std::vector<float> band_min_x_;          ///< per band entry; NaN after each band's last
    std::vector<float> band_max_x_;
    std::vector<PackedYz> band_yz_;
    std::vector<std::uint32_t> band_place_;  ///< the entry's sorted place
    std::vector<std::uint32_t> big_;         ///< sorted places of the big boxes, in order
    std::vector<float> sample_;
    std::vector<std::uint32_t> scratch_fill_;
    int shift_ = 1;
    std::vector<std::uint64_t> keys_;
    std::vector<std::uint64_t> scratch_;
    bool dirty_ = true;
    std::int64_t moved_ = 0;
};

}  // namespace collision
