// app/command.h -- a cdlab subcommand as main() sees it: each command registers its flags on the
// command line (addXCommand in its own file) and is run if it was the one chosen.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace app {

/// The flags' storage of a command whose options take an optional `json` path: CLI11 fills the
/// string, which becomes the path when given.
template <class Options>
struct OptionsWithJson {
    Options options;
    std::string json;
    const Options& resolved() {
        if (!json.empty()) options.json = json;
        return options;
    }
};

struct Command {
    CLI::App* cli = nullptr;   ///< the subcommand, to ask whether it was parsed
    std::function<int()> run;  ///< runs it with the parsed flags; returns the exit code
};

/// Parses the command line into `cli` and runs the one of `commands` that was chosen. Returns its
/// exit code, 0 after --help, kExitBadInput after CLI11's message for bad flags or no command.
int parseAndRun(CLI::App& cli, const std::vector<Command>& commands, int argc, char** argv);

Command addRunCommand(CLI::App& cli);
Command addCheckCommand(CLI::App& cli);
Command addQueryCommand(CLI::App& cli);
Command addSweepCommand(CLI::App& cli);
/// The `bench` subcommands, registered on `cdlab bench`.
Command addBenchBroadphaseCommand(CLI::App& bench);
Command addBenchCcdCommand(CLI::App& bench);
Command addBenchConvexCommand(CLI::App& bench);
Command addBenchNarrowphaseCommand(CLI::App& bench);

}  // namespace app
