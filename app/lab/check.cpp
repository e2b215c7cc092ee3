// app/lab/check.cpp -- `cdlab check`: runs each scene once and grades it with the checkers of
// its `expect:` section (checkers.h), which all watch that single run: frame 0 is the initial
// state, frame k is after k * steps_per_frame steps; a scene with an events track runs through
// it as `cdlab run` plays it (demo_playback.h). Rows come out in a fixed order (the order of
// makeCheckers, then file order), and scenes in command-line order whichever process graded them
// and whenever it finished, so two checks of the same scenes print the same table.
#include "check.h"

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <memory>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include "check_workers.h"
#include "checkers.h"
#include "checkers_step.h"
#include "demo/demo_playback.h"
#include "demo/demo_session.h"
#include "exit_codes.h"
#include "junit_report.h"
#include "output_files.h"
#include "render/image.h"

namespace app {

namespace fs = std::filesystem;

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The cores this process may run on (its affinity mask, as a container or taskset sets it).
int availableCores() {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0) {
        return CPU_COUNT(&set);
    }
    return std::max(1u, std::thread::hardware_concurrency());
}

// Bad flags, reported before anything runs; empty when the options are usable.
std::string badOption(const CheckOptions& options) {
    if (options.scenes.empty()) return "check: no scene given";
    if (options.frames && *options.frames < 1) return "--frames: must be >= 1";
    if (options.jobs < 0) return "--jobs: must be >= 0 (0: one per core)";
    if (options.timeout && !(*options.timeout > 0)) return "--timeout: must be > 0 seconds";
    return {};
}

// Loads every scene before any runs, printing the loader's notes and errors in command-line
// order; false when any scene is bad.
bool loadAll(const CheckOptions& options, std::vector<engine::Scene>& scenes, std::ostream& err) {
    bool bad = false;
    for (const fs::path& file : options.scenes) {
        try {
            scenes.push_back(loadCheckScene(file, options.events, options.frames));
            for (const std::string& note : scenes.back().notes) err << note << "\n";
        } catch (const engine::SceneError& e) {
            err << e.what() << "\n";
            bad = true;
        }
    }
    return !bad;
}

// What the grading had to say on stderr, in command-line order: the loader's notes (unless
// loadAll printed them already), the message of every scene that did not load, the children's
// output.
void printMessages(const std::vector<SceneReport>& reports, bool with_notes, std::ostream& err) {
    for (const SceneReport& s : reports) {
        if (with_notes) {
            for (const std::string& note : s.notes) err << note << "\n";
        }
        if (s.outcome == SceneOutcome::NotLoaded) err << s.rows.front().reason << "\n";
        err << s.log;
    }
}

void printTable(const std::vector<SceneReport>& reports, std::ostream& out) {
    std::size_t scene_w = 5, what_w = 11, rows = 0, failed = 0, not_loaded = 0;
    for (const SceneReport& s : reports) {
        scene_w = std::max(scene_w, s.label.size());
        for (const CheckRow& r : s.rows) what_w = std::max(what_w, r.expectation.size());
        not_loaded += s.outcome == SceneOutcome::NotLoaded ? 1 : 0;
    }
    auto pad = [](const std::string& s, std::size_t w) {
        return s + std::string(w > s.size() ? w - s.size() : 0, ' ');
    };
    out << pad("scene", scene_w) << "  " << pad("expectation", what_w) << "  result  reason\n";
    for (const SceneReport& s : reports) {
        for (const CheckRow& r : s.rows) {
            ++rows;
            failed += r.pass ? 0 : 1;
            out << pad(s.label, scene_w) << "  " << pad(r.expectation, what_w) << "  "
                << (r.pass ? "pass" : "FAIL    " + r.reason) << "\n";
        }
    }
    out << reports.size() << " scene" << (reports.size() == 1 ? "" : "s") << ", " << rows
        << " expectations, " << failed << " failed";
    if (not_loaded > 0) {
        out << ", " << not_loaded << " scene" << (not_loaded == 1 ? "" : "s") << " not loaded";
    }
    out << "\n";
}

// checkScene of a scene with events: the run through the track on a session of `frames` frames.
// The checkers see each step as it is taken, with the frame it leads to and the time it started
// at (recorded by step count the first time, so a re-simulated step gets the same bits), each
// frame shown and each entry applied.
std::vector<CheckRow> checkThroughEvents(const engine::Scene& scene, int frames,
                                         const fs::path& dump_dir) {
    engine::Scene run_scene = scene;
    run_scene.frames = frames;
    engine::checkEventTrack(run_scene.events, frames, scene.name);
    DemoSession session(run_scene, false);
    const engine::World& world = session.world();
    CheckRun run(run_scene, world, frames, dump_dir, &session);
    const std::vector<std::unique_ptr<Checker>> checkers = makeCheckers(run_scene, world);
    std::vector<double> time_after_step{double(world.time())};  // by step count
    for (const auto& c : checkers) c->observeStep(run, 0, std::nullopt);
    session.on_step = [&](const engine::World& w) {
        const auto k = std::size_t(w.stepCount());
        if (time_after_step.size() <= k) time_after_step.resize(k + 1);
        time_after_step[k] = double(w.time());
        for (const auto& c : checkers) c->observeStep(run, session.frame() + 1, time_after_step[k - 1]);
    };
    DemoPlaybackHooks hooks;
    hooks.frame_shown = [&] {
        run.markShown(session.frame());
        for (const auto& c : checkers) c->observeFrame(run, session.frame());
    };
    hooks.event_applied = [&](const engine::DemoEvent& e) {
        for (const auto& c : checkers) c->observeEvent(run, session.frame(), e.commands);
    };
    playDemo(session, run_scene.events, hooks);
    std::vector<CheckRow> rows;
    for (const auto& c : checkers) c->report(run, rows);
    if (rows.empty()) rows.push_back({"expect", false, "states no expectation"});
    return rows;
}

}  // namespace

std::vector<CheckRow> checkScene(const engine::Scene& scene, int frames, const fs::path& dump_dir) {
    std::vector<CheckRow> rows;
    if (!scene.expect.present) {
        rows.push_back({"expect", false, "the scene has no 'expect:' section"});
        return rows;
    }
    if (!scene.events.empty()) return checkThroughEvents(scene, frames, dump_dir);
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

SceneReport gradeScene(const engine::Scene& scene, std::size_t index, std::optional<int> frames,
                       const fs::path& dump_root) {
    SceneReport report;
    report.notes = scene.notes;
    const int run_frames = frames.value_or(scene.expect.frames.value_or(scene.frames));
    const auto start = std::chrono::steady_clock::now();
    try {
        const fs::path dir = dump_root / (std::to_string(index) + "_" + scene.name);
        if (!scene.expect.pause_dumps.empty()) {
            std::error_code ec;
            fs::create_directories(dir, ec);
            if (ec) throw render::RenderError("cannot create " + dir.string());
        }
        report.rows = checkScene(scene, run_frames, dir);
        report.outcome = SceneOutcome::Graded;
    } catch (const std::exception& e) {
        report.rows = {{"run", false, std::string("could not run: ") + e.what()}};
        report.outcome = SceneOutcome::NotRun;
    }
    report.seconds = secondsSince(start);
    return report;
}

engine::Scene loadCheckScene(const fs::path& file, const std::optional<fs::path>& events,
                             std::optional<int> frames) {
    engine::Scene scene = engine::loadScene(file);
    if (!events) return scene;
    if (frames) scene.frames = *frames;
    engine::EventTrack track = engine::loadEventTrack(*events, scene);
    scene.events = std::move(track.events);
    if (track.expect.present) {
        scene.expect = std::move(track.expect);
    } else {
        engine::requireGradableThroughEvents(scene.expect, file.string());
    }
    return scene;
}

std::string sceneLabel(const fs::path& file, const std::optional<fs::path>& events) {
    return events ? file.string() + " --events " + events->string() : file.string();
}

SceneReport gradeSceneFile(const fs::path& file, std::size_t index, std::optional<int> frames,
                           const fs::path& dump_root, const std::optional<fs::path>& events) {
    std::optional<engine::Scene> scene;
    try {
        scene = loadCheckScene(file, events, frames);
    } catch (const engine::SceneError& e) {
        SceneReport report;
        report.label = sceneLabel(file, events);
        report.outcome = SceneOutcome::NotLoaded;
        report.rows = {{"load", false, e.what()}};
        return report;
    }
    SceneReport report = gradeScene(*scene, index, frames, dump_root);
    report.label = sceneLabel(file, events);
    return report;
}

int runCheck(const CheckOptions& options, std::ostream& out, std::ostream& err) {
    if (const std::string bad = badOption(options); !bad.empty()) {
        err << bad << "\n";
        return kExitBadInput;
    }
    if (options.dry_run) {
        std::vector<engine::Scene> scenes;
        return loadAll(options, scenes, err) ? kExitOk : kExitBadInput;
    }
    const auto start = std::chrono::steady_clock::now();
    const bool keep_going = options.keep_going || options.junit.has_value();
    const int jobs = options.jobs == 0 ? availableCores() : options.jobs;
    const bool in_children = jobs > 1 || options.timeout.has_value();
    if (options.junit) {
        // A report that cannot be written is found out before the grading, not after it.
        try {
            prepareOutputDir(fs::absolute(*options.junit).parent_path());
        } catch (const render::RenderError& e) {
            err << "--junit: " << e.what() << "\n";
            return kExitFailure;
        }
    }

    // Without keep_going every scene is loaded before any runs: bad input stops the whole check.
    std::vector<engine::Scene> scenes;
    if (!keep_going) {
        if (!loadAll(options, scenes, err)) return kExitBadInput;
        if (in_children) scenes.clear();  // each child loads its own
    }

    fs::path dump_root;
    bool remove_dumps = false;
    std::error_code ec;
    if (options.out_dir) {
        dump_root = *options.out_dir;
    } else {
        dump_root = fs::temp_directory_path(ec) / ("cdlab_check_" + std::to_string(::getpid()));
        remove_dumps = true;
    }

    std::vector<SceneReport> reports;
    if (in_children) {
        WorkerPlan plan{options.worker_exe, options.scenes, options.frames, dump_root,
                        jobs,               options.timeout, options.events};
        try {
            reports = gradeInWorkers(plan);
        } catch (const render::RenderError& e) {
            err << "check: " << e.what() << "\n";
            return kExitFailure;
        }
    } else {
        for (std::size_t i = 0; i < options.scenes.size(); ++i) {
            if (keep_going) {
                reports.push_back(gradeSceneFile(options.scenes[i], i, options.frames, dump_root,
                                                 options.events));
            } else {
                reports.push_back(gradeScene(scenes[i], i, options.frames, dump_root));
                reports.back().label = sceneLabel(options.scenes[i], options.events);
            }
        }
    }
    if (remove_dumps) fs::remove_all(dump_root, ec);

    printMessages(reports, /*with_notes=*/keep_going, err);
    printTable(reports, out);
    bool failed = false, bad_input = false;
    for (const SceneReport& s : reports) {
        bad_input = bad_input || s.outcome == SceneOutcome::NotLoaded;
        for (const CheckRow& r : s.rows) failed = failed || !r.pass;
    }
    if (options.junit &&
        !writeTextReporting(*options.junit, junitXml(reports, secondsSince(start)), err)) {
        return bad_input ? kExitBadInput : kExitFailure;
    }
    return bad_input ? kExitBadInput : failed ? kExitFailure : kExitOk;
}

}  // namespace app
