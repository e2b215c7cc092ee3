// app/bench_main.cpp -- cdlab-bench, the benches' executable: `cdlab bench SUBCOMMAND ...` runs
// it (main.cpp), so its command line is that of `cdlab bench`. Kept apart from cdlab so that the
// demo builds neither the benches nor the peers they link (Bullet, FCL).
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
constexpr AddCommand kBenchCommands[] = {app::addBenchBroadphaseCommand, app::addBenchCcdCommand,
                                         app::addBenchConvexCommand,
                                         app::addBenchNarrowphaseCommand};

int runCli(int argc, char** argv) {
    CLI::App bench{"cdlab bench -- performance benchmarks: cdlab beside its peers", "cdlab bench"};
    bench.require_subcommand(1);
    std::vector<app::Command> commands;
    for (AddCommand add : kBenchCommands) commands.push_back(add(bench));
    return app::parseAndRun(bench, commands, argc, argv);
}

}  // namespace

// As cdlab's main: whatever escapes a bench ends it with a message and exit 1, never an abort.
int main(int argc, char** argv) {
    // The `cullide` row of bench broadphase renders its occlusion queries.
    render::installOcclusionQueryOracle();
    try {
        return runCli(argc, argv);
    } catch (const std::bad_alloc&) {
        std::cerr << "cdlab bench: out of memory\n";
    } catch (const std::exception& e) {
        std::cerr << "cdlab bench: internal error: " << e.what() << "\n";
    }
    return app::kExitFailure;
}
