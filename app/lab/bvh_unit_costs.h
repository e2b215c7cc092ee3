// app/lab/bvh_unit_costs.h -- measured unit costs of the BVH cost model F = Nv Cv + Np Cp: the time
// of one node-volume test (Cv) and one triangle test (Cp), from replaying the tests the
// all-pairs query really makes at the given poses; and Cu, the time per node of a refit (the
// Nu Cu term of a deforming mesh). Used by `cdlab query` and `bench narrowphase`.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "collision/bvh/bvh.h"
#include "collision/bvh/bvh_replay.h"

namespace app {

/// Cv and Cp of one pair of trees over a set of poses.
struct BvhUnitCosts {
    double bv_test_ns = 0;        ///< Cv: ns per node-pair volume test (B's volume moved included)
    double triangle_test_ns = 0;  ///< Cp: ns per triangle test (B's triangle moved included)
    std::int64_t bv_tests_timed = 0;        ///< tests in the timed batch (one repetition)
    std::int64_t triangle_tests_timed = 0;  ///< tests in the timed batch (one repetition)
    /// true: the triangle pairs the queries tested; false: no query reached a triangle test, so
    /// the batch is uniformly random triangle pairs of the two meshes at the first pose
    bool triangles_from_queries = true;
    std::int64_t bv_overlaps = 0;    ///< overlapping tests in the timed batch (keeps the work)
    std::int64_t triangle_hits = 0;  ///< intersecting pairs in the timed batch
    /// false: nothing was timed and the costs above are not measurements (no poses, an empty
    /// mesh, or the wide tree, kWideObbName, whose node tests the replay cannot record)
    bool measured = false;
};

/// Why a row's Cv and Cp read "-", for the tables' footnotes.
inline constexpr const char* kUnmeasuredUnitCostsNote =
    "Cv, Cp \"-\": not measured: obb4 tests up to four boxes of a node at once in SSE2 "
    "lanes inside its traversal, and the replay times single node-pair tests";

/// Records the node pairs and triangle pairs that a.intersect(b, pose) tests at every pose
/// (collision::recordTests), repeats those lists until a batch holds at least `bv_target` volume
/// tests and `triangle_target` triangle tests (each pose's list the same number of times, so
/// poses weigh as their Nv and Np do in F), and times the replays in chunks of about one query's
/// tests, each the fastest of 3 runs. None of this is inside a query's timed path. `a` and `b`
/// hold the same volume type. Cost about 3 times the batch. A tree the replay cannot record
/// (kWideObbName) gets zero costs and measured = false.
BvhUnitCosts measureBvhUnitCosts(const collision::MeshBvh& a, const collision::MeshBvh& b,
                                 std::span<const collision::Pose> poses,
                                 std::int64_t bv_target = 200000,
                                 std::int64_t triangle_target = 100000);

/// Cu of one volume type on one mesh.
struct RefitUnitCost {
    double refit_node_ns = 0;        ///< Cu: ns per node refitted (MeshBvh::refit / its Nu)
    std::int64_t nodes_timed = 0;    ///< nodes in the timed batch (one repetition)
};

/// Builds the `volume` tree of `mesh` and times refits of it to the same vertices (the same work
/// as a refit to a deformed copy: every node's volume refitted to its triangles' corners),
/// repeated until a batch holds at least `node_target` nodes, fastest of 3. A refit node's cost
/// grows with its subtree (a node is fitted to all its corners): Cu is per node on this mesh.
RefitUnitCost measureRefitUnitCost(std::string_view volume, const collision::TriangleMesh& mesh,
                                   std::int64_t node_target = 200000);

}  // namespace app
