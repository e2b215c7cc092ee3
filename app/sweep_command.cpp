// app/sweep_command.cpp -- `cdlab sweep`: the flags of a sweep over scene choices (lab/sweep.h).
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "command.h"
#include "sweep.h"

namespace app {

Command addSweepCommand(CLI::App& cli) {
    struct Flags {
        SweepOptions sweep;
        std::string out;
        double duration = 0;
        std::string float_binary;
        bool no_timing = false;
    };
    auto f = std::make_shared<Flags>();
    CLI::App* cmd = cli.add_subcommand(
        "sweep",
        "run one scene under every combination of choices; measure cost and accuracy "
        "against a fine reference run; write results.csv, report.md, charts and report.html "
        "(a page that opens from disk: the charts and a sortable table)");
    cmd->add_option("scene", f->sweep.scene, "scene file (YAML)")->required();
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
                  "leave wall-clock times out of report.md so it is bit-identical");
    return {cmd, [cmd, f]() {
                SweepOptions& sweep = f->sweep;
                if (!f->out.empty()) sweep.out_dir = f->out;
                if (cmd->count("--duration") > 0) sweep.duration = f->duration;
                sweep.report_timing = !f->no_timing;
                if (!f->float_binary.empty()) sweep.float_binary = f->float_binary;
                return runSweep(sweep, std::cout, std::cerr);
            }};
}

}  // namespace app
