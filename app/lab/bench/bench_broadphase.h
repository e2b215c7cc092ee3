// app/lab/bench/bench_broadphase.h -- `cdlab bench broadphase`: cdlab's broad phases side by side with
// Bullet and FCL on the same moving-box workload, in the same process image.
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace app {

struct BenchOptions {
    std::vector<int> sizes{1000, 10000, 100000};  ///< box counts, each >= 2
    int frames = 1000;                            ///< measured frames per method, >= 1
    /// Method names (see benchMethods()); empty: every AABB-based cdlab broad phase and the
    /// default peer configurations found at configure time.
    std::vector<std::string> methods;
    std::string workload = "both";  ///< uniform | mixed | both | wide | boxpruning
    std::optional<std::filesystem::path> json;  ///< machine-readable rows
    std::uint64_t seed = 1;
    /// A method stops early (reporting the frames it ran) once its frames took this much thread
    /// CPU time in total, so an O(n^2) method cannot stall the run. <= 0: no limit.
    double budget_seconds = 60;
    /// Run each method in a forked child, so peak memory is per method and a crashing peer is
    /// reported instead of ending the run. Off: in-process, peak memory not reported.
    bool isolate = true;
    /// "thread": each frame's thread CPU time (steady under load from other processes; methods
    /// on more than one thread are left out); "wall": elapsed time, every method.
    std::string clock = "thread";
    /// Which peer configurations run when no --methods is given. "tuned": every configuration
    /// of each peer's tuning grid on the full run, the fastest of each peer by its median (and
    /// by its exact-pairs median) its row, ratios against the fastest of those; "all": the same, printing the whole grid;
    /// "default": each peer at its default settings only.
    std::string peers = "tuned";
    /// Each table's rows (cdlab's methods and the tuned peers' winners) run this many times,
    /// interleaved: round r runs every row once, in reverse order on even rounds, so a stretch
    /// in which the machine runs slow costs each row one round instead of costing one row its
    /// whole figure. Each figure is then the median over the rounds; the per-round ratios are
    /// printed beside it. The peers' tuning runs in the first round only. 1..kMaxBenchRounds.
    int rounds = 1;
    /// > 0: after each table's first pass (every row alone: the peers' tuning, peak memory, the
    /// check), its rows are timed `rounds` more times measured together (measureTogether): all
    /// alive at once, each advancing this many frames per turn (one-shot: one repetition), the
    /// order reversed every turn. A stretch in which the machine runs slow then costs every row
    /// alike however short a row's run is. The figures are the medians over those rounds; the
    /// first pass only chooses the rows and measures memory. 0: the rounds run row after row.
    int interleave = 0;
};

constexpr int kMaxBenchRounds = 50;
constexpr int kMaxInterleaveFrames = 1000;

/// A small configuration for smoke tests: 200 boxes, 20 frames, both workloads, all methods.
/// Runs in well under a second per method in Release.
BenchOptions smallBenchOptions();

/// Runs the benchmark, printing one table per workload and size to `out` (progress and
/// diagnostics to `err`) and writing --json rows if asked (written to FILE.partial, then renamed).
/// Exit codes: 0 success; 1 a method disagreed with the reference pairs (MISMATCH) or failed, or
/// the JSON file could not be written; 2 bad options (unknown method, size < 2, ...).
int runBenchBroadphase(const BenchOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app
