// app/check_command.cpp -- `cdlab check`: the flags of grading scenes by their expect: sections
// (lab/check.h), and the hidden flags of the child process that grades one scene for `-j N`
// (lab/check_workers.h).
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "check.h"
#include "check_workers.h"
#include "command.h"
#include "exit_codes.h"

namespace app {

Command addCheckCommand(CLI::App& cli) {
    struct Flags {
        CheckOptions check;
        std::vector<std::string> scenes;
        int frames = 0;
        double timeout = 0;
        std::string out;
        std::string junit;
        std::string events;
        std::string worker_result;
        std::size_t worker_index = 0;
    };
    auto f = std::make_shared<Flags>();
    CLI::App* cmd = cli.add_subcommand(
        "check",
        "run scenes headless and grade them against their 'expect:' sections: a pass/fail "
        "table (scenes in command-line order), exit 0 all pass, 1 any failure, 2 bad input");
    cmd->add_option("scenes", f->scenes, "scene files (YAML)")->required();
    cmd->add_option("--frames", f->frames, "frames to run (overrides expect.frames and the scene)");
    cmd->add_option("--events", f->events,
                    "run each scene through this events track instead of its own events:, as "
                    "'cdlab run --events' plays it, and grade the file's expect: (else the "
                    "scene's) on that run")
        ->type_name("FILE");
    cmd->add_option("--out", f->out,
                    "keep pause dumps in DIR, scene k (from 0) in DIR/k_STEM (default: a "
                    "temporary folder, removed)");
    cmd->add_option("-j,--jobs", f->check.jobs,
                    "grade N scenes at once, each in a child process (0: one per core; "
                    "default 1: one after the other in this process); the table is the same")
        ->type_name("N");
    cmd->add_option("--timeout", f->timeout,
                    "stop a scene after SECONDS of wall-clock time: its 'run' row fails, the "
                    "other scenes go on (grades in child processes)")
        ->type_name("SECONDS");
    cmd->add_flag("--keep-going", f->check.keep_going,
                  "grade the scenes that load even when others do not (each bad one fails a "
                  "'load' row; exit code still 2); default: a bad scene stops the check");
    cmd->add_option("--junit", f->junit,
                    "also write a JUnit XML report to FILE: a testsuite per scene, a testcase "
                    "per expectation, an error per scene that did not load or run (implies "
                    "--keep-going)")
        ->type_name("FILE");
    // The child process of -j N / --timeout: one scene, its report to a file.
    cmd->add_option("--worker-result", f->worker_result)->group("");
    cmd->add_option("--worker-index", f->worker_index)->group("");
    return {cmd, [cmd, f](RunMode mode) {
                if (cmd->count("--frames") > 0) f->check.frames = f->frames;
                if (cmd->count("--events") > 0) f->check.events = f->events;
                f->check.dry_run = mode == RunMode::DryRun;
                if (!f->worker_result.empty() && !f->check.dry_run) {
                    if (f->scenes.size() != 1 || f->out.empty()) return kExitBadInput;
                    return runCheckWorker(f->scenes.front(), f->worker_index, f->check.frames,
                                          f->out, f->worker_result, f->check.events);
                }
                for (const std::string& sc : f->scenes) f->check.scenes.emplace_back(sc);
                if (cmd->count("--timeout") > 0) f->check.timeout = f->timeout;
                if (!f->out.empty()) f->check.out_dir = f->out;
                if (!f->junit.empty()) f->check.junit = f->junit;
                f->check.worker_exe = "/proc/self/exe";
                return runCheck(f->check, std::cout, std::cerr);
            }};
}

}  // namespace app
