// app/lab/check.cpp -- `cdlab check`: runs each scene once and grades it with the checkers of
// its `expect:` section (checkers.h), which all watch that single run: frame 0 is the initial
// state, frame k is after k * steps_per_frame steps. Rows come out in a fixed order (the order of
// makeCheckers, then file order), so two checks of the same scene print the same table.
#include "check.h"

#include <iostream>
#include <string>
#include <unistd.h>
#include <vector>

#include <algorithm>
#include <memory>
#include <ostream>

#include "checkers.h"
#include "exit_codes.h"
#include "output_files.h"
#include "render/image.h"

namespace app {

namespace fs = std::filesystem;

std::vector<CheckRow> checkScene(const engine::Scene& scene, int frames, const fs::path& dump_dir) {
    std::vector<CheckRow> rows;
    if (!scene.expect.present) {
        rows.push_back({"expect", false, "the scene has no 'expect:' section"});
        return rows;
    }
    engine::World world = engine::makeWorld(scene);
    CheckRun run(scene, world, frames, dump_dir);
    const std::vector<std::unique_ptr<Checker>> checkers = makeCheckers(scene, world);
    for (int frame = 0; frame < frames; ++frame) {
        if (frame == 0) {
            for (const auto& c : checkers) c->observeStep(run, 0, std::nullopt);
        } else {
            for (int s = 0; s < scene.steps_per_frame; ++s) {
                const double step_start = double(world.time());
                world.step();
                for (const auto& c : checkers) c->observeStep(run, frame, step_start);
            }
        }
        for (const auto& c : checkers) c->observeFrame(run, frame);
    }
    for (const auto& c : checkers) c->report(run, rows);
    // The scene loader rejects an `expect:` that states nothing; an Expectations built in code
    // may still be empty, and checking nothing is no pass.
    if (rows.empty()) rows.push_back({"expect", false, "states no expectation"});
    return rows;
}

int runCheck(const CheckOptions& options, std::ostream& out, std::ostream& err) {
    if (options.scenes.empty()) {
        err << "check: no scene given\n";
        return kExitBadInput;
    }
    if (options.frames && *options.frames < 1) {
        err << "--frames: must be >= 1\n";
        return kExitBadInput;
    }
    // Every scene is loaded before any runs: bad input stops the whole check.
    std::vector<engine::Scene> scenes;
    bool bad = false;
    for (const fs::path& file : options.scenes) {
        try {
            scenes.push_back(engine::loadScene(file));
            for (const std::string& note : scenes.back().notes) err << note << "\n";
        } catch (const engine::SceneError& e) {
            err << e.what() << "\n";
            bad = true;
        }
    }
    if (bad) return kExitBadInput;

    fs::path dump_root;
    bool remove_dumps = false;
    std::error_code ec;
    if (options.out_dir) {
        dump_root = *options.out_dir;
    } else {
        dump_root = fs::temp_directory_path(ec) / ("cdlab_check_" + std::to_string(::getpid()));
        remove_dumps = true;
    }

    struct Line {
        std::string scene;
        CheckRow row;
    };
    std::vector<Line> lines;
    for (std::size_t i = 0; i < scenes.size(); ++i) {
        const engine::Scene& scene = scenes[i];
        const std::string label = options.scenes[i].string();
        const int frames = options.frames.value_or(scene.expect.frames.value_or(scene.frames));
        try {
            const fs::path dir = dump_root / (std::to_string(i) + "_" + scene.name);
            if (!scene.expect.pause_dumps.empty()) {
                fs::create_directories(dir, ec);
                if (ec) throw render::RenderError("cannot create " + dir.string());
            }
            for (CheckRow& r : checkScene(scene, frames, dir)) {
                lines.push_back({label, std::move(r)});
            }
        } catch (const std::exception& e) {
            lines.push_back({label, {"run", false, std::string("could not run: ") + e.what()}});
        }
    }
    if (remove_dumps) fs::remove_all(dump_root, ec);

    std::size_t scene_w = 5, what_w = 11;
    for (const Line& l : lines) {
        scene_w = std::max(scene_w, l.scene.size());
        what_w = std::max(what_w, l.row.expectation.size());
    }
    auto pad = [](const std::string& s, std::size_t w) {
        return s + std::string(w > s.size() ? w - s.size() : 0, ' ');
    };
    int failed = 0;
    out << pad("scene", scene_w) << "  " << pad("expectation", what_w) << "  result  reason\n";
    for (const Line& l : lines) {
        failed += l.row.pass ? 0 : 1;
        out << pad(l.scene, scene_w) << "  " << pad(l.row.expectation, what_w) << "  "
            << (l.row.pass ? "pass" : "FAIL    " + l.row.reason) << "\n";
    }
    out << scenes.size() << " scene" << (scenes.size() == 1 ? "" : "s") << ", " << lines.size()
        << " expectations, " << failed << " failed\n";
    return failed == 0 ? kExitOk : kExitFailure;
}

}  // namespace app
