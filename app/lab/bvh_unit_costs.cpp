// app/lab/bvh_unit_costs.cpp -- timing of the replayed BVH tests (the replays are collision/bvh.h's).
#include "bvh_unit_costs.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>
#include <random>
#include <vector>

namespace app {

namespace {

using Clock = std::chrono::steady_clock;

// Fastest of three runs of `fn`, in seconds; `result` gets fn()'s value.
template <class Fn>
double fastestOfThree(Fn&& fn, std::int64_t* result) {
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < 3; ++r) {
        const auto start = Clock::now();
        *result = fn();
        best = std::min(best, std::chrono::duration<double>(Clock::now() - start).count());
    }
    return best;
}

}  // namespace

BvhUnitCosts measureBvhUnitCosts(const collision::MeshBvh& a, const collision::MeshBvh& b,
                                 std::span<const collision::Pose> poses, std::int64_t bv_target,
                                 std::int64_t triangle_target) {
    BvhUnitCosts costs;
    if (poses.empty() || a.triangleCount() == 0 || b.triangleCount() == 0) return costs;
    std::vector<collision::BvhTestSample> samples;
    samples.reserve(poses.size());
    std::int64_t nv = 0;
    std::int64_t np = 0;
    for (const collision::Pose& pose : poses) {
        samples.push_back(collision::recordTests(a, b, pose));
        nv += static_cast<std::int64_t>(samples.back().node_pairs.size());
        np += static_cast<std::int64_t>(samples.back().triangle_pairs.size());
    }
    // A hierarchy whose tests the replay cannot record (the wide tree: its node tests run in
    // lanes) gives no sample at all, and no unit costs.
    if (nv == 0) return costs;
    if (np == 0) {
        // No query reached its triangles (every pose apart at the volumes): time random pairs of
        // the meshes' triangles at the first pose instead, and say so.
        std::mt19937_64 rng(1);
        std::uniform_int_distribution<std::int32_t> pick_a(0, a.triangleCount() - 1);
        std::uniform_int_distribution<std::int32_t> pick_b(0, b.triangleCount() - 1);
        const auto count =
            static_cast<std::size_t>(std::min<std::int64_t>(triangle_target, 1 << 16));
        for (std::size_t k = 0; k < count; ++k) {
            samples.front().triangle_pairs.push_back({pick_a(rng), pick_b(rng)});
        }
        np = static_cast<std::int64_t>(count);
        costs.triangles_from_queries = false;
    }
    const auto bv_repeats = static_cast<int>((bv_target + nv - 1) / nv);
    const auto tri_repeats = static_cast<int>((triangle_target + np - 1) / np);
    costs.bv_tests_timed = nv * bv_repeats;
    costs.triangle_tests_timed = np * tri_repeats;
    // Each pose's list is replayed `repeats` times in chunks of about one query's tests (at least
    // kMinChunk, so the clock's own cost stays negligible), each chunk the fastest of three runs:
    // the same estimator as the queries' "fastest repetition", and a chunk rarely spans a
    // preemption of this process on a shared machine.
    constexpr std::int64_t kMinChunk = 4096;
    auto timeReplays = [&](int repeats, auto sample_size, auto replay, std::int64_t* found) {
        double seconds = 0;
        *found = 0;
        for (std::size_t k = 0; k < poses.size(); ++k) {
            const std::int64_t n = sample_size(samples[k]);
            if (n == 0) continue;
            const auto chunk =
                static_cast<int>(std::clamp<std::int64_t>((kMinChunk + n - 1) / n, 1, repeats));
            for (int done = 0; done < repeats; done += chunk) {
                const int now = std::min(chunk, repeats - done);
                std::int64_t result = 0;
                seconds += fastestOfThree([&] { return replay(k, now); }, &result);
                *found += result;
            }
        }
        return seconds;
    };
    const double bv_seconds = timeReplays(
        bv_repeats,
        [](const collision::BvhTestSample& s) {
            return static_cast<std::int64_t>(s.node_pairs.size());
        },
        [&](std::size_t k, int repeats) {
            return collision::replayVolumeTests(a, b, poses[k], samples[k], repeats);
        },
        &costs.bv_overlaps);
    const double tri_seconds = timeReplays(
        tri_repeats,
        [](const collision::BvhTestSample& s) {
            return static_cast<std::int64_t>(s.triangle_pairs.size());
        },
        [&](std::size_t k, int repeats) {
            return collision::replayTriangleTests(a, b, poses[k], samples[k], repeats);
        },
        &costs.triangle_hits);
    costs.bv_test_ns = 1e9 * bv_seconds / static_cast<double>(costs.bv_tests_timed);
    costs.triangle_test_ns = 1e9 * tri_seconds / static_cast<double>(costs.triangle_tests_timed);
    costs.measured = true;
    return costs;
}

RefitUnitCost measureRefitUnitCost(std::string_view volume, const collision::TriangleMesh& mesh,
                                   std::int64_t node_target) {
    RefitUnitCost cost;
    const std::unique_ptr<collision::MeshBvh> tree = collision::buildMeshBvh(volume, mesh);
    if (!tree || tree->nodeCount() == 0) return cost;
    const std::int64_t nodes = tree->nodeCount();
    const std::int64_t repeats = std::max<std::int64_t>(1, (node_target + nodes - 1) / nodes);
    std::int64_t refitted = 0;
    const double seconds = fastestOfThree(
        [&] {
            std::int64_t n = 0;
            for (std::int64_t r = 0; r < repeats; ++r) n += tree->refit(mesh);
            return n;
        },
        &refitted);
    cost.nodes_timed = refitted;
    cost.refit_node_ns = refitted > 0 ? 1e9 * seconds / static_cast<double>(refitted) : 0;
    return cost;
}

}  // namespace app
