// app/lab/bench/bench_rows.h -- the rows of `cdlab bench broadphase` (private to it): one method's
// measurement, one table row, and what the methods of one table run on; shared by the bench
// (bench_broadphase.cpp) and its peer tuning (bench_peer_tuning.cpp).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <limits>
#include <string>
#include <vector>

#include "bench_broadphase.h"
#include "bench_method.h"
#include "bench_workload.h"

namespace app {

/// One method's measurement. Plain data: a child process sends it to the parent through a pipe.
struct RunResult {
    int failed = 0;  ///< nonzero: `note` says why
    double insert_ms = 0;
    double median_ms = 0;
    double mean_ms = 0;
    double exact_median_ms = 0;  ///< with deliverExact() in the timed frame
    double first_median_ms = 0;
    double last_median_ms = 0;
    int frames_run = 0;
    int budget_hit = 0;
    std::int64_t pairs_last = 0;
    std::int64_t raw_pairs_last = -1;
    std::int64_t potentially_colliding_last = -1;
    int mismatched_frames = 0;
    int first_mismatch_frame = -1;
    std::int64_t expected_pairs = 0;
    std::int64_t got_pairs = 0;
    double peak_mb = std::numeric_limits<double>::quiet_NaN();
    char note[240] = {};
};

struct Row {
    std::string method;
    std::string workload;  ///< with " one-shot" for one-shot tables
    int n = 0;
    bool peer = false;
    std::string family;    ///< a tuned peer's name (its winning configuration is `method`)
    int configs = 0;       ///< configurations the tuned peer was chosen from
    std::string tuned_by;  ///< what it was the fastest by: median_ms, exact_ms or both
    bool skipped = false;
    std::string skip_reason;
    std::string clock;  ///< clockName() of the method's frames
    RunResult result;  ///< with --rounds R > 1: each figure the median over `rounds`
    double ratio = std::numeric_limits<double>::quiet_NaN();
    double exact_ratio = std::numeric_limits<double>::quiet_NaN();  ///< exact-pairs rule
    /// With --rounds R > 1: the row's result in each round, and its ratios to the best peer of
    /// that round under each rule (empty otherwise).
    std::vector<RunResult> rounds;
    std::vector<double> round_ratios;
    std::vector<double> round_exact_ratios;
};

/// What every method of one table runs on.
struct TableRun {
    const MovingBoxes& workload;
    const std::vector<PairSummary>& reference;
    const BenchOptions& options;
    bool one_shot;
    std::ostream& out;
    std::ostream& err;
    bool& failed;
};

/// A row that ran to the end and agreed with the reference: the only rows ratios are taken from.
inline bool usable(const Row& row) {
    return !row.skipped && !row.result.failed && row.result.mismatched_frames == 0;
}

/// The workload's name, with " one-shot" for one-shot tables.
inline std::string tableName(const MovingBoxes& workload, bool one_shot) {
    return std::string(workloadName(workload.kind())) + (one_shot ? " one-shot" : "");
}

/// Runs one method on a table with `options` (or a row saying why not), reporting progress
/// and mismatches (bench_broadphase.cpp).
Row runMethod(const BenchMethodEntry& m, const TableRun& run, const BenchOptions& options);

/// The methods measured together on a table (--interleave): each on its own copy of the
/// workload, all alive at once, advanced `turn_frames` frames per turn (one-shot: one repetition)
/// with the order reversed every turn, so a stretch in which the machine runs slow costs them
/// alike. In a forked child unless the options say in-process; no peak memory. Results in the
/// entries' order.
std::vector<RunResult> measureTogether(const std::vector<const BenchMethodEntry*>& entries,
                                       const TableRun& run, int turn_frames);

/// Prints `row`'s progress line and any mismatch, and marks the run failed on a failure or a
/// mismatch of one of cdlab's methods.
void reportRun(const Row& row, const BenchMethodEntry& m, const TableRun& run);

}  // namespace app
