// app/lab/sweep_local.h -- `cdlab sweep ... -j N`: the sweep planned into OUT/plan (sweep_plan.h),
// its jobs run here N at a time as child processes, then collected into OUT (sweep_collect.h).
#pragma once

#include <filesystem>
#include <ostream>

#include "sweep.h"
#include "sweep_plan.h"
#include "sweep_setup.h"

namespace app::sweep {

/// Runs every job of `plan` (`plan.binary sweep --job ... --run K`), at most `jobs` at a time,
/// stdout and stderr of job K in DIR/logs/K.log. Returns how many jobs exited non-zero (their
/// results, or the lack of them, are for the collect step to name).
int runJobsLocally(const SweepPlan& plan, int jobs, std::ostream& out);

/// The one-process sweep's outputs through a plan: plans `setup` into OUT/plan, runs its jobs
/// options.jobs at a time with options.cdlab_binary (required: `cdlab sweep` passes its own
/// executable) and collects them into OUT. Exit codes as collectSweep's.
int runPlannedLocally(const SweepOptions& options, const SweepSetup& setup, std::ostream& out,
                      std::ostream& err);

}  // namespace app::sweep
