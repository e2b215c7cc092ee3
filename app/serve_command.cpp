// app/serve_command.cpp -- `cdlab serve`: the flags of a live session (lab/serve/serve_http.h).
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "command.h"
#include "exit_codes.h"
#include "serve/serve_http.h"

namespace app {

Command addServeCommand(CLI::App& cli) {
    struct Flags {
        ServeOptions serve;
        std::string out_dir;
        std::string session;
        std::string broad_phase;
        std::vector<std::string> set;
        std::string replay;
    };
    auto f = std::make_shared<Flags>();
    CLI::App* cmd = cli.add_subcommand(
        "serve", "run a scene live behind a local web page and HTTP API: play, pause, step, "
                 "seek, show/hide layers, switch the broad phase, select, move the camera, dump");
    cmd->add_option("scene", f->serve.scene,
                    "scene file (YAML); with --replay, the recording's scene if it has moved");
    cmd->add_option("--replay", f->replay,
                    "show the frames of a recording (run --record FILE) without simulating: "
                    "scrub, step back and forth, change layers and camera, dump any frame")
        ->type_name("FILE");
    cmd->add_option("--host", f->serve.host,
                    "address to listen on (default 127.0.0.1, this machine only; any other is "
                    "said loudly: whoever reaches it can drive the session)");
    cmd->add_option("--port", f->serve.port, "port (default 8080; 0: any free port, printed)");
    cmd->add_option("--out", f->out_dir,
                    "folder for dump: true (pause_F.png/.json) and the session log (default "
                    "out/<scene name>)");
    cmd->add_option("--session", f->session,
                    "FILE: the session log, an events track kept current on disk (default "
                    "<out>/session.yaml); `cdlab run SCENE --events FILE --no-hud-timing` "
                    "replays it frame for frame");
    cmd->add_flag("--paused", f->serve.paused, "start paused at frame 0");
    cmd->add_flag("--draw-structure", f->serve.draw_structure,
                  "draw the broad phase's own structure (as run --draw-structure)");
    cmd->add_option("--broadphase", f->broad_phase,
                    "broad phase (overrides the scene): " + collision::broadPhaseNames());
    cmd->add_option("--set", f->set,
                    "KEY=VALUE: replace a scene value before validation (as run --set); "
                    "repeatable")
        ->expected(1)
        ->take_all();
    return {cmd, [cmd, f](RunMode mode) {
                ServeOptions& serve = f->serve;
                serve.dry_run = mode == RunMode::DryRun;
                for (const char* name :
                     {"--out", "--session", "--broadphase", "--host", "--replay"}) {
                    if (cmd->count(name) > 0 && cmd->get_option(name)->as<std::string>().empty()) {
                        std::cerr << name << ": must not be empty\n";
                        return kExitBadInput;
                    }
                }
                if (f->replay.empty() && serve.scene.empty()) {
                    std::cerr << "serve: a scene file, or --replay RECORDING, is required\n";
                    return kExitBadInput;
                }
                if (!f->replay.empty()) serve.replay = f->replay;
                if (!f->out_dir.empty()) serve.out_dir = f->out_dir;
                if (!f->session.empty()) serve.session_log = f->session;
                if (!f->broad_phase.empty()) serve.broad_phase = f->broad_phase;
                for (const std::string& kv : f->set) {
                    const std::size_t eq = kv.find('=');
                    if (eq == std::string::npos || eq == 0) {
                        std::cerr << "--set '" << kv << "': expected KEY=VALUE\n";
                        return kExitBadInput;
                    }
                    serve.overrides.push_back({kv.substr(0, eq), kv.substr(eq + 1)});
                }
                return serveScene(serve, std::cout, std::cerr);
            }};
}

}  // namespace app
