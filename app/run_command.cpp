// app/run_command.cpp -- `cdlab run`: the flags of the main job (lab/run_scene.h runs it).
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "command.h"
#include "exit_codes.h"
#include "run_scene.h"

namespace app {

namespace {

// --pair-order's help: the orders, and the broad phases that have one of their own.
std::string pairOrderHelp() {
    std::string own;
    for (const collision::BroadPhaseEntry& e : collision::broadPhaseRegistry()) {
        if (!e.found_order) continue;
        if (!own.empty()) own += ", ";
        own += e.name;
    }
    return "order of the flagged and confirmed pairs (overrides the scene's pair_order): sorted "
           "(by body ids, the default) or found (the broad phase's own order, without a final "
           "sort: " +
           own +
           "; every other broad phase's own order is sorted, so found changes nothing there). "
           "The same pairs and the same motion either way; --trace and pause dumps list pairs "
           "sorted";
}

}  // namespace

Command addRunCommand(CLI::App& cli) {
    // The flags' storage lives as long as the returned command (shared with its run function).
    struct Flags {
        RunOptions run;
        std::string out_dir;
        std::string video;
        int frames = 0;
        std::string broad_phase;
        std::string pair_order;
        bool no_timing = false;
        std::string stats;
        bool quiet = false;
        std::vector<std::string> set;
        std::string trace;
        std::string record;
        std::string events;
    };
    auto f = std::make_shared<Flags>();
    CLI::App* cmd = cli.add_subcommand("run", "simulate a scene, write PNG frames and a video");
    cmd->add_option("scene", f->run.scene, "scene file (YAML)")->required();
    cmd->add_option("--out", f->out_dir, "output directory (default out/<scene name>)");
    cmd->add_option("--frames", f->frames, "number of frames (overrides the scene)");
    CLI::Option* video_opt =
        cmd->add_option("--video", f->video, "video file (default <out>/<scene name>.mp4)");
    cmd->add_flag("--no-video", f->run.no_video, "do not write a video")->excludes(video_opt);
    cmd->add_flag("--no-frames", f->run.no_frames, "do not write per-frame PNGs");
    cmd->add_option("--broadphase", f->broad_phase,
                    "broad phase (overrides the scene): " + collision::broadPhaseNames());
    cmd->add_option("--pair-order", f->pair_order, pairOrderHelp());
    cmd->add_option("--pause-at", f->run.pause_at,
                    "pause at FRAME: write pause_FRAME.png (every bounding volume, each "
                    "coloured by its own overlap test) and pause_FRAME.json (repeatable); the "
                    "video holds the picture for --pause-hold seconds")
        ->expected(1)
        ->take_all();
    cmd->add_option("--events", f->events,
                    "FILE: follow this events track (a YAML mapping with 'events:', as a scene's "
                    "own) instead of the scene's: play, pause, step, seek, show/hide layers, "
                    "switch the broad phase, select a body, move the camera, dump, wait");
    cmd->add_option("--pause-hold", f->run.pause_hold_s,
                    "seconds each pause picture stays on screen in the video, as in a live "
                    "demo (default 2; 0: no hold); the PNG frames are not repeated");
    cmd->add_flag("--no-hud-timing", f->no_timing,
                  "leave the step time out of the HUD so frames are bit-identical");
    cmd->add_flag("--draw-structure", f->run.draw_structure,
                  "draw the broad phase's own structure, with a legend: grid/hash cells, "
                  "hierarchical-grid cells by level, SAP/sap1 sorted intervals along the edges "
                  "of the world bounds, tree and octree nodes by depth");
    cmd->add_flag("--check-broadphase", f->run.check_broad_phase,
                  "verify every step's pairs against the brute-force reference; stop with a "
                  "report (exit 3) at the first mismatch");
    cmd->add_option("--stats", f->stats, "write per-frame counters and stage times to FILE.csv");
    cmd->add_flag("--html", f->run.html,
                  "write <out>/index.html, a page that opens from disk without a network: the "
                  "video, a timeline of flagged and confirmed pairs and of each stage's time per "
                  "frame with a cursor that follows the video (click to seek), and each "
                  "--pause-at picture with its bodies and pairs (hover or click a body for its "
                  "volumes and state)");
    cmd->add_flag("--quiet", f->quiet, "no progress bar");
    cmd->add_flag("--timing", f->run.timing,
                  "print where the time went: wall time and fps, and milliseconds per frame for "
                  "simulation, rendering, readback, PNG compression and video encoding");
    cmd->add_option("--set", f->set,
                    "KEY=VALUE: replace a scene value before validation, KEY a dotted path "
                    "(world.time_step, bodies.2.radius); repeatable")
        ->expected(1)
        ->take_all();
    cmd->add_option("--trace", f->trace,
                    "write every frame's body poses and flagged and confirmed pairs to FILE "
                    "(JSON lines)");
    cmd->add_option("--record", f->record,
                    "write a recording to FILE: every frame's body states, pairs and state "
                    "hash, for `cdlab serve --replay FILE` (shown without simulating) and "
                    "`cdlab replay FILE --check` (simulated again, compared frame by frame)")
        ->type_name("FILE");
    return {cmd, [cmd, f](RunMode mode) {
                RunOptions& run = f->run;
                run.dry_run = mode == RunMode::DryRun;
                // A flag given with an empty value ("--broadphase ''") is an error, not "unset".
                for (const char* name :
                     {"--out", "--video", "--broadphase", "--pair-order", "--stats", "--trace", "--record",
                      "--events"}) {
                    if (cmd->count(name) > 0 && cmd->get_option(name)->as<std::string>().empty()) {
                        std::cerr << name << ": must not be empty\n";
                        return kExitBadInput;
                    }
                }
                if (!f->out_dir.empty()) run.out_dir = f->out_dir;
                if (!f->video.empty()) run.video = f->video;
                if (cmd->count("--frames") > 0) run.frames = f->frames;
                if (!f->broad_phase.empty()) run.broad_phase = f->broad_phase;
                if (!f->pair_order.empty()) run.pair_order = f->pair_order;
                if (!f->stats.empty()) run.stats_csv = f->stats;
                if (!f->events.empty()) run.events = f->events;
                for (const std::string& kv : f->set) {
                    const std::size_t eq = kv.find('=');
                    if (eq == std::string::npos || eq == 0) {
                        std::cerr << "--set '" << kv << "': expected KEY=VALUE\n";
                        return kExitBadInput;
                    }
                    run.overrides.push_back({kv.substr(0, eq), kv.substr(eq + 1)});
                }
                if (!f->trace.empty()) run.trace = f->trace;
                if (!f->record.empty()) run.record = f->record;
                run.hud_timing = !f->no_timing;
                run.progress = !f->quiet;
                return runScene(run, std::cout, std::cerr);
            }};
}

}  // namespace app
