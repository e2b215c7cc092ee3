// app/lab/bench/bench_workload.h -- the moving-box workloads of `cdlab bench broadphase` and of the Google
// Benchmark target: N axis-aligned boxes drifting coherently in a cube, and an independent
// reference pair count to check every broad phase against.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "collision/math.h"
#include "collision/volumes/bounding_volumes.h"

namespace app {

enum class WorkloadKind {
    Uniform,  ///< half extents uniform in [0.4, 0.6] per axis
    Mixed,    ///< box scale log-uniform in [0.05, 5] (1:100), each axis x U[0.8, 1.2]
    Wide,     ///< box scale log-uniform in [0.005, 50] (1:10^4), each axis x U[0.8, 1.2]
    /// Terdiman's BoxPruning scene ("Box pruning revisited", 2017): integer centres in
    /// [-2048, 2047]^3 and integer half extents in [0, 127] from MSVC's rand() seeded with 42
    /// (41 + seed); each frame every centre moves by -1, 0 or +1 per axis, kept in the range.
    BoxPruning,
};

std::string_view workloadName(WorkloadKind kind);
/// "uniform", "mixed", "wide" or "boxpruning"; nullopt otherwise.
std::optional<WorkloadKind> parseWorkloadKind(std::string_view name);

/// The overlapping pairs of one frame, summarised: their number and an order-independent hash
/// of the set, so two broad phases agree when both fields agree.
struct PairSummary {
    std::int64_t pairs = 0;
    std::uint64_t hash = 0;
    friend bool operator==(const PairSummary&, const PairSummary&) = default;
};

/// Hash contribution of the pair (a, b), a < b; a set hashes to the wrapping sum over its pairs.
std::uint64_t pairHash(collision::ProxyId a, collision::ProxyId b);

/// N boxes in the cube [lower, lower + side]^3. Uniform, mixed and wide: lower = 0, each box with
/// a constant velocity, reflected at the walls so the box stays inside; per-frame displacement is
/// 1-2 % of the box's size (twice its mean half extent). BoxPruning: see WorkloadKind. Everything is a pure function of (kind, n, seed): two objects built with the same
/// arguments and stepped the same number of times hold bit-identical boxes.
class MovingBoxes {
public:
    /// Overlapping pairs per box (pairs / N) the cube side is calibrated for, at frame 0.
    static constexpr double kTargetPairsPerBody = 2.8;

    /// Generates the boxes and calibrates the cube side (a few reference sweeps, O(n log n)).
    /// Precondition: n >= 2.
    MovingBoxes(WorkloadKind kind, int n, std::uint64_t seed);

    WorkloadKind kind() const { return kind_; }
    int size() const { return static_cast<int>(center_.size()); }
    collision::Real side() const { return side_; }
    /// The cube's lowest coordinate on every axis.
    collision::Real lower() const { return lower_; }
    int frame() const { return frame_; }

    /// Advances every box by its velocity for one frame, reflecting at the walls.
    void step();

    const std::vector<collision::Vec3>& centers() const { return center_; }
    const std::vector<collision::Vec3>& halfExtents() const { return half_; }
    /// Box i's exact AABB: centre -/+ half extents (the same doubles every peer sees). Made
    /// when the boxes move, untimed, so every method reads its boxes from this one array.
    const collision::Aabb& aabb(int i) const { return box_[static_cast<std::size_t>(i)]; }
    const std::vector<collision::Aabb>& aabbs() const { return box_; }
    /// Every box's volumes for cdlab broad phases: the AABB, its circumscribed sphere, and the
    /// AABB as an axis-aligned OBB. `out` is resized to size().
    void volumes(std::vector<collision::ProxyVolumes>& out) const;

private:
    void place();
    void generateBoxPruning(int n, std::uint64_t seed);
    void jitter();
    void makeBoxes();

    WorkloadKind kind_;
    collision::Real side_ = 1;
    collision::Real lower_ = 0;
    std::uint32_t rand_state_ = 0;  // BoxPruning: MSVC rand() state
    int frame_ = 0;
    std::vector<collision::Vec3> unit_;  // frame-0 positions in [0,1]^3, scaled into the cube
    std::vector<collision::Vec3> center_;
    std::vector<collision::Vec3> half_;
    std::vector<collision::Vec3> velocity_;
    std::vector<collision::Aabb> box_;  // centre -/+ half extents, for aabb()
};

/// Counts the overlapping pairs of a frame (closed test, as collision::Aabb::overlaps), written
/// independently of cdlab's broad phases: the cube is cut into slabs along y, each box is entered
/// in every slab it touches, and each slab is sorted and swept along x. A pair is counted only in
/// the slab holding the larger of the two min-y values, which lies in both boxes' slab ranges.
/// Expected cost O(n log n + n^2 / (slabs * side)); the buffers are kept between calls.
class PairReference {
public:
    PairSummary count(const MovingBoxes& boxes);

private:
    struct Entry {
        collision::Aabb box;
        int id;
    };
    std::vector<Entry> entries_;
    std::vector<int> slab_start_;
    std::vector<collision::Real> extents_;
};

/// Summary of a pair list as cdlab's broad phases report it.
PairSummary summarizePairs(std::span<const collision::ProxyPair> pairs);

}  // namespace app
