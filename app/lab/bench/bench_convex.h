// app/lab/bench/bench_convex.h -- `cdlab bench convex`: microseconds per convex contact query (GJK distance,
// EPA depth, SAT box-box, sphere/capsule closed forms) beside the path Bullet runs for each pair
// (its dispatcher's algorithm) and its general GJK/EPA on the same random poses, with every
// answer's error against an exact reference.
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>

namespace app {

struct BenchConvexOptions {
    int queries = 20000;     ///< random pairs per workload
    int passes = 5;          ///< timed passes over the pairs; the median pass is reported
    std::uint64_t seed = 1;  ///< pose generator seed
    /// Relative tolerance of the accuracy count: |signed distance - exact| above
    /// tolerance * (larger bounding radius) counts as a wrong answer.
    double tolerance = 1e-6;
    /// Run only the workloads whose name contains this text (all when empty).
    std::string workload;
    std::optional<std::filesystem::path> json;  ///< also write the rows as JSON
};

/// Runs every workload through cdlab's contact() and (when built with Bullet) the row's Bullet
/// path, prints one row per workload and writes the JSON. Exit codes: 0 success (wrong answers
/// are reported, not fatal); 1 the JSON could not be written; 2 bad options.
int runBenchConvex(const BenchConvexOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app
