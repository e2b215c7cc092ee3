// app/main.cpp -- the cdlab command line: parses flags and hands off to the commands.
#include <CLI/CLI.hpp>
#include <iostream>

#include "bench_broadphase.h"
#include "bench_ccd.h"
#include "bench_convex.h"
#include "collision/broad_phase.h"
#include "query_command.h"
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
    run_cmd->add_flag("--draw-structure", run.draw_structure,
                      "draw the broad phase's own structure: grid/hash cells, hierarchical-grid "
                      "cells by level, SAP intervals, tree and octree nodes by depth");
    run_cmd->add_flag("--check-broadphase", run.check_broad_phase,
                      "verify every step's pairs against the brute-force reference; stop with a "
                      "report (exit 3) at the first mismatch");
    std::string stats;
    run_cmd->add_option("--stats", stats, "write per-frame counters and stage times to FILE.csv");
    bool quiet = false;
    run_cmd->add_flag("--quiet", quiet, "no progress bar");

    // BEGIN ccd subcommand
    // END ccd subcommand
    // BEGIN query subcommand
    app::QueryOptions query;
    CLI::App* query_cmd = cli.add_subcommand(
        "query", "mesh against mesh through every BVH volume type: answer, triangle pairs, "
                 "BV and triangle tests, build and query time side by side");
    query_cmd->add_option("mesh_a", query.mesh_a, "mesh A (any format assimp reads)")->required();
    query_cmd->add_option("mesh_b", query.mesh_b, "mesh B")->required();
    query_cmd->add_option("--bv", query.bv, "volume type or all")->capture_default_str();
    query_cmd->add_option("--pose-b", query.pose_b,
                          "B's pose in A's frame: x,y,z,qw,qx,qy,qz (default identity)");
    query_cmd->add_flag("--json", query.json, "machine-readable output");
    // END query subcommand
    // BEGIN bench subcommand (registered by app/bench_*.cpp)
    CLI::App* bench_cmd = cli.add_subcommand("bench", "performance benchmarks");
    bench_cmd->require_subcommand(1);
    app::BenchOptions bench_bp;
    std::string bench_bp_json;
    CLI::App* bench_bp_cmd = bench_cmd->add_subcommand(
        "broadphase", "cdlab's broad phases beside Bullet and FCL on moving boxes");
    bench_bp_cmd->add_option("--sizes", bench_bp.sizes, "box counts, comma-separated")
        ->delimiter(',')
        ->capture_default_str();
    bench_bp_cmd->add_option("--frames", bench_bp.frames, "measured frames per method")
        ->capture_default_str();
    bench_bp_cmd
        ->add_option("--methods", bench_bp.methods,
                     "comma-separated (default: every AABB broad phase and the default peers)")
        ->delimiter(',');
    bench_bp_cmd->add_option("--workload", bench_bp.workload, "uniform, mixed or both")
        ->check(CLI::IsMember({"uniform", "mixed", "both"}))
        ->capture_default_str();
    bench_bp_cmd->add_option("--json", bench_bp_json, "also write the rows as JSON to FILE");
    bench_bp_cmd->add_option("--seed", bench_bp.seed, "workload seed")->capture_default_str();
    bench_bp_cmd
        ->add_option("--budget", bench_bp.budget_seconds,
                     "stop a method after this many seconds of frame time (0: no limit)")
        ->capture_default_str();
    bool bench_bp_in_process = false;
    bench_bp_cmd->add_flag("--in-process", bench_bp_in_process,
                           "do not fork per method (no per-method peak memory)");
    app::BenchCcdOptions bench_ccd;
    std::vector<std::string> bench_ccd_dirs;
    std::string bench_ccd_json;
    CLI::App* bench_ccd_cmd = bench_cmd->add_subcommand(
        "ccd", "vertex-face and edge-edge CCD methods on the sample queries: FN, FP, us/query");
    bench_ccd_cmd->add_option("dirs", bench_ccd_dirs,
                              "query directories (default tests/data/ccd-sample-queries)");
    bench_ccd_cmd->add_option("--json", bench_ccd_json, "also write the table as JSON to FILE");
    bench_ccd_cmd->add_option("--method", bench_ccd.method, "conservative, naive or all")
        ->check(CLI::IsMember({"conservative", "naive", "all"}))
        ->capture_default_str();
    std::string bench_ccd_scenes;
    bench_ccd_cmd->add_option("--scenes", bench_ccd_scenes,
                              "folder with tunnel_sphere.yaml and tunnel_bar.yaml (default scenes): "
                              "CCD cost per frame, off vs on");
    bool bench_ccd_no_scenes = false;
    bench_ccd_cmd->add_flag("--no-scenes", bench_ccd_no_scenes, "skip the tunnelling scenes");
    app::BenchConvexOptions bench_convex;
    std::string bench_convex_json;
    CLI::App* bench_convex_cmd = bench_cmd->add_subcommand(
        "convex", "convex contact queries (GJK, EPA, SAT, closed forms) beside Bullet's GJK/EPA: "
                  "us/query, answers compared");
    bench_convex_cmd->add_option("--queries", bench_convex.queries, "random pairs per workload")
        ->capture_default_str();
    bench_convex_cmd->add_option("--passes", bench_convex.passes, "timed passes (fastest kept)")
        ->capture_default_str();
    bench_convex_cmd->add_option("--seed", bench_convex.seed, "pose seed")->capture_default_str();
    bench_convex_cmd
        ->add_option("--tolerance", bench_convex.tolerance,
                     "relative answer tolerance for counting disagreements")
        ->capture_default_str();
    bench_convex_cmd->add_option("--json", bench_convex_json, "also write the rows as JSON to FILE");
    // END bench subcommand

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
        if (!stats.empty()) run.stats_csv = stats;
        run.hud_timing = !no_timing;
        run.progress = !quiet;
        return app::runScene(run, std::cout, std::cerr);
    }
    // BEGIN ccd dispatch
    // END ccd dispatch
    // BEGIN query dispatch
    if (query_cmd->parsed()) return app::runQuery(query, std::cout, std::cerr);
    // END query dispatch
    // BEGIN bench dispatch
    if (bench_bp_cmd->parsed()) {
        if (!bench_bp_json.empty()) bench_bp.json = bench_bp_json;
        bench_bp.isolate = !bench_bp_in_process;
        return app::runBenchBroadphase(bench_bp, std::cout, std::cerr);
    }
    if (bench_ccd_cmd->parsed()) {
        for (const std::string& d : bench_ccd_dirs) bench_ccd.dirs.emplace_back(d);
        if (!bench_ccd_json.empty()) bench_ccd.json = bench_ccd_json;
        if (!bench_ccd_scenes.empty()) {
            bench_ccd.scenes_dir = bench_ccd_scenes;
            bench_ccd.scenes_explicit = true;
        }
        bench_ccd.scenes = !bench_ccd_no_scenes;
        return app::runBenchCcd(bench_ccd, std::cout, std::cerr);
    }
    if (bench_convex_cmd->parsed()) {
        if (!bench_convex_json.empty()) bench_convex.json = bench_convex_json;
        return app::runBenchConvex(bench_convex, std::cout, std::cerr);
    }
    // END bench dispatch
    return 2;
}
