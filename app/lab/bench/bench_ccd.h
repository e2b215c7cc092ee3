// app/lab/bench/bench_ccd.h -- `cdlab bench ccd`: the conservative and naive vertex-face / edge-edge CCD
// methods (and Tight-Inclusion when built against it) on the sample queries of Wang et al. 2021 (or any directory in their CSV layout):
// false negatives, false positives and microseconds per query, per method, query set and kind;
// then the per-frame cost of the engine's CCD stage in the tunnelling scenes, off vs on.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace app {

struct BenchCcdOptions {
    /// Query directories: a root of `<set>/<vertex-face|edge-edge>/*.csv`, one set, or one
    /// kind directory. Empty: tests/data/ccd-sample-queries, in the working directory or else in
    /// the source tree the program was built from.
    std::vector<std::filesystem::path> dirs;
    std::optional<std::filesystem::path> json;  ///< also write the table as JSON
    /// conservative | naive | tight-inclusion (when built against it) | all
    std::string method = "all";
    int reps = 1;  ///< runs per query; its time is the fastest

    /// Folder holding tunnel_sphere.yaml and tunnel_bar.yaml: each is run with ccd off and with
    /// ccd conservative_advancement, reporting the step time and the CCD stage's time per frame.
    /// Default "scenes", in the working directory or else in the source tree (skipped, with a
    /// note on stderr, when in neither); an explicitly given folder must hold them.
    std::filesystem::path scenes_dir = "scenes";
    bool scenes_explicit = false;
    bool scenes = true;  ///< false: --no-scenes
};

/// Method names accepted by --method.
std::vector<std::string> ccdBenchMethods();

/// Runs every query once per method, timing each call, and prints one row per method, set and
/// kind plus an "all" row per method and kind, then the conservative method's median, p99 and
/// max over Tight-Inclusion's when both ran. Exit codes: 0 success; 1 the conservative method
/// had a false negative on an exactly represented query, or the JSON could not be written;
/// 2 bad options or a malformed CSV (reported as file:line:col).
int runBenchCcd(const BenchCcdOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app
