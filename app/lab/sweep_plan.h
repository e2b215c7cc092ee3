// app/lab/sweep_plan.h -- a sweep split into independent jobs (`cdlab sweep --plan DIR`): one
// job per run (the reference first, then every combination), each a command line of
// DIR/jobs.txt that any engine can run (a shell loop, GNU Parallel, a Slurm job array) and that
// writes DIR/results/K.json (sweep_job.h); `cdlab sweep --collect DIR` merges them
// (sweep_collect.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "engine/scene.h"
#include "sweep.h"
#include "sweep_setup.h"

namespace app::sweep {

/// One job of a plan: a run of the scene under its overrides.
struct PlannedRun {
    std::string label;  ///< as SweepRun::label; the reference's is its --reference label
    std::vector<engine::SceneOverride> overrides;
};

/// Everything a job needs, pinned when the sweep is planned, so that jobs run anywhere the
/// same paths hold the same scene, assets and binary.
struct SweepPlan {
    std::string id;             ///< FNV-1a (hex) of the plan's content; in every result file
    std::filesystem::path dir;  ///< the plan's directory (absolute; not stored, where it was read)
    std::filesystem::path scene;   ///< absolute
    std::string scene_hash;        ///< FNV-1a (hex) of the scene file's bytes when planned
    std::filesystem::path binary;  ///< absolute path of the cdlab the jobs run
    double duration = 0;           ///< simulated seconds per run
    int repeat = 1;
    double reference_refine = 10;
    std::vector<std::string> vary;       ///< --vary as given (the report reads the keys)
    std::vector<std::string> reference;  ///< --reference as given
    std::string created;                 ///< UTC, ISO 8601
    std::string nonce;                   ///< random, so two plans never share an id
    std::vector<PlannedRun> runs;        ///< runs[0] is the reference
};

/// The plan of `setup`'s runs for jobs running `binary`, in `dir`.
SweepPlan makePlan(const SweepOptions& options, const SweepSetup& setup,
                   const std::filesystem::path& binary, const std::filesystem::path& dir);

/// `cdlab sweep SCENE --vary ... --plan DIR [--slurm]`: checks the sweep as the one-process
/// sweep does (every run's scene loads), then writes the plan. `binary`: the cdlab the jobs run.
/// Exit codes: 0 planned, 1 output failure, 2 bad input (nothing written).
int planSweep(const SweepOptions& options, const std::filesystem::path& dir, bool slurm,
              const std::filesystem::path& binary, std::ostream& out, std::ostream& err);

/// Writes DIR/plan.json and DIR/jobs.txt (line K + 1 runs job K), DIR/sweep.sbatch with
/// `slurm`, and empties DIR/results and DIR/logs, so no result of an earlier plan remains.
/// Throws on an output failure.
void writePlan(const SweepPlan& plan, bool slurm);

/// Reads `path` (a plan directory or its plan.json) and checks it: format, fields, and that its
/// id matches its content (an edited plan is refused). Nothing on error, with the reason
/// (naming the file) in `err`.
std::optional<SweepPlan> readPlan(const std::filesystem::path& path, std::ostream& err);

/// Job K's command line: `'BINARY' sweep --job 'DIR/plan.json' --run K`.
std::string jobCommand(const SweepPlan& plan, std::size_t k);

/// DIR/sweep.sbatch: a Slurm job array with one task per job, task K running line K + 1 of
/// jobs.txt, and the collect step to submit after it.
std::string slurmScript(const SweepPlan& plan);

/// Where job K writes its result: DIR/results/K.json.
std::filesystem::path resultPath(const SweepPlan& plan, std::size_t k);

/// FNV-1a, 64 bits, as 16 hex digits.
std::string fnv1aHex(const std::string& bytes);

/// `s` single-quoted for /bin/sh: every character literal, ' written as '\''.
std::string shellQuote(const std::string& s);

}  // namespace app::sweep
