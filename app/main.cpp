// app/main.cpp -- the cdlab command line: parses flags and hands off to the commands.
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <new>

#include "bench_broadphase.h"
#include "bench_ccd.h"
#include "bench_convex.h"
#include "bench_narrowphase.h"
#include "check_command.h"
#include "collision/broad_phase.h"
#include "query_command.h"
#include "run_command.h"
#include "sweep_command.h"

namespace {

int runCli(int argc, char** argv) {
    CLI::App cli{
        "cdlab -- collision-detection lab: run rigid-body scenes headless and render "
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
    CLI::Option* video_opt =
        run_cmd->add_option("--video", video, "video file (default <out>/<scene name>.mp4)");
    run_cmd->add_flag("--no-video", run.no_video, "do not write a video")->excludes(video_opt);
    run_cmd->add_flag("--no-frames", run.no_frames, "do not write per-frame PNGs");
    run_cmd->add_option("--broadphase", broad_phase,
                        "broad phase (overrides the scene): " + collision::broadPhaseNames());
    run_cmd
        ->add_option("--pause-at", run.pause_at,
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
    std::vector<std::string> run_set;
    run_cmd
        ->add_option("--set", run_set,
                     "KEY=VALUE: replace a scene value before validation, KEY a dotted path "
                     "(world.time_step, bodies.2.radius); repeatable")
        ->expected(1)
        ->take_all();
    std::string run_trace;
    run_cmd->add_option("--trace", run_trace,
                        "write every frame's body poses and confirmed pairs to FILE (JSON lines)");

    app::CheckOptions check;
    std::vector<std::string> check_scenes;
    int check_frames = 0;
    std::string check_out;
    CLI::App* check_cmd =
        cli.add_subcommand("check",
                           "run scenes headless and grade them against their 'expect:' sections: a "
                           "pass/fail table, exit 0 all pass, 1 any failure, 2 bad input");
    check_cmd->add_option("scenes", check_scenes, "scene files (YAML)")->required();
    check_cmd->add_option("--frames", check_frames,
                          "frames to run (overrides expect.frames and the scene)");
    check_cmd->add_option("--out", check_out,
                          "keep pause dumps in DIR (default: a temporary folder, removed)");
    app::QueryOptions query;
    CLI::App* query_cmd = cli.add_subcommand(
        "query",
        "mesh against mesh through every BVH volume type: answer, triangle pairs, "
        "BV and triangle tests, build and query time side by side");
    query_cmd->add_option("mesh_a", query.mesh_a, "mesh A (any format assimp reads)")->required();
    query_cmd->add_option("mesh_b", query.mesh_b, "mesh B")->required();
    query_cmd->add_option("--bv", query.bv, "volume type or all")->capture_default_str();
    query_cmd->add_option("--pose-b", query.pose_b,
                          "B's pose in A's frame: x,y,z,qw,qx,qy,qz (default identity)");
    query_cmd->add_flag("--json", query.json, "machine-readable output");
    app::SweepOptions sweep;
    std::string sweep_out;
    double sweep_duration = 0;
    CLI::App* sweep_cmd = cli.add_subcommand(
        "sweep",
        "run one scene under every combination of choices; measure cost and accuracy "
        "against a fine reference run; write results.csv, report.md and charts");
    sweep_cmd->add_option("scene", sweep.scene, "scene file (YAML)")->required();
    sweep_cmd
        ->add_option("--vary", sweep.vary,
                     "KEY=V1,V2,... (repeatable): a dotted scene key and its values, e.g. "
                     "broadphase=sap,hgrid or world.time_step=0.01,0.002")
        ->expected(1)
        ->take_all();
    sweep_cmd
        ->add_option("--reference", sweep.reference,
                     "KEY=VALUE override for the reference run (repeatable)")
        ->expected(1)
        ->take_all();
    sweep_cmd
        ->add_option("--reference-refine", sweep.reference_refine,
                     "the reference's time step is the scene's divided by this")
        ->capture_default_str();
    sweep_cmd->add_option("--duration", sweep_duration,
                          "simulated seconds per run (default: the scene's frames)");
    sweep_cmd->add_option("--out", sweep_out, "output directory (default out/sweep_<scene>)");
    std::string sweep_float;
    sweep_cmd->add_option("--float-binary", sweep_float,
                          "a cdlab built with -DCDLAB_USE_FLOAT=ON: compare every run's frames "
                          "with it (float_vs_double.csv, a report section)");
    sweep_cmd->add_flag("--keep-traces", sweep.keep_traces,
                        "keep DIR/traces/ (both builds' frames) after the float comparison");
    bool sweep_no_timing = false;
    sweep_cmd->add_flag("--no-report-timing", sweep_no_timing,
                        "leave wall-clock times out of report.md so it is bit-identical");
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
    bench_bp_cmd
        ->add_option("--workload", bench_bp.workload,
                     "uniform, mixed (sizes 1:100), both (those two) or wide (sizes 1:10^4)")
        ->check(CLI::IsMember({"uniform", "mixed", "both", "wide"}))
        ->capture_default_str();
    bench_bp_cmd->add_option("--json", bench_bp_json, "also write the rows as JSON to FILE");
    bench_bp_cmd->add_option("--seed", bench_bp.seed, "workload seed")->capture_default_str();
    bench_bp_cmd
        ->add_option("--budget", bench_bp.budget_seconds,
                     "stop a method after this many seconds of frame time (0: no limit)")
        ->capture_default_str();
    bench_bp_cmd
        ->add_option("--clock", bench_bp.clock,
                     "thread: thread CPU time per frame (methods on several threads left out); "
                     "wall: elapsed time, every method")
        ->check(CLI::IsMember({"thread", "wall"}))
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
    bench_ccd_cmd->add_option(
        "--scenes", bench_ccd_scenes,
        "folder with tunnel_sphere.yaml and tunnel_bar.yaml (default scenes): "
        "CCD cost per frame, off vs on");
    bool bench_ccd_no_scenes = false;
    bench_ccd_cmd->add_flag("--no-scenes", bench_ccd_no_scenes, "skip the tunnelling scenes");
    app::BenchConvexOptions bench_convex;
    std::string bench_convex_json;
    CLI::App* bench_convex_cmd = bench_cmd->add_subcommand(
        "convex",
        "convex contact queries (GJK, EPA, SAT, closed forms) beside Bullet's GJK/EPA: "
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
    bench_convex_cmd->add_option("--json", bench_convex_json,
                                 "also write the rows as JSON to FILE");
    app::BenchNarrowphaseOptions bench_np;
    std::string bench_np_json;
    CLI::App* bench_np_cmd = bench_cmd->add_subcommand(
        "narrowphase",
        "mesh-mesh queries on two tori: every BVH volume type beside FCL's "
        "BVHModel types (build, first contact, all pairs, Nv, Np)");
    bench_np_cmd->add_option("--triangles", bench_np.triangles, "triangles per torus")
        ->capture_default_str();
    bench_np_cmd->add_flag("--large", bench_np.large, "100k-triangle tori");
    bench_np_cmd->add_option("--poses", bench_np.poses, "poses, even: half collide")
        ->capture_default_str();
    bench_np_cmd->add_option("--reps", bench_np.reps, "repetitions per pose (fastest counts)")
        ->capture_default_str();
    bench_np_cmd->add_option("--seed", bench_np.seed, "pose seed")->capture_default_str();
    bench_np_cmd
        ->add_option("--methods", bench_np.methods,
                     "comma-separated (default all): volume names (NAME-bu: bottom-up build) "
                     "and fcl-obbrss, fcl-obb, fcl-rss, fcl-kios, fcl-aabb, fcl-kdop18")
        ->delimiter(',');
    bench_np_cmd->add_option("--json", bench_np_json, "also write the table as JSON to FILE");

    try {
        cli.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = cli.exit(e);
        return code == 0 ? 0 : 2;
    }

    if (run_cmd->parsed()) {
        // A flag given with an empty value ("--broadphase ''") is an error, not "unset".
        for (const char* name : {"--out", "--video", "--broadphase", "--stats", "--trace"}) {
            if (run_cmd->count(name) > 0 && run_cmd->get_option(name)->as<std::string>().empty()) {
                std::cerr << name << ": must not be empty\n";
                return 2;
            }
        }
        if (!out_dir.empty()) run.out_dir = out_dir;
        if (!video.empty()) run.video = video;
        if (run_cmd->count("--frames") > 0) run.frames = frames;
        if (!broad_phase.empty()) run.broad_phase = broad_phase;
        if (!stats.empty()) run.stats_csv = stats;
        for (const std::string& kv : run_set) {
            const std::size_t eq = kv.find('=');
            if (eq == std::string::npos || eq == 0) {
                std::cerr << "--set '" << kv << "': expected KEY=VALUE\n";
                return 2;
            }
            run.overrides.push_back({kv.substr(0, eq), kv.substr(eq + 1)});
        }
        if (!run_trace.empty()) run.trace = run_trace;
        run.hud_timing = !no_timing;
        run.progress = !quiet;
        return app::runScene(run, std::cout, std::cerr);
    }
    if (sweep_cmd->parsed()) {
        if (!sweep_out.empty()) sweep.out_dir = sweep_out;
        if (sweep_cmd->count("--duration") > 0) sweep.duration = sweep_duration;
        sweep.report_timing = !sweep_no_timing;
        if (!sweep_float.empty()) sweep.float_binary = sweep_float;
        return app::runSweep(sweep, std::cout, std::cerr);
    }
    if (check_cmd->parsed()) {
        for (const std::string& sc : check_scenes) check.scenes.emplace_back(sc);
        if (check_cmd->count("--frames") > 0) check.frames = check_frames;
        if (!check_out.empty()) check.out_dir = check_out;
        return app::runCheck(check, std::cout, std::cerr);
    }
    if (query_cmd->parsed()) return app::runQuery(query, std::cout, std::cerr);
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
    if (bench_np_cmd->parsed()) {
        if (!bench_np_json.empty()) bench_np.json = bench_np_json;
        return app::runBenchNarrowphase(bench_np, std::cout, std::cerr);
    }
    return 2;
}

}  // namespace

// Whatever escapes a command ends the run with a message and exit 1, never an abort: running out
// of memory (a scene past what this machine holds) is reported as such.
int main(int argc, char** argv) {
    try {
        return runCli(argc, argv);
    } catch (const std::bad_alloc&) {
        std::cerr << "cdlab: out of memory (the scene or request needs more than this machine "
                     "can allocate)\n";
    } catch (const std::exception& e) {
        std::cerr << "cdlab: internal error: " << e.what() << "\n";
    }
    return 1;
}
