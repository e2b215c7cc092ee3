// app/lab/check.h -- `cdlab check`: runs scenes headless and grades them against their
// `expect:` sections (engine/scene.h), printing a pass/fail table with a reason per failure and,
// on request, a JUnit XML report (junit_report.h). Scenes are graded one after the other in
// this process, or several at once in child processes (check_workers.h). A scene with an events
// track (its own `events:`, or `--events FILE` with that file's `expect:`) is graded on the run
// through the track, played as `cdlab run` plays it (demo/demo_playback.h).
#pragma once

#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "checkers.h"
#include "engine/scene.h"

namespace app {

struct CheckOptions {
    std::vector<std::filesystem::path> scenes;
    std::optional<int> frames;  ///< overrides expect.frames and the scene's frame count
    /// An events file each scene's run follows instead of its own `events:` (as `cdlab run
    /// --events`); its `expect:`, when it has one, replaces the scene's (loadCheckScene).
    std::optional<std::filesystem::path> events;
    /// Where pause dumps are written; default: a temporary folder removed afterwards. Scene k
    /// (from 0, command-line order) writes into `k_STEM`, so two scenes of the same file name
    /// never share a folder.
    std::optional<std::filesystem::path> out_dir;
    /// Scenes graded at once, each in a child process; 1 (default) grades them one after the
    /// other in this process; 0 = one per core this process may run on.
    int jobs = 1;
    /// Wall-clock seconds a scene may take; a scene still running then is stopped (SIGKILL)
    /// and fails its "run" row. Grades in a child process even with jobs == 1.
    std::optional<double> timeout;
    /// Grade the scenes that load when others do not (each bad one gets a failing "load" row);
    /// without it a bad scene stops the check before any scene runs. Implied by `junit`.
    bool keep_going = false;
    /// Write a JUnit XML report here (junit_report.h), atomically.
    std::optional<std::filesystem::path> junit;
    /// The cdlab executable a child process runs (`cdlab check --worker-result ...`):
    /// /proc/self/exe from the command line. Used only when grading in child processes.
    std::filesystem::path worker_exe;
    /// Check the options and load every scene, then return (0, or 2 for bad input) before any
    /// scene runs or any file or folder is written (`cdlab --dry-run check ...`).
    bool dry_run = false;
};

/// How the grading of one scene ended.
enum class SceneOutcome {
    Graded,     ///< it ran; `rows` has one row per expectation
    NotLoaded,  ///< the scene file is bad input; one "load" row with file:line:col: message
    NotRun,     ///< it loaded but could not run to the end (render error, crash, timeout); one
                ///< "run" row saying why
};

/// The grading of one scene, in whatever process it ran.
struct SceneReport {
    std::string label;  ///< the scene file as given on the command line
    SceneOutcome outcome = SceneOutcome::NotRun;
    std::vector<CheckRow> rows;
    std::vector<std::string> notes;  ///< the loader's notes about the file
    std::string log;                 ///< what a child process wrote to stdout and stderr
    double seconds = 0;              ///< wall-clock seconds of running and grading (not loading)
};

/// Runs `scene` for `frames` frames (frame 0 = initial state) and grades every expectation.
/// Renders only for `colors` and `pause_dumps`; pause dumps go to `dump_dir`. A scene without an
/// `expect:` section gets one failing row. Deterministic: same scene -> same rows (except paths).
/// A scene with `events` is run through them on a DemoSession of `frames` frames, as `cdlab run`
/// plays them: every step taken (re-simulated ones after stepping back too) and every frame
/// shown (as often as shown) reach the checkers; frames the track never shows fail the
/// expectations on them; dumps are the track's `dump: true` entries.
/// Throws render::RenderError when rendering or writing fails, engine::SceneError when the
/// track does not fit `frames`.
std::vector<CheckRow> checkScene(const engine::Scene& scene, int frames,
                                 const std::filesystem::path& dump_dir);

/// checkScene for scene number `index` of a check: frames from `frames`, else expect.frames,
/// else the scene's; pause dumps in `dump_root / "INDEX_STEM"`. Never throws for a scene that
/// cannot run: that is a NotRun report.
SceneReport gradeScene(const engine::Scene& scene, std::size_t index, std::optional<int> frames,
                       const std::filesystem::path& dump_root);

/// The scene a check grades: `file` as loaded; with `events`, that file's track in place of the
/// scene's `events:` (read against the scene, its frames set to `frames` first, as `cdlab run
/// --frames N --events FILE` reads it) and its `expect:` in place of the scene's, or, when the
/// file has none, the scene's graded through the track (refused where it cannot be:
/// engine::requireGradableThroughEvents). Throws engine::SceneError.
engine::Scene loadCheckScene(const std::filesystem::path& file,
                             const std::optional<std::filesystem::path>& events,
                             std::optional<int> frames);

/// The table's name of a scene: the file as given, and " --events FILE" when one is given.
std::string sceneLabel(const std::filesystem::path& file,
                       const std::optional<std::filesystem::path>& events);

/// Loads `file` (loadCheckScene) and grades it as gradeScene; a file that does not load is a
/// NotLoaded report (its message in the "load" row), never an exception.
SceneReport gradeSceneFile(const std::filesystem::path& file, std::size_t index,
                           std::optional<int> frames, const std::filesystem::path& dump_root,
                           const std::optional<std::filesystem::path>& events = std::nullopt);

/// Exit codes: 0 every expectation of every scene passed, 1 any failed (or could not run, or
/// the JUnit report could not be written), 2 bad input (a bad flag, or a scene that does not
/// load). A bad scene stops the check before any scene runs unless `keep_going` or `junit`;
/// then the other scenes are graded and the exit code is still 2. The table (stdout) and the
/// report list the scenes in command-line order and are the same for every `jobs`.
int runCheck(const CheckOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app
