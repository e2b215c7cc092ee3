// tests/app/cli_run.h -- shared by the end-to-end tests of the command line: run the cdlab
// binary (CDLAB_BINARY) with its output captured, read a file whole, make a per-process
// temporary folder.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

namespace cdlab_test {

/// Exit code (-1 when cdlab did not exit normally) and the captured streams of one run.
struct CliResult {
    int exit_code = -1;
    std::string out;
    std::string err;
};

/// The whole file (empty when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

/// An empty folder `prefix + name + "_" + pid` under the system's temporary directory.
inline std::filesystem::path tempDir(const std::string& prefix, const std::string& name) {
    const std::filesystem::path d =
        std::filesystem::temp_directory_path() / (prefix + name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
    return d;
}

/// Runs `cd CWD && ENV cdlab ARGS` through the shell, stdout and stderr to files in `work`,
/// stdin from /dev/null. `env` is prepended to the command ("PATH=/x" sets it for cdlab only).
inline CliResult runCdlab(const std::string& args, const std::filesystem::path& work,
                          const std::string& env = "",
                          const std::filesystem::path& cwd = CDLAB_SOURCE_DIR) {
    const std::filesystem::path out = work / "stdout.txt";
    const std::filesystem::path err = work / "stderr.txt";
    const std::string cmd = "cd " + cwd.string() + " && " + env + " " + CDLAB_BINARY + " " + args +
                            " > " + out.string() + " 2> " + err.string() + " < /dev/null";
    const int status = std::system(cmd.c_str());
    CliResult r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

/// The smallest scene the command-line tests run (relative to the repository).
inline const std::string kTiny = "tests/data/tiny.yaml";

/// True when ffprobe (Debian package ffmpeg) can be run.
inline bool haveFfprobe() { return std::system("ffprobe -version > /dev/null 2>&1") == 0; }

/// ffprobe's key=value lines for the first video stream, frames decoded and counted.
inline std::map<std::string, std::string> probeVideo(const std::filesystem::path& video,
                                                     const std::filesystem::path& work) {
    const std::filesystem::path out = work / "ffprobe.txt";
    const std::string cmd =
        "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
        "stream=codec_name,pix_fmt,width,height,nb_read_frames "
        "-of default=noprint_wrappers=1 " +
        video.string() + " > " + out.string() + " 2>&1";
    std::map<std::string, std::string> fields;
    if (std::system(cmd.c_str()) != 0) {
        fields["error"] = slurp(out);
        return fields;
    }
    std::istringstream lines(slurp(out));
    for (std::string line; std::getline(lines, line);) {
        const std::size_t eq = line.find('=');
        if (eq != std::string::npos) fields[line.substr(0, eq)] = line.substr(eq + 1);
    }
    return fields;
}

}  // namespace cdlab_test
