// app/command.cpp -- see command.h.
#include "command.h"

#include <CLI/CLI.hpp>

#include "exit_codes.h"

namespace app {

int parseAndRun(CLI::App& cli, const std::vector<Command>& commands, int argc, char** argv) {
    try {
        cli.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = cli.exit(e);
        return code == 0 ? kExitOk : kExitBadInput;
    }
    for (const Command& command : commands) {
        if (command.cli->parsed()) return command.run();
    }
    return kExitBadInput;
}

}  // namespace app
