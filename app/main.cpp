// app/main.cpp -- the cdlab command line: the table of commands (each registers its own flags,
// command.h), parsing, and the last line of defence against anything a command throws.
// `cdlab bench ...` and `cdlab --dry-run bench ...` are handed to cdlab-bench, the executable
// built beside this one (bench_main.cpp), which parses them.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstring>
#include <exception>
#include <filesystem>
#include <iostream>
#include <new>
#include <string>
#include <system_error>
#include <vector>

#include "command.h"
#include "exit_codes.h"
#include "render/occlusion_oracle.h"

namespace {

using AddCommand = app::Command (*)(CLI::App&);
constexpr AddCommand kCommands[] = {app::addRunCommand,   app::addCheckCommand,
                                    app::addQueryCommand, app::addSweepCommand,
                                    app::addServeCommand, app::addReplayCommand};

constexpr const char* kBenchExecutable = "cdlab-bench";

// Replaces this process by cdlab-bench from cdlab's own folder, given the arguments that follow
// `bench` (`--dry-run` first when it came before `bench`); returns only when that cannot be
// done, with the exit code, after saying why.
int runBench(int argc, char** argv, bool dry_run) {
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    const std::filesystem::path bench =
        (ec ? std::filesystem::path(argv[0]) : self).parent_path() / kBenchExecutable;
    if (::access(bench.c_str(), X_OK) != 0) {
        std::cerr << "cdlab bench: " << bench.string()
                  << " is not built: the benches are built apart from cdlab (they link Bullet "
                     "and FCL); build them with `cmake --build build --target cdlab-bench` "
                     "(Debian packages libbullet-dev and libfcl-dev for the peers) or with "
                     "`bash .ci/bootstrap test`\n";
        return app::kExitFailure;
    }
    std::vector<char*> args{const_cast<char*>(bench.c_str())};
    static char dry_run_flag[] = "--dry-run";
    if (dry_run) args.push_back(dry_run_flag);
    for (int i = dry_run ? 3 : 2; i < argc; ++i) args.push_back(argv[i]);
    args.push_back(nullptr);
    ::execv(bench.c_str(), args.data());
    std::cerr << "cdlab bench: cannot run " << bench.string() << ": " << std::strerror(errno)
              << "\n";
    return app::kExitFailure;
}

int runCli(int argc, char** argv) {
    CLI::App cli{
        "cdlab -- collision-detection lab: run rigid-body scenes headless and render "
        "every bounding volume coloured by its overlap state"};
    cli.require_subcommand(1);
    std::vector<app::Command> commands;
    for (AddCommand add : kCommands) commands.push_back(add(cli));
    // Listed in the help only: `cdlab bench ...` never reaches this parser (main).
    cli.add_subcommand("bench",
                       "performance benchmarks beside the peers: broadphase, ccd, convex, "
                       "narrowphase (cdlab-bench, built with the tests)");
    // A first word that is no command is named, with the commands there are (CLI11 would say
    // only that a subcommand is required); so is a missing command.
    std::string names;
    bool known = false;
    for (const CLI::App* sub : cli.get_subcommands({})) {
        names += (names.empty() ? "" : ", ") + sub->get_name();
        known = known || (argc > 1 && sub->get_name() == argv[1]);
    }
    if (argc < 2 || (argv[1][0] != '-' && !known)) {
        if (argc < 2) {
            std::cerr << "cdlab: no command given";
        } else {
            std::cerr << "cdlab: unknown command '" << argv[1] << "'";
        }
        std::cerr << " (expected one of: " << names << "); cdlab --help says what each does\n";
        return app::kExitBadInput;
    }
    return app::parseAndRun(cli, commands, argc, argv);
}

}  // namespace

// Whatever escapes a command ends the run with a message and exit 1, never an abort: running out
// of memory (a scene past what this machine holds) is reported as such.
int main(int argc, char** argv) {
    // The composition root hands render's occlusion queries to the `cullide` broad phase.
    render::installOcclusionQueryOracle();
    try {
        if (argc > 1 && std::string(argv[1]) == "bench") return runBench(argc, argv, false);
        if (argc > 2 && std::string(argv[1]) == "--dry-run" && std::string(argv[2]) == "bench") {
            return runBench(argc, argv, true);
        }
        return runCli(argc, argv);
    } catch (const std::bad_alloc&) {
        std::cerr << "cdlab: out of memory (the scene or request needs more than this machine "
                     "can allocate)\n";
    } catch (const std::exception& e) {
        std::cerr << "cdlab: internal error: " << e.what() << "\n";
    }
    return app::kExitFailure;
}
