// app/lab/check_workers.h -- `cdlab check -j N` and `--timeout`: each scene graded by a child
// process (`cdlab check --worker-result FILE ...`, one scene each), at most N at a time, so a
// scene that crashes or hangs its process costs only its own row. The parent collects the
// children's reports (a length-prefixed text file each) in command-line order.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "check.h"

namespace app {

/// What the parent needs to grade scenes in child processes.
struct WorkerPlan {
    std::filesystem::path exe;  ///< the cdlab executable the children run
    std::vector<std::filesystem::path> scenes;
    std::optional<int> frames;        ///< as CheckOptions::frames
    std::filesystem::path dump_root;  ///< as CheckOptions::out_dir, resolved
    int jobs = 1;                     ///< children at a time, >= 1
    std::optional<double> timeout;    ///< wall-clock seconds per child
    std::optional<std::filesystem::path> events;  ///< as CheckOptions::events
};

/// Grades every scene of `plan` in child processes, at most `jobs` at once; one report per
/// scene, in the order of `plan.scenes`. A child that dies, exits without a report or outlives
/// the timeout (then it is killed) gives a NotRun report saying so; what it printed is kept in
/// the report's `log`. Labels are the scene paths as given (sceneLabel). The children die with this process
/// (PR_SET_PDEATHSIG), so a check killed from outside leaves none grading for nobody. Throws
/// render::RenderError when the folder of the children's reports cannot be made.
std::vector<SceneReport> gradeInWorkers(const WorkerPlan& plan);

/// The child's side: grades scene number `index` (gradeSceneFile) and writes its report to
/// `result`. Returns the process exit code: 0 when the report was written, whatever the grade.
/// (The parent set it up, before exec, to be killed when the parent dies.)
int runCheckWorker(const std::filesystem::path& scene, std::size_t index, std::optional<int> frames,
                   const std::filesystem::path& dump_root, const std::filesystem::path& result,
                   const std::optional<std::filesystem::path>& events = std::nullopt);

/// The report as a child writes it: length-prefixed byte strings, so any bytes a scene file
/// puts into a body name come back unchanged. parseWorkerReport returns nullopt on anything
/// that is not a whole report.
std::string formatWorkerReport(const SceneReport& report);
std::optional<SceneReport> parseWorkerReport(const std::string& text);

}  // namespace app
