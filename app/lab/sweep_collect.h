// app/lab/sweep_collect.h -- `cdlab sweep --collect DIR`: the result files of a planned sweep's
// jobs (sweep_job.h) merged into the results.csv, report.md and charts the one-process sweep
// writes; every job that left no result is named, never silently left out.
#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <vector>

#include "sweep.h"
#include "sweep_plan.h"

namespace app::sweep {

/// What the jobs of a plan left.
struct CollectedSweep {
    /// The combinations with a result, in plan order, compared with the reference (empty
    /// without a reference).
    std::vector<SweepRun> runs;
    std::optional<SweepRun> reference;  ///< none when the reference job left no result
    /// Every job without a usable result (missing file, failure record), in plan order.
    std::vector<SweepFailure> failures;
    /// Two jobs' timed intervals overlapped on one host, or the jobs ran on several hosts.
    bool timed_concurrently = false;
};

/// Reads every result of `plan`. Nothing (with every bad file named in `err`) when a result
/// file is malformed or belongs to another plan or job: that is bad input, not a failed job.
std::optional<CollectedSweep> gatherResults(const SweepPlan& plan, std::ostream& err);

struct CollectOptions {
    std::filesystem::path plan;     ///< the plan's directory (or its plan.json)
    std::filesystem::path out_dir;  ///< default: the plan's directory
    bool report_timing = true;      ///< as SweepOptions::report_timing
};

/// Collects the plan's results and writes results.csv, report.md and the charts. Exit codes:
/// 0 every job had a result; 1 some job left none (each named on `err` and in report.md;
/// without the reference's result only report.md is written, naming the failures) or an output
/// failed; 2 bad input (no or malformed plan, a malformed or foreign result file; nothing
/// written).
int collectSweep(const CollectOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app::sweep
