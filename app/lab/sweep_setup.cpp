// app/lab/sweep_setup.cpp -- see sweep_setup.h.
#include "sweep_setup.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "sweep_measure.h"
#include "sweep_report.h"

namespace app::sweep {

namespace fs = std::filesystem;

namespace {

using Axes = std::vector<std::pair<std::string, std::vector<std::string>>>;

// The axes of --vary and the overrides of --reference; an error message and false when one is
// malformed or a key is given twice.
bool parseSweepOptions(const SweepOptions& options, std::ostream& err, Axes& axes,
                       std::vector<engine::SceneOverride>& reference_overrides) {
    for (const std::string& v : options.vary) {
        std::string key, error;
        std::vector<std::string> values;
        if (!parseVary(v, key, values, error)) {
            err << "--vary " << error << "\n";
            return false;
        }
        for (const auto& axis : axes) {
            if (axis.first == key) {
                err << "--vary " << key << ": given twice; list every value in one --vary (" << key
                    << "=A,B,...)\n";
                return false;
            }
        }
        axes.emplace_back(key, values);
    }
    for (const std::string& v : options.reference) {
        std::string key, error;
        std::vector<std::string> values;
        if (!parseVary(v, key, values, error) || values.size() != 1) {
            err << "--reference " << (error.empty() ? "'" + v + "': expected KEY=VALUE" : error)
                << "\n";
            return false;
        }
        reference_overrides.push_back({key, values[0], "--reference"});
    }
    if (!(options.reference_refine >= 1) || !std::isfinite(options.reference_refine)) {
        err << "--reference-refine: must be a finite number >= 1\n";
        return false;
    }
    if (options.repeat < 1) {
        err << "--repeat " << options.repeat
            << ": must be >= 1 (each run is timed this many times; 3 gives a min..max spread)\n";
        return false;
    }
    if (options.duration && !(*options.duration > 0 && std::isfinite(*options.duration))) {
        err << "--duration: must be a finite number > 0\n";
        return false;
    }

    return true;
}

// Every combination of the axes' values, in axis order (one empty combination without axes).
std::vector<std::vector<engine::SceneOverride>> combinations(const Axes& axes) {
    std::vector<std::vector<engine::SceneOverride>> combos{{}};
    for (const auto& [key, values] : axes) {
        std::vector<std::vector<engine::SceneOverride>> next;
        for (const auto& c : combos) {
            for (const std::string& v : values) {
                next.push_back(c);
                next.back().push_back({key, v, "--vary"});
            }
        }
        combos = std::move(next);
    }
    return combos;
}

}  // namespace

std::optional<SweepSetup> setUpSweep(const SweepOptions& options, std::ostream& err) {
    Axes axes;
    std::vector<engine::SceneOverride> reference_overrides;
    if (!parseSweepOptions(options, err, axes, reference_overrides)) return std::nullopt;
    // Every combination is loaded (and so validated) before anything runs.
    const std::vector<std::vector<engine::SceneOverride>> combos = combinations(axes);
    engine::Scene base;
    std::vector<engine::Scene> scenes;
    try {
        base = engine::loadScene(options.scene);
        for (const std::string& note : base.notes) err << note << "\n";
    } catch (const engine::SceneError& e) {
        err << e.what() << "\n";
        return std::nullopt;
    }
    for (const auto& c : combos) {
        try {
            scenes.push_back(engine::loadScene(options.scene, c));
        } catch (const engine::SceneError& e) {
            err << "sweep run '" << labelOf(c) << "': " << e.what() << "\n";
            return std::nullopt;
        }
    }
    const double duration = options.duration ? *options.duration
                                             : double(std::max(base.frames - 1, 1)) *
                                                   base.steps_per_frame * base.world.time_step;
    engine::Scene reference_scene;
    // %.17g: the refined step survives the trip through text (and a plan file) bit for bit.
    std::vector<engine::SceneOverride> ref = {
        {"world.time_step", fmt(base.world.time_step / options.reference_refine, "%.17g")}};
    ref.insert(ref.end(), reference_overrides.begin(), reference_overrides.end());
    try {
        reference_scene = engine::loadScene(options.scene, ref);
    } catch (const engine::SceneError& e) {
        err << "sweep reference: " << e.what() << "\n";
        return std::nullopt;
    }

    // Steps per run, checked before anything runs: llround of a huge quotient is undefined, and
    // a run of 1e20 s would never end.
    constexpr double kMaxSweepSteps = 1e9;
    std::vector<const engine::Scene*> all_runs{&reference_scene};
    for (const engine::Scene& s : scenes) all_runs.push_back(&s);
    for (const engine::Scene* s : all_runs) {
        const double steps = duration / s->world.time_step;
        if (!(steps <= kMaxSweepSteps)) {
            err << "--duration " << fmt(duration) << ": " << fmt(steps) << " steps at time step "
                << fmt(s->world.time_step) << " s, more than the limit of " << fmt(kMaxSweepSteps)
                << "\n";
            return std::nullopt;
        }
    }

    SweepSetup setup;
    setup.out_dir =
        options.out_dir.empty() ? fs::path("out") / ("sweep_" + base.name) : options.out_dir;
    setup.base = std::move(base);
    setup.combos = combos;
    setup.scenes = std::move(scenes);
    setup.reference_overrides = std::move(reference_overrides);
    setup.reference_run = std::move(ref);
    setup.reference_scene = std::move(reference_scene);
    setup.duration = duration;
    return setup;
}

}  // namespace app::sweep
