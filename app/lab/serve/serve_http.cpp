// app/lab/serve/serve_http.cpp -- see serve_http.h: the flags checked, the session started, the
// page made, and the HTTP server (http_server.h) run until a signal. Its requests touch the
// session only through LiveSession's thread-safe calls, so a slow or vanished client never
// holds the simulation.
#include "serve/serve_http.h"

#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "collision/broadphase/broad_phase.h"
#include "engine/demo_commands.h"
#include "engine/recording.h"
#include "engine/scene.h"
#include "replay/run_recorder.h"
#include "exit_codes.h"
#include "html_page.h"
#include "output_files.h"
#include "page_assets.h"
#include "serve/http_server.h"
#include "serve/live_session.h"

namespace app {

namespace {

// `replay`: the recording shown, or "" for a live simulation.
std::string servePage(const engine::Scene& scene, const std::string& scene_name,
                      const std::string& replay) {
    nlohmann::ordered_json data;
    data["scene"] = scene_name;
    data["replay"] = replay.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(replay);
    data["width"] = scene.output.width;
    data["height"] = scene.output.height;
    data["fps"] = scene.output.fps;
    nlohmann::ordered_json layers = nlohmann::ordered_json::array();
    for (int i = 0; i <= int(engine::DemoLayer::Hud); ++i) {
        layers.push_back(std::string(engine::demoLayerName(engine::DemoLayer(i))));
    }
    data["layers"] = std::move(layers);
    nlohmann::ordered_json phases = nlohmann::ordered_json::array();
    for (const collision::BroadPhaseEntry& e : collision::broadPhaseRegistry()) {
        phases.push_back(e.name);
    }
    data["broadphases"] = std::move(phases);
    std::string page = html::pageStart("cdlab serve: " + scene_name);
    page += "<header><h1>cdlab serve: " + html::escape(scene_name) +
            "</h1><p class=\"note\">" +
            (replay.empty() ? std::string("A live session")
                            : "A replay of the recording " + html::escape(replay) +
                                  ", shown without simulating") +
            ": every picture is drawn by the off-screen renderer; the commands below are the "
            "ones a scene's events track and POST /api/command take.</p></header>\n";
    page += "<main id=\"live\"></main>\n";
    page += html::jsonScript("serve-data", data.dump());
    page += html::pageEnd(servePageJs());
    return page;
}

// SIGINT and SIGTERM, blocked in every thread and awaited by one, which stops the server.
class StopSignals {
public:
    StopSignals() {
        sigemptyset(&set_);
        sigaddset(&set_, SIGINT);
        sigaddset(&set_, SIGTERM);
        pthread_sigmask(SIG_BLOCK, &set_, &saved_);
    }
    ~StopSignals() {
        if (waiter_.joinable()) {
            // Wakes the waiter if no signal came, without stopping what is gone by now.
            closing_ = true;
            if (!signalled_) pthread_kill(waiter_.native_handle(), SIGTERM);
            waiter_.join();
        }
        pthread_sigmask(SIG_SETMASK, &saved_, nullptr);
    }
    StopSignals(const StopSignals&) = delete;
    StopSignals& operator=(const StopSignals&) = delete;

    void onSignal(std::function<void(int)> stop) {
        waiter_ = std::thread([this, stop = std::move(stop)] {
            int sig = 0;
            if (sigwait(&set_, &sig) == 0) {
                signalled_ = true;
                if (!closing_) stop(sig);
            }
        });
    }

private:
    sigset_t set_{};
    sigset_t saved_{};
    std::thread waiter_;
    std::atomic<bool> signalled_{false};
    std::atomic<bool> closing_{false};
};

bool isLoopback(const std::string& host) {
    return host == "127.0.0.1" || host == "localhost" || host == "::1";
}

}  // namespace

int serveScene(const ServeOptions& options, std::ostream& out, std::ostream& err) {
    engine::Scene scene;
    std::optional<engine::Recording> recording;
    std::filesystem::path scene_file = options.scene;
    try {
        if (options.replay) {
            if (options.broad_phase || !options.overrides.empty()) {
                err << "--replay: --broadphase and --set do not apply: the recording holds its "
                       "run's broad phase and scene values\n";
                return kExitBadInput;
            }
            if (std::error_code ec; !std::filesystem::exists(*options.replay, ec)) {
                err << "--replay " << options.replay->string() << ": no such file or folder\n";
                return kExitBadInput;
            }
            recording = engine::Recording::open(*options.replay);
            const std::optional<std::filesystem::path> moved =
                options.scene.empty() ? std::nullopt : std::optional(options.scene);
            scene = loadRecordedScene(*recording, moved);
            scene_file = moved.value_or(recording->header().scene);
        } else {
            scene = engine::loadScene(options.scene, options.overrides);
        }
    } catch (const engine::SceneError& e) {
        err << e.what() << "\n";
        return kExitBadInput;
    } catch (const engine::RecordingError& e) {
        err << e.what() << "\n";
        return kExitBadInput;
    }
    for (const std::string& note : scene.notes) err << note << "\n";
    if (options.broad_phase) {
        if (collision::findBroadPhase(*options.broad_phase) == nullptr) {
            err << "--broadphase: unknown broad phase '" << *options.broad_phase
                << "' (expected one of: " << collision::broadPhaseNames() << ")\n";
            return kExitBadInput;
        }
        scene.world.broad_phase = *options.broad_phase;
    }
    if (options.port < 0 || options.port > 65535) {
        err << "--port " << options.port << ": expected 0..65535 (0: any free port)\n";
        return kExitBadInput;
    }
    if (options.host.empty()) {
        err << "--host: must not be empty\n";
        return kExitBadInput;
    }
    if (options.dry_run) return kExitOk;

    const std::string scene_name = scene_file.stem().string();
    const std::filesystem::path out_dir =
        options.out_dir.empty() ? std::filesystem::path("out") / scene_name : options.out_dir;
    LiveOptions live;
    live.structure = options.draw_structure;
    live.paused = options.paused;
    live.dump_dir = out_dir;
    live.log_file = options.session_log.value_or(out_dir / "session.yaml");
    live.replay = recording ? &*recording : nullptr;
    std::string replay = "cdlab run " + scene_file.string() + " --events " +
                         live.log_file->string() + " --no-hud-timing";
    if (recording) {
        replay += " --broadphase " + recording->header().broad_phase + " --frames " +
                  std::to_string(recording->frames());
    }
    if (options.broad_phase) replay += " --broadphase " + *options.broad_phase;
    for (const engine::SceneOverride& o :
         recording ? recording->header().overrides : options.overrides) {
        replay += " --set '" + o.key + "=" + o.value + "'";
    }
    if (options.draw_structure) replay += " --draw-structure";
    live.log_comment = {"A cdlab serve session of " +
                            (recording ? "the recording " + recording->file().string()
                                       : scene_file.string()) +
                            ". Replay it with:",
                        "  " + replay};

    std::unique_ptr<LiveSession> session;
    StopSignals signals;  // before any thread starts, so every thread inherits the mask
    try {
        prepareOutputDir(out_dir);
        if (live.log_file->has_parent_path()) prepareOutputDir(live.log_file->parent_path());
        session = std::make_unique<LiveSession>(scene, live);
    } catch (const std::exception& e) {
        err << "cdlab serve: " << e.what() << "\n";
        return kExitFailure;
    }

    HttpServer server(*session, servePage(scene, scene_name,
                                          recording ? recording->file().filename().string() : ""));
    const int port = server.listen(options.host, options.port);
    if (port <= 0) {
        err << "cdlab serve: cannot listen on " << options.host << ":" << options.port
            << " (in use, or not an address of this machine)\n";
        return kExitFailure;
    }
    if (!isLoopback(options.host)) {
        err << "cdlab serve: WARNING: listening on " << options.host
            << ", not only this machine: anyone who reaches it can drive the session and see "
               "its frames\n";
    }
    signals.onSignal([&](int) { server.stop(); });
    const std::string shown_host =
        options.host.find(':') != std::string::npos ? "[" + options.host + "]" : options.host;
    out << "cdlab serve: http://" << shown_host << ":" << port << "/ (Ctrl-C stops; session log "
        << live.log_file->string() << ")" << std::endl;
    server.run();
    session->stop();
    const std::string failure = session->failure();
    if (!failure.empty()) {
        err << "cdlab serve: the session stopped: " << failure << "\n";
        return kExitFailure;
    }
    out << "cdlab serve: stopped; session log " << live.log_file->string() << "\n" << "replay: "
        << replay << "\n";
    return kExitOk;
}

}  // namespace app
