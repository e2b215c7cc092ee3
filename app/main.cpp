// app/main.cpp -- the cdlab command line: parses flags and hands off to the commands.
#include <CLI/CLI.hpp>
#include <iostream>

#include "collision/broad_phase.h"
#include "run_command.h"

int main(int argc, char** argv) {
    CLI::App cli{"cdlab -- collision-detection lab: run rigid-body scenes headless and render "
                 "every bounding volume coloured by its overlap state"};
    cli.require_subcommand(1);

    app::RunOptions run;
    std::string out_dir;
    std::string video;
    int frames = 0;
    std::string broad_phase;
    CLI::App* run_cmd = cli.add_subcommand("run", "simulate a scene, write PNG frames and a video");
    run_cmd->add_option("scene", run.scene, "scene file (YAML)")->required();
    run_cmd->add_option("--out", out_dir, "output directory (default out/<scene name>)");
    run_cmd->add_option("--frames", frames, "number of frames (overrides the scene)");
    run_cmd->add_option("--video", video, "video file (default <out>/<scene name>.mp4)");
    run_cmd->add_flag("--no-video", run.no_video, "do not write a video");
    run_cmd->add_flag("--no-frames", run.no_frames, "do not write per-frame PNGs");
    run_cmd->add_option("--broadphase", broad_phase,
                        "broad phase (overrides the scene): " + collision::broadPhaseNames());
    run_cmd->add_option("--pause-at", run.pause_at,
                        "pause at FRAME: write pause_FRAME.png (every bounding volume) and "
                        "pause_FRAME.json (repeatable)")
        ->expected(1)
        ->take_all();
    bool no_timing = false;
    run_cmd->add_flag("--no-hud-timing", no_timing,
                      "leave the step time out of the HUD so frames are bit-identical");
    bool quiet = false;
    run_cmd->add_flag("--quiet", quiet, "no progress bar");

    try {
        cli.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = cli.exit(e);
        return code == 0 ? 0 : 2;
    }

    if (run_cmd->parsed()) {
        if (!out_dir.empty()) run.out_dir = out_dir;
        if (!video.empty()) run.video = video;
        if (run_cmd->count("--frames") > 0) run.frames = frames;
        if (!broad_phase.empty()) run.broad_phase = broad_phase;
        run.hud_timing = !no_timing;
        run.progress = !quiet;
        return app::runScene(run, std::cout, std::cerr);
    }
    return 2;
}
