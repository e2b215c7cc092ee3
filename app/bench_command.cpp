// app/bench_command.cpp -- the `cdlab bench` subcommands' flags: broadphase, ccd, convex,
// narrowphase (lab/bench_*.h). A dry run stops after the flags' checks (and, for ccd, checks
// that the folders named exist).
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "bench_broadphase.h"
#include "bench_ccd.h"
#include "bench_convex.h"
#include "bench_narrowphase.h"
#include "command.h"
#include "exit_codes.h"

namespace app {

Command addBenchBroadphaseCommand(CLI::App& bench) {
    struct Flags {
        BenchOptions options;
        std::string json;
        bool in_process = false;
    };
    auto f = std::make_shared<Flags>();
    BenchOptions& o = f->options;
    CLI::App* cmd = bench.add_subcommand(
        "broadphase", "cdlab's broad phases beside Bullet and FCL on moving boxes");
    cmd->add_option("--sizes", o.sizes, "box counts, comma-separated")
        ->delimiter(',')
        ->capture_default_str();
    cmd->add_option("--frames", o.frames, "measured frames per method")->capture_default_str();
    cmd->add_option("--methods", o.methods,
                    "comma-separated (default: every AABB broad phase, sap-packed-loose -- "
                    "sap-packed's candidates unfiltered, a loose pair cache like Bullet's -- and "
                    "the default peers); hgrid:found, hgrid2:found: pairs in the order found, not "
                    "sorted; terdiman-v17: Terdiman's BoxPruning17, a peer when built with "
                    "-DCDLAB_BOXPRUNING_DIR (float boxes: exact on the boxpruning workload)")
        ->delimiter(',');
    cmd->add_option("--workload", o.workload,
                    "uniform, mixed (sizes 1:100), both (those two), wide (sizes 1:10^4) or "
                    "boxpruning (Terdiman's scene, one-shot and moving; sizes default to "
                    "10000,100000)")
        ->check(CLI::IsMember({"uniform", "mixed", "both", "wide", "boxpruning"}))
        ->capture_default_str();
    cmd->add_option("--peers", o.peers,
                    "tuned: sweep each peer's settings (DBVT margin, prediction, deferred; SAP "
                    "world size and handle bits; FCL update and tree build), each setting on all "
                    "frames, and compare with the best of each by its median (and by the "
                    "exact-pairs median); all: the same and print every configuration; default: "
                    "each peer at its defaults")
        ->check(CLI::IsMember({"tuned", "all", "default"}))
        ->capture_default_str();
    cmd->add_option("--json", f->json, "also write the rows as JSON to FILE");
    cmd->add_option("--seed", o.seed, "workload seed")->capture_default_str();
    cmd->add_option("--budget", o.budget_seconds,
                    "stop a method after this many seconds of frame time (0: no limit)")
        ->capture_default_str();
    cmd->add_option("--clock", o.clock,
                    "thread: thread CPU time per frame (methods on several threads left out; "
                    "cullide, which renders on llvmpipe's threads, by process CPU time); wall: "
                    "elapsed time, every method")
        ->check(CLI::IsMember({"thread", "wall"}))
        ->capture_default_str();
    cmd->add_option("--rounds", o.rounds,
                    "run each table's rows this many times, interleaved (every other round in "
                    "reverse order), and report medians over the rounds with each round's ratios "
                    "(a machine that runs slow for a stretch then costs a round, not a row)")
        ->check(CLI::Range(1, kMaxBenchRounds))
        ->capture_default_str();
    cmd->add_option("--interleave", o.interleave,
                    "FRAMES > 0: after a first pass of each row alone (peer tuning, memory), "
                    "time the rows --rounds times measured together: all alive at once, FRAMES "
                    "frames each per turn (one-shot: one repetition), the order reversed every "
                    "turn, so a slow stretch of the machine costs every row alike; 0: rounds run "
                    "row after row")
        ->check(CLI::Range(0, kMaxInterleaveFrames))
        ->capture_default_str();
    cmd->add_flag("--in-process", f->in_process,
                  "do not fork per method (no per-method peak memory)");
    return {cmd, [f, cmd](RunMode mode) {
                if (mode == RunMode::DryRun) return kExitOk;
                if (!f->json.empty()) f->options.json = f->json;
                f->options.isolate = !f->in_process;
                if (f->options.workload == "boxpruning" && cmd->count("--sizes") == 0) {
                    f->options.sizes = {10000, 100000};
                }
                return runBenchBroadphase(f->options, std::cout, std::cerr);
            }};
}

Command addBenchCcdCommand(CLI::App& bench) {
    struct Flags {
        BenchCcdOptions options;
        std::vector<std::string> dirs;
        std::string json;
        std::string scenes;
        bool no_scenes = false;
    };
    auto f = std::make_shared<Flags>();
    CLI::App* cmd = bench.add_subcommand(
        "ccd", "vertex-face and edge-edge CCD methods on the sample queries: FN, FP, us/query");
    cmd->add_option("dirs", f->dirs, "query directories (default tests/data/ccd-sample-queries)");
    cmd->add_option("--json", f->json, "also write the table as JSON to FILE");
    cmd->add_option("--method", f->options.method,
                    "conservative, naive, tight-inclusion (when configured with it) or all")
        ->check(CLI::IsMember({"conservative", "naive", "tight-inclusion", "all"}))
        ->capture_default_str();
    cmd->add_option("--reps", f->options.reps,
                    "runs per query; a query's time is its fastest run")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    cmd->add_option("--scenes", f->scenes,
                    "folder with tunnel_sphere.yaml and tunnel_bar.yaml (default scenes): "
                    "CCD cost per frame, off vs on");
    cmd->add_flag("--no-scenes", f->no_scenes, "skip the tunnelling scenes");
    return {cmd, [f](RunMode mode) {
                if (mode == RunMode::DryRun) {
                    std::vector<NamedInput> inputs;
                    for (const std::string& d : f->dirs) inputs.push_back({"dirs", d});
                    if (!f->scenes.empty()) inputs.push_back({"--scenes", f->scenes});
                    return checkInputsExist(inputs, std::cerr);
                }
                BenchCcdOptions& o = f->options;
                for (const std::string& d : f->dirs) o.dirs.emplace_back(d);
                if (!f->json.empty()) o.json = f->json;
                if (!f->scenes.empty()) {
                    o.scenes_dir = f->scenes;
                    o.scenes_explicit = true;
                }
                o.scenes = !f->no_scenes;
                return runBenchCcd(o, std::cout, std::cerr);
            }};
}

Command addBenchConvexCommand(CLI::App& bench) {
    auto f = std::make_shared<OptionsWithJson<BenchConvexOptions>>();
    BenchConvexOptions& o = f->options;
    CLI::App* cmd = bench.add_subcommand(
        "convex",
        "convex contact queries (GJK, EPA, SAT, closed forms) beside Bullet's own path per pair "
        "(btBoxBoxDetector, its closed forms) and its general GJK/EPA: us/query, errors against "
        "an exact reference");
    cmd->add_option("--queries", o.queries, "random pairs per workload")->capture_default_str();
    cmd->add_option("--passes", o.passes, "timed passes (median kept)")->capture_default_str();
    cmd->add_option("--seed", o.seed, "pose seed")->capture_default_str();
    cmd->add_option("--workload", o.workload,
                    "only the workloads whose name contains this text (e.g. box-box)");
    cmd->add_option("--tolerance", o.tolerance,
                    "relative tolerance for counting answers as wrong")
        ->capture_default_str();
    cmd->add_option("--json", f->json, "also write the rows as JSON to FILE");
    return {cmd, [f](RunMode mode) {
                if (mode == RunMode::DryRun) return kExitOk;
                return runBenchConvex(f->resolved(), std::cout, std::cerr);
            }};
}

Command addBenchNarrowphaseCommand(CLI::App& bench) {
    auto f = std::make_shared<OptionsWithJson<BenchNarrowphaseOptions>>();
    BenchNarrowphaseOptions& o = f->options;
    CLI::App* cmd =
        bench.add_subcommand("narrowphase",
                             "mesh-mesh queries on two tori: every BVH volume type beside FCL's "
                             "BVHModel types (build, first contact, all pairs, Nv, Np)");
    cmd->add_option("--triangles", o.triangles, "triangles per torus")->capture_default_str();
    cmd->add_flag("--large", o.large, "100k-triangle tori");
    cmd->add_option("--poses", o.poses, "poses, even: half collide")->capture_default_str();
    cmd->add_option("--reps", o.reps, "repetitions per pose (fastest counts)")
        ->capture_default_str();
    cmd->add_option("--rounds", o.rounds,
                    "measure the methods this many times, interleaved (every other round in "
                    "reverse order), and report each time's median over the rounds with each "
                    "round's best ratios (a machine that runs slow for a stretch then costs a "
                    "round, not a method)")
        ->capture_default_str();
    cmd->add_option("--seed", o.seed, "pose seed")->capture_default_str();
    cmd->add_option("--methods", o.methods,
                    "comma-separated (default all): volume names (NAME-bu: bottom-up build; "
                    "obb4, the 4-wide OBB tree, has no Cv/Cp) "
                    "and fcl-obbrss, fcl-obb, fcl-rss, fcl-kios, fcl-aabb, fcl-kdop18 "
                    "(FCL-NAME-median, FCL-NAME-center: FCL's other split rules)")
        ->delimiter(',');
    cmd->add_option("--json", f->json, "also write the table as JSON to FILE");
    return {cmd, [f](RunMode mode) {
                if (mode == RunMode::DryRun) return kExitOk;
                return runBenchNarrowphase(f->resolved(), std::cout, std::cerr);
            }};
}

}  // namespace app
