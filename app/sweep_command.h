// app/sweep_command.h -- `cdlab sweep`: one scene under every combination of settings asked,
// headless, into results.csv (time per frame and per stage, pairs, BV tests) and report.md.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace app {

/// One `--vary KEY=V1,V2,...`: KEY is broadphase, time_step or steps_per_frame.
struct SweepAxis {
    std::string key;
    std::vector<std::string> values;  ///< as written; validated by runSweep
};

struct SweepOptions {
    std::filesystem::path scene;
    std::vector<SweepAxis> axes;
    std::filesystem::path out_dir;
    std::optional<int> frames;  ///< overrides the scene's frame count
};

/// Parses "KEY=V1,V2,..." (no validation of the values). Throws std::invalid_argument with the
/// message "--vary ARG: what is wrong" on a missing '=', an empty key or an empty value.
SweepAxis parseSweepAxis(const std::string& arg);

/// Runs every combination (the first axis varies slowest), writes OUT/results.csv and
/// OUT/report.md. Exit codes: 0 written, 1 output failure, 2 bad input (scene, key, value).
/// Everything but the time columns is deterministic: same scene and axes -> same numbers.
int runSweep(const SweepOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app
