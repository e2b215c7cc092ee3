// app/lab/sweep_job.h -- one job of a planned sweep (`cdlab sweep --job DIR/plan.json --run K`):
// run K of the plan measured like a run of the one-process sweep, written to DIR/results/K.json
// with everything the collect step needs (the run's columns, its repeats' timings and its
// per-pair first contacts, which accuracy compares with the reference's).
#pragma once

#include <cstddef>
#include <filesystem>
#include <ostream>
#include <string>

#include "sweep.h"
#include "sweep_measure.h"
#include "sweep_plan.h"

namespace app::sweep {

/// What a result file holds.
struct JobResult {
    std::size_t run = 0;
    std::string failure;  ///< non-empty: the job failed, and this is why (no measurement)
    /// The run, timed columns summarised over the repeats; label, overrides and the accuracy
    /// columns are filled in by the collect step.
    SweepRun measured;
    FirstContacts contacts;  ///< every pair's first contact (s)
    double started = 0;      ///< wall clock (system_clock), s since the epoch
    double finished = 0;
    long pid = 0;
};

/// The result file's text. Every double is written as the shortest decimal that reads back to
/// the same bits (nlohmann::json), or "inf" / "-inf" / "nan", so collected columns are
/// bit-identical to the one-process sweep's.
std::string resultJson(const SweepPlan& plan, const JobResult& result);

/// Parses a result file of job `k` of `plan`. Throws std::runtime_error saying what is wrong:
/// malformed JSON, a missing field, another plan's id, another run's number.
JobResult parseResult(const std::string& text, const SweepPlan& plan, std::size_t k);

/// Runs job `k` of the plan at `plan_path` (a plan directory or its plan.json) and writes its
/// result atomically (a killed job leaves none). Exit codes: 0 measured; 1 the run failed (a
/// repeat differs from the first, the result cannot be written); 2 bad input (unreadable plan,
/// no job `k`, a scene that no longer loads or differs from the planned one). A job that ran
/// and failed writes a failure record naming the reason, so collect can name it.
int runSweepJob(const std::filesystem::path& plan_path, long k, std::ostream& out,
                std::ostream& err);

}  // namespace app::sweep
