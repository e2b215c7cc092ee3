// collision/bvh/bvh_replay.h -- the tests one all-pairs query of two hierarchies makes, recorded
// and replayed alone: how `cdlab bench narrowphase` and `cdlab query` time the unit costs Cv and
// Cp of the cost model F = Nv Cv + Np Cp on the real work of a query.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "collision/bvh/bvh.h"

namespace collision {

/// The node pairs and triangle pairs one all-pairs query tests, in the order it tests them
/// (recordTests): a sample of the real work of a query, for measuring the cost model's
/// unit costs Cv and Cp by replaying it (replayVolumeTests, replayTriangleTests).
struct BvhTestSample {
    std::vector<std::array<std::int32_t, 2>> node_pairs;  ///< (node of A, node of B), node indices
    /// (triangle of A, triangle of B) as leaf-order positions (Bvh::leafTriangle), in [0,
    /// triangleCount()) of each tree
    std::vector<std::array<std::int32_t, 2>> triangle_pairs;
};

/// Every node pair and triangle pair that a.intersect(b, b_in_a) tests, in its order
/// (node_pairs.size() is its Nv, triangle_pairs.size() its Np): the same traversal with a
/// recorder; the queries themselves record nothing. `b` must hold a's volume type (asserted;
/// empty if not). Empty for the wide tree (kWideObbName): its queries test up to four boxes of a
/// node at once in lanes, not the binary tree's node pairs. Memory O(Nv + Np).
BvhTestSample recordTests(const MeshBvh& a, const MeshBvh& b, const Pose& b_in_a);

/// Runs the node-volume tests of `sample`, `repeats` times, exactly as the traversal does them
/// (B's node volume moved into A's frame once per run of pairs with the same B node, then the
/// overlap test, with its slack) and nothing else, for timing Cv. Returns the number of tests
/// that found an overlap (all repeats); -1 when an index of `sample` is out of range; 0 when the
/// volume types differ (asserted).
std::int64_t replayVolumeTests(const MeshBvh& a, const MeshBvh& b, const Pose& b_in_a,
                               const BvhTestSample& sample, int repeats);

/// Runs the triangle tests of `sample`, `repeats` times, as the traversal does them (B's
/// triangle moved into A's frame, then the exact triangle-triangle test), for timing Cp.
/// Returns the number of intersecting pairs (all repeats); -1 when an index is out of range.
std::int64_t replayTriangleTests(const MeshBvh& a, const MeshBvh& b, const Pose& b_in_a,
                                 const BvhTestSample& sample, int repeats);

}  // namespace collision
