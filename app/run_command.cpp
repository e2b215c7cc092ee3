// app/run_command.cpp -- the run loop: load, simulate, render, write; every failure reported.
// Outputs appear complete or not at all: PNGs and the video are written under temporary names
// and renamed, and summary.json, written last, marks a finished run.
#include "run_command.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "engine/scene.h"
#include "pause_dump.h"
#include "render/image.h"
#include "render/renderer.h"

namespace app {

namespace fs = std::filesystem;

namespace {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;

void writeTextAtomically(const fs::path& file, const std::string& text) {
    const fs::path partial = fs::path(file.string() + ".partial");
    {
        std::ofstream f(partial, std::ios::binary | std::ios::trunc);
        if (!f) throw render::RenderError("cannot write " + partial.string());
        f << text;
        f.flush();
        if (!f) throw render::RenderError("cannot write " + partial.string());
    }
    std::error_code ec;
    fs::rename(partial, file, ec);
    if (ec) throw render::RenderError("cannot rename " + partial.string() + ": " + ec.message());
}

// Creates the output directory and proves it writable before any simulation work is done.
void prepareOutputDir(const fs::path& dir) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) {
        throw render::RenderError("cannot create output directory " + dir.string() +
                                  (ec ? ": " + ec.message() : ""));
    }
    const fs::path probe = dir / ".cdlab-write-test";
    {
        std::ofstream f(probe);
        if (!f) throw render::RenderError("output directory " + dir.string() + " is not writable");
    }
    fs::remove(probe, ec);
}

class ProgressBar {
public:
    ProgressBar(bool enabled, int total) : enabled_(enabled), total_(total) {}
    void update(int done) {
        if (!enabled_) return;
        const int width = 40;
        const int filled = total_ > 0 ? done * width / total_ : width;
        std::fprintf(stderr, "\r[%.*s%*s] %d/%d frames", filled,
                     "########################################", width - filled, "", done,
                     total_);
        std::fflush(stderr);
    }
    ~ProgressBar() {
        if (enabled_) std::fputc('\n', stderr);
    }

private:
    bool enabled_;
    int total_;
};

std::string frameName(int frame) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", frame);
    return name;
}

}  // namespace

int runScene(const RunOptions& options, std::ostream& out, std::ostream& err) {
    // 1. Everything that can be wrong with the input is found before any output is written.
    engine::Scene scene;
    try {
        scene = engine::loadScene(options.scene);
    } catch (const engine::SceneError& e) {
        err << e.what() << "\n";
        return kExitBadInput;
    }
    if (options.frames) {
        if (*options.frames < 1) {
            err << "--frames: must be >= 1\n";
            return kExitBadInput;
        }
        scene.frames = *options.frames;
    }
    if (options.broad_phase) {
        if (collision::findBroadPhase(*options.broad_phase) == nullptr) {
            err << "--broadphase: unknown broad phase '" << *options.broad_phase
                << "' (expected one of: " << collision::broadPhaseNames() << ")\n";
            return kExitBadInput;
        }
        scene.world.broad_phase = *options.broad_phase;
    }
    const std::set<int> pauses(options.pause_at.begin(), options.pause_at.end());
    for (int f : pauses) {
        if (f < 0 || f >= scene.frames) {
            err << "--pause-at " << f << ": frame out of range (the run has frames 0.."
                << scene.frames - 1 << ")\n";
            return kExitBadInput;
        }
    }
    const fs::path out_dir = options.out_dir.empty() ? fs::path("out") / scene.name
                                                     : options.out_dir;
    const bool want_video = !options.no_video;
    const fs::path video_path =
        options.video ? *options.video : out_dir / (scene.name + ".mp4");
    if (want_video && !render::ffmpegAvailable()) {
        err << "ffmpeg not found on PATH: install it (apt-get install ffmpeg) or pass --no-video\n";
        return kExitFailure;
    }

    try {
        prepareOutputDir(out_dir);
        if (want_video && video_path.has_parent_path()) prepareOutputDir(video_path.parent_path());
        std::error_code ec;
        fs::remove(out_dir / "summary.json", ec);

        engine::World world = engine::makeWorld(scene);
        render::Renderer renderer(scene.output.width, scene.output.height);
        std::unique_ptr<render::VideoWriter> video;
        if (want_video) {
            video = std::make_unique<render::VideoWriter>(video_path, scene.output.width,
                                                          scene.output.height, scene.output.fps);
        }
        render::FrameOptions frame_options;
        frame_options.draw = scene.draw;
        render::FrameOptions pause_options = frame_options;
        pause_options.draw.sphere = pause_options.draw.aabb = pause_options.draw.obb = true;

        ProgressBar progress(options.progress && ::isatty(STDERR_FILENO), scene.frames);
        std::int64_t flagged_total = 0;
        std::int64_t colliding_total = 0;
        double step_seconds = 0;
        for (int frame = 0; frame < scene.frames; ++frame) {
            if (frame > 0) {
                for (int s = 0; s < scene.steps_per_frame; ++s) {
                    world.step();
                    step_seconds += world.lastStats().total_s;
                }
            }
            flagged_total += static_cast<std::int64_t>(world.flaggedPairs().size());
            colliding_total += static_cast<std::int64_t>(world.collidingPairs().size());
            frame_options.hud_text =
                scene.draw.hud ? render::hudLine(world, frame, options.hud_timing) : "";
            if (!options.no_frames || video) {
                const render::Image image = renderer.render(world, scene.camera, frame_options);
                if (!options.no_frames) render::writePng(out_dir / frameName(frame), image);
                if (video) video->addFrame(image);
            }
            if (pauses.count(frame)) {
                pause_options.hud_text = "PAUSED  " + render::hudLine(world, frame, false);
                const std::string stem = "pause_" + std::to_string(frame);
                render::writePng(out_dir / (stem + ".png"),
                                 renderer.render(world, scene.camera, pause_options));
                writeTextAtomically(out_dir / (stem + ".json"), pauseDumpJson(world, frame));
            }
            progress.update(frame + 1);
        }
        if (video) video->finish();

        nlohmann::ordered_json summary;
        summary["scene"] = options.scene.string();
        summary["broadphase"] = scene.world.broad_phase;
        summary["frames"] = scene.frames;
        summary["steps"] = world.stepCount();
        summary["time"] = world.time();
        summary["bodies"] = world.bodies().size();
        summary["state_hash"] = world.stateHash();
        summary["flagged_pair_frames"] = flagged_total;
        summary["colliding_pair_frames"] = colliding_total;
        summary["mean_step_ms"] =
            world.stepCount() > 0 ? 1e3 * step_seconds / double(world.stepCount()) : 0.0;
        summary["video"] = want_video ? video_path.string() : "";
        writeTextAtomically(out_dir / "summary.json", summary.dump(1) + "\n");

        out << "wrote " << (options.no_frames ? 0 : scene.frames) << " frames to "
            << out_dir.string();
        if (want_video) out << " and " << video_path.string();
        out << " (" << world.bodies().size() << " bodies, " << world.stepCount() << " steps, "
            << scene.world.broad_phase << ")\n";
    } catch (const render::RenderError& e) {
        err << "error: " << e.what() << "\n";
        return kExitFailure;
    } catch (const std::exception& e) {
        err << "error: " << e.what() << "\n";
        return kExitFailure;
    }
    return kExitOk;
}

}  // namespace app
