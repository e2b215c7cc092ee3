// app/sweep_command.cpp -- `cdlab sweep`: the flags of a sweep over scene choices (lab/sweep.h),
// run in one process, N processes at a time (-j), or planned as independent jobs (--plan, --job,
// --collect: lab/sweep_plan.h).
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "command.h"
#include "exit_codes.h"
#include "sweep.h"
#include "sweep_collect.h"
#include "sweep_job.h"
#include "sweep_plan.h"

namespace app {

namespace {

struct Flags {
    SweepOptions sweep;
    std::string out;
    double duration = 0;
    std::string float_binary;
    bool no_timing = false;
    std::string plan;
    bool slurm = false;
    std::string job;
    long run = -1;
    std::string collect;
};

// Which of the sweep's modes the flags ask for, and the flags that do not go with it.
int runSweepCommand(const CLI::App& cmd, Flags& f, RunMode mode) {
    SweepOptions& sweep = f.sweep;
    sweep.dry_run = mode == RunMode::DryRun;
    if (!f.out.empty()) sweep.out_dir = f.out;
    if (cmd.count("--duration") > 0) sweep.duration = f.duration;
    sweep.report_timing = !f.no_timing;
    if (!f.float_binary.empty()) sweep.float_binary = f.float_binary;
    const int modes = int(!f.job.empty()) + int(!f.collect.empty()) + int(!f.plan.empty());
    if (modes > 1) {
        std::cerr << "sweep: --plan, --job and --collect are separate steps; give one\n";
        return kExitBadInput;
    }
    const bool has_scene = !sweep.scene.empty();
    if (!f.job.empty() || !f.collect.empty()) {
        if (has_scene || !sweep.vary.empty() || cmd.count("-j") > 0) {
            std::cerr << "sweep " << (f.job.empty() ? "--collect" : "--job")
                      << ": the plan holds the scene and its runs; leave out SCENE, --vary and "
                         "-j\n";
            return kExitBadInput;
        }
    }
    if (!f.job.empty()) {
        if (cmd.count("--run") == 0) {
            std::cerr << "sweep --job: --run K is required (the job's number)\n";
            return kExitBadInput;
        }
        if (sweep.dry_run) return checkInputsExist({{"--job", f.job}}, std::cerr);
        return sweep::runSweepJob(f.job, f.run, std::cout, std::cerr);
    }
    if (cmd.count("--run") > 0) {
        std::cerr << "sweep --run: only with --job\n";
        return kExitBadInput;
    }
    if (!f.collect.empty()) {
        if (sweep.dry_run) return checkInputsExist({{"--collect", f.collect}}, std::cerr);
        sweep::CollectOptions collect;
        collect.plan = f.collect;
        collect.out_dir = f.out;
        collect.report_timing = sweep.report_timing;
        return sweep::collectSweep(collect, std::cout, std::cerr);
    }
    if (!has_scene) {
        std::cerr << "sweep: a scene file is required (or --job, or --collect)\n";
        return kExitBadInput;
    }
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    sweep.cdlab_binary = self;
    if (f.slurm && f.plan.empty()) {
        std::cerr << "sweep --slurm: only with --plan DIR\n";
        return kExitBadInput;
    }
    if (!f.plan.empty()) {
        if (cmd.count("-j") > 0) {
            std::cerr << "sweep --plan: -j runs a sweep here; a plan's jobs are run by you\n";
            return kExitBadInput;
        }
        return sweep::planSweep(sweep, f.plan, f.slurm, self, std::cout, std::cerr);
    }
    return runSweep(sweep, std::cout, std::cerr);
}

}  // namespace

Command addSweepCommand(CLI::App& cli) {
    auto f = std::make_shared<Flags>();
    CLI::App* cmd = cli.add_subcommand(
        "sweep",
        "run one scene under every combination of choices; measure cost and accuracy "
        "against a fine reference run; write results.csv, report.md, charts and report.html "
        "(a page that opens from disk: the charts and a sortable table). Runs in "
        "this process, -j N processes at a time, or as independent jobs for GNU Parallel or a "
        "Slurm array (--plan DIR, then --collect DIR)");
    cmd->add_option("scene", f->sweep.scene, "scene file (YAML); not with --job or --collect");
    cmd->add_option("--vary", f->sweep.vary,
                    "KEY=V1,V2,... (repeatable): a dotted scene key and its values, e.g. "
                    "broadphase=sap,hgrid or world.time_step=0.01,0.002")
        ->expected(1)
        ->take_all();
    cmd->add_option("--reference", f->sweep.reference,
                    "KEY=VALUE (repeatable): a setting of the reference run, the yardstick every "
                    "run's missed and extra contacts and first-contact errors are measured "
                    "against. The reference is the scene at its time step divided by "
                    "--reference-refine (default dt / 10), then these overrides: give it your "
                    "most accurate choices (e.g. world.ccd=conservative_advancement) and a step "
                    "finer than every --vary step (world.time_step=... here overrides the "
                    "refined step). A run at the reference's step or finer is flagged: its "
                    "accuracy figures prove nothing. Check the reference is fine enough by "
                    "raising --reference-refine: the figures should not change")
        ->expected(1)
        ->take_all();
    cmd->add_option("--reference-refine", f->sweep.reference_refine,
                    "the reference's time step is the scene's divided by this (>= 1)")
        ->capture_default_str();
    cmd->add_option("--repeat", f->sweep.repeat,
                    "time every run (the reference too) N times, N >= 1; tables give the median "
                    "and min..max range of each wall-clock column (steady_clock), and the reading "
                    "names a cheapest run only when its range lies below the others'; repeats "
                    "must reproduce every deterministic column")
        ->capture_default_str();
    cmd->add_option("--duration", f->duration,
                    "simulated seconds per run (default: the scene's frames)");
    cmd->add_option("--out", f->out, "output directory (default out/sweep_<scene>)");
    cmd->add_option("--float-binary", f->float_binary,
                    "a cdlab built with -DCDLAB_USE_FLOAT=ON: compare every run's frames "
                    "with it (float_vs_double.csv, a report section)");
    cmd->add_flag("--keep-traces", f->sweep.keep_traces,
                  "keep DIR/traces/ (both builds' frames) after the float comparison");
    cmd->add_flag("--no-report-timing", f->no_timing,
                  "leave times (wall-clock and CPU) out of report.md so it is bit-identical");
    cmd->add_option("-j,--jobs", f->sweep.jobs,
                    "run N runs at a time, each a cdlab process of its own (a plan in OUT/plan, "
                    "collected into OUT); the reading then ranks by CPU time when runs overlapped")
        ->capture_default_str();
    cmd->add_option("--plan", f->plan,
                    "write the sweep as independent jobs into DIR instead of running it: "
                    "DIR/jobs.txt has one command line per run (the reference first), each "
                    "writing DIR/results/K.json; run them anywhere (GNU Parallel, Slurm), then "
                    "--collect DIR");
    cmd->add_flag("--slurm", f->slurm,
                  "with --plan: also write DIR/sweep.sbatch, a Slurm job array of the jobs");
    cmd->add_option("--job", f->job, "run one job of a plan: DIR/plan.json (or DIR), with --run");
    cmd->add_option("--run", f->run, "with --job: the job's number K (line K + 1 of jobs.txt)");
    cmd->add_option("--collect", f->collect,
                    "merge the results of the plan in DIR into results.csv, report.md and charts "
                    "(in DIR, or --out); names every missing or failed job and exits 1");
    return {cmd, [cmd, f](RunMode mode) { return runSweepCommand(*cmd, *f, mode); }};
}

}  // namespace app
