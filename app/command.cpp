// app/command.cpp -- see command.h.
#include "command.h"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "exit_codes.h"

namespace app {

namespace {

// Holds what a stream is sent until restored: a dry run speaks only when a check fails.
class HeldStream {
public:
    explicit HeldStream(std::ostream& stream)
        : stream_(stream), saved_(stream.rdbuf(held_.rdbuf())) {}
    ~HeldStream() { stream_.rdbuf(saved_); }
    HeldStream(const HeldStream&) = delete;
    HeldStream& operator=(const HeldStream&) = delete;
    /// Puts the stream back and writes what it held to it.
    void release() {
        stream_.rdbuf(saved_);
        stream_ << held_.str();
    }

private:
    std::ostream& stream_;
    std::ostringstream held_;
    std::streambuf* saved_;
};

int dryRun(const Command& command) {
    HeldStream out(std::cout);
    HeldStream err(std::cerr);
    const int code = command.run(RunMode::DryRun);
    if (code != kExitOk) {
        out.release();
        err.release();
    }
    return code;
}

}  // namespace

int parseAndRun(CLI::App& cli, const std::vector<Command>& commands, int argc, char** argv) {
    bool dry_run = false;
    cli.add_flag("--dry-run", dry_run,
                 "parse and check the command line as the command would (flags, values, scenes "
                 "loaded, named files present), then stop: run nothing, write nothing, print "
                 "nothing and exit 0 when it would run");
    try {
        cli.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = cli.exit(e);
        return code == 0 ? kExitOk : kExitBadInput;
    }
    for (const Command& command : commands) {
        if (!command.cli->parsed()) continue;
        return dry_run ? dryRun(command) : command.run(RunMode::Run);
    }
    return kExitBadInput;
}

int checkInputsExist(const std::vector<NamedInput>& inputs, std::ostream& err) {
    int code = kExitOk;
    for (const NamedInput& input : inputs) {
        std::error_code ec;
        if (std::filesystem::exists(input.path, ec)) continue;
        err << input.flag << " " << input.path << ": no such file or folder\n";
        code = kExitBadInput;
    }
    return code;
}

}  // namespace app
