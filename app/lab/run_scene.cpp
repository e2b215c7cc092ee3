// app/lab/run_scene.cpp -- the run loop: load, simulate, render, write; every failure reported.
// Outputs appear complete or not at all: PNGs and the video are written under temporary names
// and renamed, and summary.json, written last, marks a finished run.
#include "run_scene.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <new>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <stdexcept>
#include <span>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "broadphase_check.h"
#include "collision/broadphase/broad_phase.h"
#include "demo/demo_playback.h"
#include "demo/demo_session.h"
#include "engine/scene.h"
#include "engine/volume_overlaps.h"
#include "exit_codes.h"
#include "html_page.h"
#include "output_files.h"
#include "pause_dump.h"
#include "replay/run_recorder.h"
#include "render/frame_writer.h"
#include "render/image.h"
#include "render/output_file.h"
#include "render/renderer.h"
#include "run_html.h"
#include "run_rows.h"

namespace app {

namespace fs = std::filesystem;

namespace {

class ProgressBar {
public:
    ProgressBar(bool enabled, int total) : enabled_(enabled), total_(total) {}
    void update(int done) {
        if (!enabled_) return;
        const int width = 40;
        const int filled = total_ > 0 ? done * width / total_ : width;
        std::fprintf(stderr, "\r[%.*s%*s] %d/%d frames", filled,
                     "########################################", width - filled, "", done, total_);
        std::fflush(stderr);
    }
    ~ProgressBar() {
        if (enabled_) std::fputc('\n', stderr);
    }

private:
    bool enabled_;
    int total_;
};

double wallSeconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

// The main thread's share of the run, for --timing.
struct StageTimes {
    double sim_s = 0;       ///< world steps
    double render_s = 0;    ///< GL drawing until the frame is finished
    double readback_s = 0;  ///< supersampled buffer -> RGB image with overlays
    double wait_s = 0;      ///< blocked on the frame writer's full queues

    void add(const render::FrameStats& f) {
        render_s += f.draw_s;
        readback_s += f.readback_s;
    }
};

// Frames wait in each of the writer's queues at most this many at a time (each a full RGB frame,
// 2.8 MB at 1280x720): enough to absorb an encoder hiccup, bounded whatever the frame count.
constexpr int kQueueFrames = 4;

// PNG workers: all cores but the one that simulates and renders, at least one and at most four
// (a 1280x720 PNG takes about 7 ms, so four keep up with any renderer here); the encoder process
// runs its own threads beside them.
int pngThreads() {
    const int cores = int(std::thread::hardware_concurrency());
    return std::clamp(cores - 1, 1, 4);
}

std::string timingLine(int frames, double wall_s, const StageTimes& st,
                       const render::FrameWriterTimes& wt) {
    const double per = frames > 0 ? 1e3 / frames : 0;
    char line[512];
    std::snprintf(line, sizeof line,
                  "timing: %d frames in %.2f s wall (%.1f fps); ms per frame: sim %.2f, render "
                  "%.2f, readback %.2f, waiting for writers %.2f (main thread); png %.2f "
                  "(cpu, %lld files), video feed %.2f, encoder %.2f (cpu, %lld frames)\n",
                  frames, wall_s, wall_s > 0 ? frames / wall_s : 0.0, st.sim_s * per,
                  st.render_s * per, st.readback_s * per, st.wait_s * per, wt.png_cpu_s * per,
                  wt.png_files, wt.video_feed_s * per, wt.encoder_cpu_s * per, wt.video_frames);
    return line;
}

// --check-broadphase found a step whose pairs differ from the reference: what() is the report.
struct BroadPhaseMismatch : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A step failed (engine::SimulationError): what() is "frame F: what went wrong".
struct StepFailure : std::runtime_error {
    using std::runtime_error::runtime_error;
};

std::string frameName(int frame) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", frame);
    return name;
}

}  // namespace

namespace {

// The scene with the command line's overrides applied, and the pause frames; an error message
// and kExitBadInput when anything is wrong with the input (before any output is written).
int loadRunScene(const RunOptions& options, std::ostream& err, engine::Scene& scene,
                 std::set<int>& pauses, std::vector<engine::DemoEvent>& events) {
    try {
        scene = engine::loadScene(options.scene, options.overrides);
    } catch (const engine::SceneError& e) {
        err << e.what() << "\n";
        return kExitBadInput;
    }
    for (const std::string& note : scene.notes) err << note << "\n";
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
    if (options.pair_order) {
        const std::optional<collision::PairOrder> order =
            collision::findPairOrder(*options.pair_order);
        if (!order) {
            err << "--pair-order: unknown pair order '" << *options.pair_order
                << "' (expected one of: " << collision::pairOrderNames() << ")\n";
            return kExitBadInput;
        }
        scene.world.pair_order = *order;
    }
    if (!std::isfinite(options.pause_hold_s) || options.pause_hold_s < 0 ||
        options.pause_hold_s > kMaxPauseHoldSeconds) {
        err << "--pause-hold " << options.pause_hold_s << ": must be a number of seconds from 0 "
            << "(no hold) to " << kMaxPauseHoldSeconds << "\n";
        return kExitBadInput;
    }
    // The track: the scene's own, or --events FILE's instead; checked against the frame count
    // the run has (--frames may have changed it).
    try {
        if (options.events) {
            if (!scene.events.empty()) {
                err << "note: --events " << options.events->string()
                    << " replaces the scene's own events: track\n";
            }
            events = engine::loadEvents(*options.events, scene);
        } else {
            events = scene.events;
            engine::checkEventTrack(events, scene.frames, options.scene.string());
        }
    } catch (const engine::SceneError& e) {
        err << e.what() << "\n";
        return kExitBadInput;
    }
    if (options.record) {
        if (const std::string why = recordRefusal(scene, events); !why.empty()) {
            err << "--record " << options.record->string() << ": " << why << "\n";
            return kExitBadInput;
        }
    }
    pauses = std::set<int>(options.pause_at.begin(), options.pause_at.end());
    for (int f : pauses) {
        if (f < 0 || f >= scene.frames) {
            err << "--pause-at " << f << ": frame out of range (the run has frames 0.."
                << scene.frames - 1 << ")\n";
            return kExitBadInput;
        }
    }
    return kExitOk;
}

// Every output folder made and every output path proven writable (and not a device, FIFO, link
// or directory) before the first step, not after the whole simulation; an earlier run's outputs
// in `out_dir` cleared, and the folder held for this run (OutputLock) until the returned lock
// goes. Throws render::RenderError.
OutputLock prepareOutputs(const RunOptions& options, const fs::path& out_dir, bool want_video,
                          const fs::path& video_path) {
    prepareOutputDir(out_dir);
    OutputLock lock(out_dir);
    if (want_video && video_path.has_parent_path()) prepareOutputDir(video_path.parent_path());
    if (options.stats_csv && options.stats_csv->has_parent_path()) {
        prepareOutputDir(options.stats_csv->parent_path());
    }
    for (const auto& file : {options.trace, options.record}) {
        if (file && file->has_parent_path()) prepareOutputDir(file->parent_path());
        if (file) render::checkOutputWritable(*file);
    }
    if (options.stats_csv) render::checkOutputWritable(*options.stats_csv);
    if (want_video) render::checkOutputWritable(video_path);
    clearPreviousRun(out_dir);
    return lock;
}

// What summary.json records of a run that completed.
struct RunTotals {
    std::int64_t flagged = 0;    ///< flagged pairs summed over frames
    std::int64_t colliding = 0;  ///< colliding pairs summed over frames
    std::int64_t self_pairs = 0;  ///< self-intersecting triangle pairs summed over frames
    double step_seconds = 0;
};

std::string summaryJson(const RunOptions& options, const engine::Scene& scene,
                        const engine::World& world, const RunTotals& totals, bool want_video,
                        const fs::path& video_path, std::size_t events) {
    nlohmann::ordered_json summary;
    summary["scene"] = options.scene.string();
    summary["broadphase"] = scene.world.broad_phase;
    summary["pair_order"] = std::string(collision::pairOrderName(scene.world.pair_order));
    summary["frames"] = scene.frames;
    summary["steps"] = world.stepCount();
    summary["time"] = world.time();
    summary["bodies"] = world.bodies().size();
    summary["state_hash"] = world.stateHash();
    summary["flagged_pair_frames"] = totals.flagged;
    summary["colliding_pair_frames"] = totals.colliding;
    summary["self_pair_frames"] = totals.self_pairs;
    summary["mean_step_ms"] =
        world.stepCount() > 0 ? 1e3 * totals.step_seconds / double(world.stepCount()) : 0.0;
    summary["video"] = want_video ? video_path.string() : "";
    summary["checked_broadphase"] = options.check_broad_phase;
    if (events > 0) {
        summary["events"] = events;
        summary["final_broadphase"] = std::string(world.broadPhase().name());
    }
    return summary.dump(1) + "\n";
}

// What index.html says of the run before its frames: the scene and the picture format.
RunPage runPage(const RunOptions& options, const engine::Scene& scene, const engine::World& world,
                long hold_frames) {
    RunPage page;
    page.scene = options.scene.string();
    page.scene_name = scene.name;
    page.broad_phase = scene.world.broad_phase;
    page.bodies = world.bodies().size();
    page.width = scene.output.width;
    page.height = scene.output.height;
    page.fps = scene.output.fps;
    page.hold_frames = hold_frames;
    page.frames_written = !options.no_frames;
    return page;
}

// Writes out_dir/index.html once the video is complete: the video referred to relative to the
// page, or the reason there is none.
void writeRunPage(RunPage page, const fs::path& out_dir, bool want_video,
                  const fs::path& video_path) {
    std::error_code ec;
    if (!want_video) {
        page.no_video_reason = "the run was made with --no-video";
    } else if (!fs::is_regular_file(video_path, ec)) {
        page.no_video_reason = video_path.string() + " was not found when this page was written";
    } else {
        const fs::path dir = fs::absolute(out_dir, ec);
        fs::path relative = fs::absolute(video_path, ec).lexically_relative(dir);
        if (relative.empty()) relative = fs::absolute(video_path, ec);
        page.video = html::urlPath(relative.generic_string());
    }
    writeTextAtomically(out_dir / "index.html", runPageHtml(page));
}

}  // namespace

int runScene(const RunOptions& options, std::ostream& out, std::ostream& err) {
    // 1. Everything that can be wrong with the input is found before any output is written.
    engine::Scene scene;
    std::set<int> pauses;
    std::vector<engine::DemoEvent> events;
    if (const int code = loadRunScene(options, err, scene, pauses, events); code != kExitOk) {
        return code;
    }
    const fs::path out_dir =
        options.out_dir.empty() ? fs::path("out") / scene.name : options.out_dir;
    const bool want_video = !options.no_video;
    const fs::path video_path = options.video ? *options.video : out_dir / (scene.name + ".mp4");
    if (want_video && !render::isSupportedVideoFile(video_path)) {
        err << video_path.string() << ": unsupported video container '"
            << video_path.extension().string()
            << "' (supported: " << render::supportedVideoExtensions() << ")\n";
        return kExitBadInput;
    }
    if (options.dry_run) return kExitOk;
    if (want_video && !render::ffmpegAvailable()) {
        err << "ffmpeg not found on PATH: install it (apt-get install ffmpeg) or pass --no-video\n";
        return kExitFailure;
    }

    std::optional<RunRecorder> recorder;
    // A run that stops early still ends its recording, saying why, so frames up to there can be
    // viewed.
    auto endRecording = [&](const std::string& why) {
        try {
            if (recorder) recorder->finish(why);
        } catch (const engine::RecordingError& e) {
            err << "error: " << e.what() << "\n";
        }
    };
    try {
        const OutputLock out_lock = prepareOutputs(options, out_dir, want_video, video_path);
        DemoSession session(scene, options.draw_structure);
        const engine::World& world = session.world();
        if (options.record) {
            recorder.emplace(*options.record,
                             recordingHeader(options.scene, options.overrides, scene), world);
        }
        render::Renderer renderer(scene.output.width, scene.output.height);
        std::unique_ptr<render::VideoWriter> video;
        if (want_video) {
            video = std::make_unique<render::VideoWriter>(video_path, scene.output.width,
                                                          scene.output.height, scene.output.fps);
        }
        render::FrameWriter writer(std::move(video), pngThreads(), kQueueFrames);
        StageTimes stage;
        const double run_start = wallSeconds();
        // Each pause picture is held this many video frames after its frame.
        const long hold_frames = std::lround(options.pause_hold_s * scene.output.fps);

        std::unique_ptr<BroadPhaseChecker> checker;
        if (options.check_broad_phase) {
            checker = std::make_unique<BroadPhaseChecker>(scene.world.broad_phase);
        }
        std::string stats_text;
        if (options.stats_csv) stats_text = kStatsHeader;
        std::string trace_text;
        ProgressBar progress(options.progress && ::isatty(STDERR_FILENO), scene.frames);
        RunTotals totals;
        RunPage page = runPage(options, scene, world, hold_frames);
        FrameStats frame_stats;  // the steps since the last frame shown
        frame_stats.add(world.lastStats());
        if (checker) {
            if (const std::string report = checker->check(world); !report.empty()) {
                err << "check-broadphase: MISMATCH at frame 0, step 0, t=" << world.time()
                    << " s\n"
                    << report;
                return kExitCheckFailed;
            }
        }
        session.on_step = [&](const engine::World& w) {
            if (recorder) recorder->observe(w);
            frame_stats.add(w.lastStats());
            totals.step_seconds += w.lastStats().total_s;
            stage.sim_s += w.lastStats().total_s;
            if (!checker) return;
            const double check_start = wallSeconds();
            const std::string report = checker->check(w);
            stage.sim_s += wallSeconds() - check_start;
            if (report.empty()) return;
            std::ostringstream what;
            what << "check-broadphase: MISMATCH at frame " << session.frame() + 1 << ", step "
                 << w.stepCount() << ", t=" << w.time() << " s\n"
                 << report;
            throw BroadPhaseMismatch(what.str());
        };
        auto hudText = [&](bool paused) { return session.hudText(paused, options.hud_timing); };
        std::set<int> frames_written;
        int newest_frame = -1;   // the furthest frame reached so far
        double video_credit = 0;  // video frames owed at the current speed
        // A frame's PNG waits until the run leaves the frame: the picture after the events at
        // that frame, which is the one a live session last showed of it.
        struct PendingPng {
            std::shared_ptr<const render::Image> image;
            int frame = 0;
        };
        std::optional<PendingPng> pending_png;
        auto flushPng = [&]() {
            if (!pending_png) return;
            writer.submit(std::move(pending_png->image), out_dir / frameName(pending_png->frame),
                          0);
            pending_png.reset();
        };
        // The current frame as the run shows it: its rows, its PNG, its video frames, and the
        // pause picture when --pause-at asks for it.
        auto showFrame = [&]() {
            const int frame = session.frame();
            if (options.stats_csv) stats_text += statsRow(frame, world, frame_stats);
            if (options.trace) trace_text += traceLine(frame, world);
            if (options.html && frame > newest_frame) {
                page.frames.push_back(pageFrame(frame, world, frame_stats));
            }
            newest_frame = std::max(newest_frame, frame);
            frame_stats = FrameStats{};
            totals.flagged += static_cast<std::int64_t>(world.flaggedPairs().size());
            totals.colliding += static_cast<std::int64_t>(world.collidingPairs().size());
            totals.self_pairs += selfPairCount(world);
            video_credit += 1.0 / session.view().speed;
            const long copies = std::lround(std::floor(video_credit + 1e-9));
            video_credit -= double(copies);
            const bool png = !options.no_frames;
            if (png || (want_video && copies > 0)) {
                render::FrameOptions frame_options = session.frameOptions();
                frame_options.hud_text = hudText(!session.playing());
                std::shared_ptr<render::Image> image = writer.blankFrame();
                renderer.render(world, session.camera(), frame_options, *image);
                stage.add(renderer.lastFrameStats());
                const double wait_start = wallSeconds();
                flushPng();
                if (want_video && copies > 0) writer.submit(image, fs::path(), copies);
                stage.wait_s += wallSeconds() - wait_start;
                if (png) {
                    pending_png = PendingPng{std::move(image), frame};
                    frames_written.insert(frame);
                }
            }
            if (pauses.count(frame)) {
                // The volumes chosen, or every proxy volume, each coloured by its own test.
                render::FrameOptions pause_options = session.frameOptions();
                pause_options.draw =
                    pauseDrawSettings(pause_options.draw, session.view().volumes_chosen);
                pause_options.hud_text = "PAUSED  " + render::hudLine(world, frame, false);
                const std::string stem = "pause_" + std::to_string(frame);
                auto pause_image = std::make_shared<const render::Image>(
                    renderer.render(world, session.camera(), pause_options));
                writer.submit(std::move(pause_image), out_dir / (stem + ".png"), hold_frames);
                std::string dump = pauseDumpJson(world, frame, pause_options.draw);
                writeTextAtomically(out_dir / (stem + ".json"), dump);
                if (options.html) {
                    page.pauses.push_back({frame, std::move(dump), bodyRects(world, session.camera(), scene.output.width, scene.output.height)});
                }
            }
            progress.update(frame + 1);
        };
        // An event's dump: the current view, paused, as pause_F.png and pause_F.json.
        auto dumpFrame = [&]() {
            const int frame = session.frame();
            render::FrameOptions dump_options = session.frameOptions();
            dump_options.hud_text = hudText(true);
            const std::string stem = "pause_" + std::to_string(frame);
            render::writePng(out_dir / (stem + ".png"),
                             renderer.render(world, session.camera(), dump_options));
            std::string dump = pauseDumpJson(world, frame, dump_options.draw);
            writeTextAtomically(out_dir / (stem + ".json"), dump);
            if (options.html) page.pauses.push_back({frame, std::move(dump), bodyRects(world, session.camera(), scene.output.width, scene.output.height)});
        };
        // An event's wait: the current picture held in the video.
        auto holdFrame = [&](double seconds) {
            const long copies = std::lround(seconds * scene.output.fps);
            if (!want_video || copies == 0) return;
            render::FrameOptions hold_options = session.frameOptions();
            hold_options.hud_text = hudText(!session.playing());
            auto image = std::make_shared<const render::Image>(
                renderer.render(world, session.camera(), hold_options));
            writer.submit(std::move(image), fs::path(), copies);
        };

        // The track as playDemo plays it (a run without one just plays): the frames it shows,
        // each entry's picture, dump and wait.
        DemoPlaybackHooks hooks;
        hooks.frame_shown = showFrame;
        hooks.event_applied = [&](const engine::DemoEvent& e) {
            // An entry that stayed on its frame changed its picture (a view, a pause): the
            // frame's PNG is the picture after it, as a live session shows it. (One that steps
            // or seeks showed its frames, the last with its view.)
            if (!e.commands.step && !e.commands.seek && pending_png &&
                pending_png->frame == session.frame()) {
                render::FrameOptions frame_options = session.frameOptions();
                frame_options.hud_text = hudText(!session.playing());
                pending_png->image = std::make_shared<const render::Image>(
                    renderer.render(world, session.camera(), frame_options));
            }
            if (e.commands.dump) dumpFrame();
            if (e.commands.wait_s > 0) holdFrame(double(e.commands.wait_s));
        };
        try {
            playDemo(session, events, hooks);
        } catch (const engine::SimulationError& e) {
            throw StepFailure("frame " + std::to_string(session.frame() + 1) + ": " + e.what());
        }
        flushPng();
        writer.finish();
        if (recorder) recorder->finish();
        if (options.timing) {
            out << timingLine(scene.frames, wallSeconds() - run_start, stage, writer.times());
        }
        if (options.stats_csv) writeTextAtomically(*options.stats_csv, stats_text);
        if (options.trace) writeTextAtomically(*options.trace, trace_text);
        if (options.html) writeRunPage(std::move(page), out_dir, want_video, video_path);

        writeTextAtomically(out_dir / "summary.json",
                            summaryJson(options, scene, world, totals, want_video, video_path,
                                        events.size()));

        out << "wrote " << frames_written.size() << " frames to " << out_dir.string();
        if (want_video) out << " and " << video_path.string();
        if (options.html) out << ", the page " << (out_dir / "index.html").string();
        out << " (" << world.bodies().size() << " bodies, " << world.stepCount() << " steps, "
            << scene.world.broad_phase
            << (scene.world.pair_order == collision::PairOrder::Found ? ", pairs in found order"
                                                                      : "")
            << (options.check_broad_phase ? ", every step checked" : "");
        if (!events.empty()) {
            out << ", " << events.size() << " events";
            if (world.broadPhase().name() != scene.world.broad_phase) {
                out << ", ending on " << world.broadPhase().name();
            }
        }
        out << ")\n";
        if (recorder) out << recorder->summary() << "\n";
        if (!session.playing() && session.frame() < session.lastFrame()) {
            out << "note: the events track ended paused at frame " << session.frame()
                << ": the run stops there\n";
        }
        const double scale = double(engine::videoTimeScale(scene));
        if (want_video && std::abs(scale - 1.0) > 1e-9) {
            // A scene may ask for slow motion; say so, so that nobody reads it as real time.
            out << "note: one second of video shows " << scale
                << " s of simulated time (time_step x steps_per_frame x fps)\n";
        }
    } catch (const BroadPhaseMismatch& e) {
        endRecording("stopped: the broad phase differed from its reference");
        err << e.what();
        return kExitCheckFailed;
    } catch (const StepFailure& e) {
        // No summary.json: the run is incomplete, and says so.
        endRecording(std::string("stopped: ") + e.what());
        err << "error: " << options.scene.string() << ": " << e.what() << "\n";
        return kExitFailure;
    } catch (const render::RenderError& e) {
        endRecording(std::string("stopped: ") + e.what());
        err << "error: " << e.what() << "\n";
        return kExitFailure;
    } catch (const std::bad_alloc&) {
        endRecording("stopped: out of memory");
        err << "error: out of memory: this scene needs more memory than the machine can allocate "
               "(fewer bodies, fewer volumes drawn, or --no-frames --no-video)\n";
        return kExitFailure;
    } catch (const std::exception& e) {
        endRecording(std::string("stopped: ") + e.what());
        err << "error: " << e.what() << "\n";
        return kExitFailure;
    }
    return kExitOk;
}

}  // namespace app
