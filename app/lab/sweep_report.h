// app/lab/sweep_report.h -- what `cdlab sweep` writes: results.csv, the charts, report.md (with the
// float-versus-double section) and the comparison of two traces behind that section.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "engine/scene.h"
#include "sweep.h"

namespace app::sweep {

/// `v` formatted by printf `spec` (default 4 significant digits).
std::string fmt(double v, const char* spec = "%.4g");

/// `s` as one CSV field (quoted when it holds a comma, quote or newline).
std::string csvField(const std::string& s);

/// results.csv: one row per run, deterministic columns and timings (median, min and max over
/// the repeats of each timed column, the clock named in a column).
std::string csvTable(const std::vector<SweepRun>& runs);

/// One chart of the sweep: a column of results.csv against the runs (timed columns: medians).
struct Chart {
    std::string file;
    std::string title;
    double (*value)(const SweepRun&);
    bool log_scale;
    bool timing;
};
/// The charts the sweep draws, in report order.
const std::vector<Chart>& charts();

/// Which of several timed figures (lower is better) is measurably the lowest.
struct Ranking {
    enum class State {
        Empty,         ///< no figure
        Only,          ///< one figure: nothing to compare
        NoSpread,      ///< one repeat each: no spread to compare the differences with
        WithinSpread,  ///< the lowest median's range overlaps another's: no winner
        Separated,     ///< `best`'s whole range lies below every other range: the winner
    };
    State state = State::Empty;
    std::size_t best = 0;  ///< index of the lowest median (ties: the first)
    /// WithinSpread: indices whose range overlaps best's, best first, then by median.
    std::vector<std::size_t> overlapping;
};

/// Ranks `values` (timed over `repeats` repeats each) by median and names the lowest only when
/// the difference exceeds the spread: its max is below every other value's min, so its slowest
/// repeat beat every other run's fastest. A pure function of the numbers given.
Ranking rankLowest(const std::vector<Timed>& values, int repeats);

/// report.md: the table, the reading of it, the float comparison when there was one, and a
/// section naming every run of a plan that left no result (`failures`).
std::string markdownReport(const SweepOptions& options, const engine::Scene& base,
                           double duration, const std::vector<SweepRun>& runs,
                           const SweepRun& reference, const std::vector<FloatRun>& floats,
                           const std::vector<SweepFailure>& failures = {});

/// Writes the sweep's outputs into `out_dir` (which exists): the charts, results.csv,
/// report.md and report.html (sweep_html.h), each file complete or absent. Throws on an output failure.
void writeSweepOutputs(const SweepOptions& options, const engine::Scene& base, double duration,
                       const std::vector<SweepRun>& runs, const SweepRun& reference,
                       const std::vector<FloatRun>& floats,
                       const std::vector<SweepFailure>& failures,
                       const std::filesystem::path& out_dir);

/// Removes the outputs an earlier sweep left in `out_dir` (results.csv, report.md,
/// report.html, charts, float comparison), so none outlives a rerun that fails before writing its own.
void removeSweepOutputs(const std::filesystem::path& out_dir);

}  // namespace app::sweep
