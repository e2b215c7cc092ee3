// app/lab/bench/bench_narrowphase.h -- `cdlab bench narrowphase`: mesh-mesh queries on two procedural tori
// over fixed random poses (half of them colliding), every cdlab BVH volume type beside FCL's
// BVHModel types, with every answer checked against cdlab's brute-force triangle loop.
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace app {

struct BenchNarrowphaseOptions {
    int triangles = 10000;  ///< per torus (rounded to 2 nu nv with nu = 2 nv); >= 32
    bool large = false;     ///< 100k-triangle tori (overrides `triangles`)
    int poses = 32;         ///< even, >= 2: half colliding, half not
    int reps = 3;  ///< repetitions per pose (and of the build, at most 3); the fastest counts
    /// The method list measured this many times (1..kMaxBenchRounds, bench_broadphase.h), in
    /// order then in reverse, in turn; each time is the median over the rounds, so a stretch
    /// where the machine runs slow costs a round, not a method.
    int rounds = 1;
    std::uint64_t seed = 7;
    /// Method names (cdlab volume names, NAME-bu for the bottom-up build, "fcl-obbrss", ...);
    /// empty: every volume name (top-down) and every FCL type.
    std::vector<std::string> methods;
    std::optional<std::filesystem::path> json;  ///< also write the table as JSON
};

/// Names accepted by --methods, in table order.
std::vector<std::string> narrowphaseBenchMethods();

/// Prints one row per method: build ms (one tree), first-contact and all-pairs µs per query (mean
/// over poses of the fastest repetition; with rounds, the median over the rounds), Nv and Np per
/// query, and answer mismatches against the brute force. Exit codes: 0 success; 1 a cdlab method
/// disagreed with the brute force, or the JSON could not be written; 2 bad options.
int runBenchNarrowphase(const BenchNarrowphaseOptions& options, std::ostream& out,
                        std::ostream& err);

}  // namespace app
