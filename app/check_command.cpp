// app/check_command.cpp -- `cdlab check`: the flags of grading scenes by their expect: sections
// (lab/check.h).
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "check.h"
#include "command.h"

namespace app {

Command addCheckCommand(CLI::App& cli) {
    struct Flags {
        CheckOptions check;
        std::vector<std::string> scenes;
        int frames = 0;
        std::string out;
    };
    auto f = std::make_shared<Flags>();
    CLI::App* cmd =
        cli.add_subcommand("check",
                           "run scenes headless and grade them against their 'expect:' sections: a "
                           "pass/fail table, exit 0 all pass, 1 any failure, 2 bad input");
    cmd->add_option("scenes", f->scenes, "scene files (YAML)")->required();
    cmd->add_option("--frames", f->frames,
                    "frames to run (overrides expect.frames and the scene)");
    cmd->add_option("--out", f->out,
                    "keep pause dumps in DIR (default: a temporary folder, removed)");
    return {cmd, [cmd, f]() {
                for (const std::string& sc : f->scenes) f->check.scenes.emplace_back(sc);
                if (cmd->count("--frames") > 0) f->check.frames = f->frames;
                if (!f->out.empty()) f->check.out_dir = f->out;
                return runCheck(f->check, std::cout, std::cerr);
            }};
}

}  // namespace app
