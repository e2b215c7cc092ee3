// collision/src/broadphase/hgrid.h -- hierarchical grid (Mirtich, MERL TR-97-23, §2-2.2).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "broadphase/helper_thread.h"
#include "broadphase/proxy_table.h"
#include "collision/broadphase/broad_phase.h"

namespace collision {

/// Hierarchical grid after Mirtich, "Efficient Algorithms for Two-Phase Collision Detection"
/// (TR-97-23 §2-2.2). Level k has cells of size s_top / 8^k, s_top = the largest AABB extent;
/// each proxy lives at the finest level whose cells are at least its largest extent. A pair is
/// found once, at the coarser of its two levels (TR-97-23 §2.2): a proxy is also entered, as a
/// guest, in every coarser level that holds proxies of its own, and guests are paired only with
/// that level's own members. Each frame the levels are planned both ways, as above and as one
/// level holding everything, and the plan with the cheaper estimated sweep is used (planLevels):
/// the levels win when a few huge boxes would widen every column for many small ones, one
/// level wins when sizes spread evenly (the bench's 1:100 and 1:10^4 log-uniform mixes).
///
/// Within a level the cells are columns of a 2-D grid over (y, z), at least twice the level's
/// mean extent wide; an entry is written into every column its box touches (at most 2 x 2,
/// since cells are at least the extents), and each column is one list sorted by min x, swept
/// forward (sort and sweep, Baraff 1992). A pair shares several columns when both boxes
/// straddle a boundary; it is reported only in the column holding the point (max of the min y,
/// max of the min z), which lies in both boxes (owner rule, as in Ericson, Real-Time Collision
/// Detection §7.1.5), so it is met once. That column is known from two bits per entry: whether
/// the entry's own min corner is in this column's row (y) and layer (z).
///
/// Each frame the proxies are sorted by float(min x) (a non-decreasing image of min x): last
/// frame's order insertion-sorted when no proxy came or went (O(n + swaps) under coherent
/// motion; past n / 2 swaps, where boxes are dense along x, a radix sort, for kResortPause
/// frames), a radix sort otherwise; and scattered into the columns stably in that order, so each column is nearly sorted; an
/// insertion sort per column restores the exact (min x, id) order (sorting a column outright
/// past a budget of shifts). Pairs are put in (a, b) order by one more radix sort (or left in
/// the sweep's order: PairOrder). Cost per
/// frame O(n + candidates + pairs) for the sizes it is planned for, and no heap allocation once
/// the buffers have grown. Exact: every comparison is on the proxies' own coordinates,
/// touching counts.
///
/// With two threads ("hgrid2", from kTwoLaneMinimum proxies) a helper thread counts and
/// scatters half of the proxies, sweeps chunks of columns as they come free, sorts its own
/// pairs, and merges half of the two sorted lists; the output is identical to one thread's.
/// The helper spins for about a millisecond after each job (waking a sleeping thread cost more
/// than the jobs here), so hgrid2 keeps the second core busy while frames come quickly.
class HierarchicalGrid : public RebuildingBroadPhase {
public:
    /// PairOrder::Found: each pair as (a, b), a < b, in the order the sweep met them, with no
    /// final sort (BoxPruning one-shot: the sort is about a third of the frame at 100k boxes, a
    /// few per cent at 10k). One lane only: with two (hgrid2, from kTwoLaneMinimum proxies) the
    /// pairs come sorted, since which lane sweeps which columns varies from run to run.
    using PairOrder = collision::PairOrder;
    /// How the levels are planned each frame: the cheaper estimate of the level hierarchy (cells
    /// 2^kLevelBits apart) and of one level holding everything ("hgrid"), or always the
    /// hierarchy with cells halving per level ("hgrid-levels": Mirtich's own factor, a level per
    /// size class, to be seen and measured as TR-97-23 describes it).
    enum class LevelPlan { Cheaper, Hierarchy };
    /// `two_threads`: count, scatter and sweep split between this thread and a helper thread
    /// (from kTwoLaneMinimum proxies); the pairs are the same either way.
    explicit HierarchicalGrid(bool two_threads = false, PairOrder order = PairOrder::Sorted,
                              LevelPlan plan = LevelPlan::Cheaper);
    ~HierarchicalGrid() override;
    std::string_view name() const override {
        return helper_ ? "hgrid2" : level_plan_ == LevelPlan::Hierarchy ? "hgrid-levels" : "hgrid";
    }
    std::unique_ptr<BroadPhase> clone() const override {
        return std::make_unique<HierarchicalGrid>(*this);
    }
    void insert(ProxyId id, const ProxyVolumes& v) override;
    void insertMany(ProxyId first, std::span<const ProxyVolumes> v) override;
    void insertBoxes(ProxyId first, std::span<const Aabb> boxes) override;
    void remove(ProxyId id) override;
    void findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) override;
    void setPairOrder(PairOrder order) override { pair_order_ = order; }
    void draw(DebugDraw& draw, const Aabb& bounds) const override;
    std::string validate() const override;

    static constexpr int kMaxLevels = 40;
    /// Cells shrink by 2^kLevelBits per level. Mirtich uses 2; 8 halves the levels a 1:100 size
    /// mix spreads over, and each proxy is a guest in every coarser level.
    static constexpr int kLevelBits = 3;
    /// Fewer proxies than this run on one thread even when two are allowed.
    static constexpr std::size_t kTwoLaneMinimum = 4096;
    /// Columns are at least this many times the mean extent of a level's own members.
    static constexpr Real kCellPerExtent = 2;

    /// One box in one column. `flags`: bit 0, its min y is in this column's row; bit 1, its min
    /// z is in this column's layer; bit 2, the level is its own (not a guest). A pair is
    /// reported in a column iff the OR of the two flags is 7.
    struct Entry {
        Real min_x, max_x, min_y, min_z, max_y, max_z;
        std::uint32_t id;
        std::uint32_t flags;
    };

private:
    /// A level's column grid, as planLevels plans it.
    struct Grid {
        Real cell = 1;  // column width in y and z
        Real inv_cell = 1;
        std::int64_t ny = 1, nz = 1;
        std::size_t members = 0;  // proxies whose own level this is
        std::size_t guests = 0;   // proxies of finer levels, entered here as guests
    };
    using Plan = std::array<Grid, kMaxLevels>;
    struct Level : Grid {
        std::size_t first = 0;  // this level's entries are entries_[first, first + count)
        std::size_t count = 0;
        std::size_t first_column = 0;      // columns of the levels before (for the lane split)
        std::vector<std::uint32_t> start;  // column -> offset of its first entry in the level
    };
    struct Span {
        std::int64_t y0, z0, dy, dz;  // first column and how many more, in y and in z
    };
    /// Where one box goes in one level: its first column and how many more in y and z (at
    /// most 2: a box's extent is at most the cell of its level and of every coarser one).
    struct Placement {
        std::uint32_t column;
        std::uint16_t dy, dz;
        std::uint8_t level, own;
    };
    /// Unused slots around each lane's cursors, so that two lanes' cursors (written for every
    /// entry) never share a cache line.
    static constexpr std::size_t kCursorPad = 16;
    /// One thread's share of a frame: positions [first, last) to count and scatter, the
    /// chunks of columns it swept, and what it found.
    struct Lane {
        std::size_t first = 0, last = 0;
        std::array<Real, kMaxLevels> extent_sum{};  // of its boxes, by level
        std::array<std::size_t, kMaxLevels> members{};
        std::size_t zero_size = 0;
        int finest = 0;
        std::vector<Placement> placements;                          // by position, then level
        std::array<std::vector<std::uint32_t>, kMaxLevels> cursor;  // counts, then cursors
        std::vector<std::uint64_t> keys, scratch;
        std::vector<std::uint32_t> natives;  // sweep scratch: a column's own members
        std::vector<ProxyPair> pairs;        // with two lanes; one lane writes the caller's
        std::int64_t tests = 0, swaps = 0;
    };
    struct Bounds {
        Real lo_y, hi_y, lo_z, hi_z;
        Vec3 centre_span;  // of the boxes' centres
    };
    /// The boxes' bounds, gathered with them.
    struct Extents {
        Real top = 0;                 // largest extent
        Real lo_y, hi_y, lo_z, hi_z;  // of the boxes
        Vec3 lo_c, hi_c;              // of their centres
    };
    /// A box's largest extent, which decides its level.
    static Real extentOf(const Aabb& b) { return (b.max - b.min).maxCoeff(); }
    static constexpr std::uint8_t kZeroSize = 0xff;  // level_of_ mark: any level will do
    static double planLevels(const std::array<std::size_t, kMaxLevels>& members,
                             const std::array<Real, kMaxLevels>& extent_sum, int level_count,
                             int level_bits, Real top, const Bounds& bounds, Plan& plan);
    Extents gatherBoxes();
    // Steps of findPairs, in order (hgrid_order.cpp, hgrid_levels.cpp, hgrid.cpp).
    void chooseLevels(Real top, const Extents& x);
    std::size_t layoutColumns(std::size_t& flat_columns);
    void planChunks(std::size_t total, std::size_t flat_columns);
    void mergeLanePairs(std::vector<ProxyPair>& pairs);
    void sortByMinX();
    bool resortByMinX();
    void levelLane(Lane& lane, Real top);
    void countLane(Lane& lane);
    void scatterLane(Lane& lane, std::size_t spare_slot);
    void sweepLane(Lane& lane, std::vector<ProxyPair>& pairs);
    std::int64_t fixColumns(const Level& level, std::size_t from, std::size_t to);
    Span span(const Level& level, const Aabb& box) const;
    std::int64_t column(const Level& level, Real v, Real origin, std::int64_t n) const;

    int level_count_ = 0;
    int finest_ = 0;     // the finest level with members; zero-size boxes join it
    bool flat_ = false;  // every box at level 0 (planLevels found that cheaper)
    LevelPlan level_plan_ = LevelPlan::Cheaper;
    int level_bits_ = kLevelBits;  // cells shrink by 2^level_bits_ per level
    // The last plan, for draw(): the size levels the proxies span, and the estimated sweep
    // costs of their hierarchy and of one level (0 when not planned).
    int size_levels_ = 0;
    double hierarchy_estimate_ = 0, one_level_estimate_ = 0;
    Real origin_y_ = 0, origin_z_ = 0;
    std::array<Level, kMaxLevels> levels_;
    std::vector<std::uint32_t> order_;   // present proxies by (min x, id)
    bool order_stale_ = true;            // a proxy was inserted or removed since order_ was made
    /// Frames the radix sort runs after an insertion sort ran past its budget.
    static constexpr int kResortPause = 16;
    int resort_pause_ = 0;
    std::vector<std::uint64_t> packed_;  // (float min x, id) sort keys
    std::vector<std::uint32_t> key_of_id_;  // float min x's sort key, by id
    std::vector<std::uint64_t> packed_scratch_;
    std::vector<Aabb> box_;               // their boxes
    std::vector<std::uint8_t> level_of_;  // by position in order_
    int id_shift_ = 1;                    // bits per id in a packed pair key
    std::vector<Entry> entries_;
    std::vector<std::size_t> chunks_;  // flat column index where each sweep chunk starts, + end
    /// The next sweep chunk a lane takes; a copy of the grid starts from the same count.
    struct ChunkCounter : std::atomic<std::size_t> {
        ChunkCounter() : std::atomic<std::size_t>(0) {}
        ChunkCounter(const ChunkCounter& other) : std::atomic<std::size_t>(other.load()) {}
        ChunkCounter& operator=(const ChunkCounter& other) {
            store(other.load());
            return *this;
        }
    };
    ChunkCounter next_chunk_;
    std::array<Lane, 2> lanes_;
    int lane_count_ = 1;
    PairOrder pair_order_;
    /// hgrid2's helper thread (none for hgrid): a copy of the grid gets a thread of its own.
    struct HelperSlot {
        std::unique_ptr<HelperThread> thread;
        HelperSlot() = default;
        explicit HelperSlot(bool on) : thread(on ? std::make_unique<HelperThread>() : nullptr) {}
        HelperSlot(const HelperSlot& other) : HelperSlot(other.thread != nullptr) {}
        HelperSlot(HelperSlot&&) noexcept = default;
        HelperSlot& operator=(const HelperSlot& other) {
            if (this != &other) *this = HelperSlot(other);
            return *this;
        }
        HelperSlot& operator=(HelperSlot&&) noexcept = default;
        HelperThread* operator->() const { return thread.get(); }
        explicit operator bool() const { return thread != nullptr; }
    };
    HelperSlot helper_;
};

}  // namespace collision
