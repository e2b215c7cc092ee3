// app/replay_command.cpp -- `cdlab replay`: a recording's summary, or with --check the scene
// simulated again and compared with it frame by frame (lab/replay/replay_check.h).
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <string>

#include "command.h"
#include "exit_codes.h"
#include "replay/replay_check.h"

namespace app {

Command addReplayCommand(CLI::App& cli) {
    struct Flags {
        ReplayOptions replay;
        std::string scene;
        int frames = 0;
    };
    auto f = std::make_shared<Flags>();
    CLI::App* cmd = cli.add_subcommand(
        "replay", "what a recording (run --record FILE) holds; with --check, its scene simulated "
                  "again and compared frame by frame: exit 0 all equal, 3 the first frame that "
                  "differs named, 2 bad input");
    cmd->add_option("recording", f->replay.recording, "recording file")->required();
    cmd->add_flag("--check", f->replay.check,
                  "simulate the recorded scene again and name the first frame whose state "
                  "hash differs, with the first body and quantity that differ");
    cmd->add_option("--scene", f->scene,
                    "the scene file, if it has moved since the recording (its bytes must be "
                    "the same)")
        ->type_name("FILE");
    cmd->add_option("--frames", f->frames, "compare only the first N frames")->type_name("N");
    return {cmd, [cmd, f](RunMode mode) {
                if (cmd->count("--scene") > 0) {
                    if (f->scene.empty()) {
                        std::cerr << "--scene: must not be empty\n";
                        return kExitBadInput;
                    }
                    f->replay.scene = f->scene;
                }
                if (cmd->count("--frames") > 0) f->replay.frames = f->frames;
                f->replay.dry_run = mode == RunMode::DryRun;
                return replayRecording(f->replay, std::cout, std::cerr);
            }};
}

}  // namespace app
