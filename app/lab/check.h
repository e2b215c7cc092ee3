// app/lab/check.h -- `cdlab check`: runs scenes headless and grades them against their
// `expect:` sections (engine/scene.h), printing a pass/fail table with a reason per failure.
#pragma once

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
    /// Where pause dumps are written; default: a temporary folder removed afterwards.
    std::optional<std::filesystem::path> out_dir;
};

/// Runs `scene` for `frames` frames (frame 0 = initial state) and grades every expectation.
/// Renders only for `colors` and `pause_dumps`; pause dumps go to `dump_dir`. A scene without an
/// `expect:` section gets one failing row. Deterministic: same scene -> same rows (except paths).
/// Throws render::RenderError when rendering or writing fails.
std::vector<CheckRow> checkScene(const engine::Scene& scene, int frames,
                                 const std::filesystem::path& dump_dir);

/// Exit codes: 0 every expectation of every scene passed, 1 any failed (or could not run),
/// 2 bad input (a scene that does not load, a bad flag); no scene runs when any is bad.
int runCheck(const CheckOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app
