// app/main.cpp -- the cdlab command line: the table of commands (each registers its own flags,
// command.h), parsing, and the last line of defence against anything a command throws.
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <new>
#include <vector>

#include "command.h"
#include "exit_codes.h"
#include "render/occlusion_oracle.h"

namespace {

using AddCommand = app::Command (*)(CLI::App&);
constexpr AddCommand kCommands[] = {app::addRunCommand, app::addCheckCommand,
                                    app::addQueryCommand, app::addSweepCommand};
constexpr AddCommand kBenchCommands[] = {app::addBenchBroadphaseCommand, app::addBenchCcdCommand,
                                         app::addBenchConvexCommand,
                                         app::addBenchNarrowphaseCommand};

int runCli(int argc, char** argv) {
    CLI::App cli{
        "cdlab -- collision-detection lab: run rigid-body scenes headless and render "
        "every bounding volume coloured by its overlap state"};
    cli.require_subcommand(1);
    std::vector<app::Command> commands;
    for (AddCommand add : kCommands) commands.push_back(add(cli));
    CLI::App* bench = cli.add_subcommand("bench", "performance benchmarks");
    bench->require_subcommand(1);
    for (AddCommand add : kBenchCommands) commands.push_back(add(*bench));

    try {
        cli.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = cli.exit(e);
        return code == 0 ? app::kExitOk : app::kExitBadInput;
    }
    for (const app::Command& command : commands) {
        if (command.cli->parsed()) return command.run();
    }
    return app::kExitBadInput;
}

}  // namespace

// Whatever escapes a command ends the run with a message and exit 1, never an abort: running out
// of memory (a scene past what this machine holds) is reported as such.
int main(int argc, char** argv) {
    // The composition root hands render's occlusion queries to the `cullide` broad phase.
    render::installOcclusionQueryOracle();
    try {
        return runCli(argc, argv);
    } catch (const std::bad_alloc&) {
        std::cerr << "cdlab: out of memory (the scene or request needs more than this machine "
                     "can allocate)\n";
    } catch (const std::exception& e) {
        std::cerr << "cdlab: internal error: " << e.what() << "\n";
    }
    return app::kExitFailure;
}
