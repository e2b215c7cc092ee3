// app/lab/sweep_setup.h -- a sweep checked before anything runs: the --vary axes and their
// combinations, every run's scene loaded (and so validated), the reference's settings, the
// interval simulated and the output directory. Shared by the one-process sweep and the plan.
#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <vector>

#include "engine/scene.h"
#include "sweep.h"

namespace app::sweep {

struct SweepSetup {
    engine::Scene base;  ///< the scene as written
    /// Every combination of the --vary values, the last --vary changing fastest.
    std::vector<std::vector<engine::SceneOverride>> combos;
    std::vector<engine::Scene> scenes;  ///< combos[i] applied to the scene
    /// --reference as given (the reference's label).
    std::vector<engine::SceneOverride> reference_overrides;
    /// What makes the reference scene: the refined time step, then --reference.
    std::vector<engine::SceneOverride> reference_run;
    engine::Scene reference_scene;
    double duration = 0;  ///< simulated seconds per run
    std::filesystem::path out_dir;
};

/// Parses and checks the options, loads the scene under every combination and the reference's
/// settings, and checks each run's step count. On bad input prints `file:line:col: ...` or the
/// flag at fault to `err` and returns nothing.
std::optional<SweepSetup> setUpSweep(const SweepOptions& options, std::ostream& err);

}  // namespace app::sweep
