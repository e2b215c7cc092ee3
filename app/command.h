// app/command.h -- a cdlab subcommand as main() sees it: each command registers its flags on the
// command line (addXCommand in its own file) and is run if it was the one chosen.
#pragma once

#include <functional>
#include <iosfwd>
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

/// What a command's run function is asked to do with its parsed flags.
enum class RunMode {
    Run,     ///< the command itself
    DryRun,  ///< `--dry-run`: every check a run makes of its flags and inputs (scenes loaded,
             ///< named files present), then stop before anything runs or is written
};

struct Command {
    CLI::App* cli = nullptr;          ///< the subcommand, to ask whether it was parsed
    std::function<int(RunMode)> run;  ///< runs it with the parsed flags; returns the exit code
};

/// Registers `--dry-run` on `cli` (the top-level parser of cdlab and of cdlab-bench), parses the
/// command line into it and runs the one of `commands` that was chosen. Returns its exit code,
/// 0 after --help, kExitBadInput after CLI11's message for bad flags or no command. Under
/// --dry-run the command's output is held back and shown only when a check fails, so a line that
/// would run prints nothing and exits 0.
int parseAndRun(CLI::App& cli, const std::vector<Command>& commands, int argc, char** argv);

/// Under --dry-run: kExitOk when every one of `inputs` (files or folders a command reads,
/// relative to the working directory) exists, else kExitBadInput after `FLAG PATH: no such file
/// or folder` on `err` for each one missing. `flag` names the option (or positional) given.
struct NamedInput {
    std::string flag;
    std::string path;
};
int checkInputsExist(const std::vector<NamedInput>& inputs, std::ostream& err);

Command addRunCommand(CLI::App& cli);
Command addCheckCommand(CLI::App& cli);
Command addQueryCommand(CLI::App& cli);
Command addSweepCommand(CLI::App& cli);
Command addServeCommand(CLI::App& cli);
Command addReplayCommand(CLI::App& cli);
/// The `bench` subcommands, registered on `cdlab bench`.
Command addBenchBroadphaseCommand(CLI::App& bench);
Command addBenchCcdCommand(CLI::App& bench);
Command addBenchConvexCommand(CLI::App& bench);
Command addBenchNarrowphaseCommand(CLI::App& bench);

}  // namespace app
