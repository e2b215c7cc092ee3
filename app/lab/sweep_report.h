// app/lab/sweep_report.h -- what `cdlab sweep` writes: results.csv, the charts, report.md (with the
// float-versus-double section) and the comparison of two traces behind that section.
#pragma once

#include <string>
#include <vector>

#include "engine/scene.h"
#include "sweep.h"

namespace app::sweep {

/// `v` formatted by printf `spec` (default 4 significant digits).
std::string fmt(double v, const char* spec = "%.4g");

/// `s` as one CSV field (quoted when it holds a comma, quote or newline).
std::string csvField(const std::string& s);

/// results.csv: one row per run, deterministic columns and timings.
std::string csvTable(const std::vector<SweepRun>& runs);

/// One chart of the sweep: a column of results.csv against the runs.
struct Chart {
    std::string file;
    std::string title;
    double SweepRun::*field;
    bool log_scale;
    bool timing;
};
/// The charts the sweep draws, in report order.
const std::vector<Chart>& charts();

/// report.md: the table, the reading of it, the float comparison when there was one.
std::string markdownReport(const SweepOptions& options, const engine::Scene& base,
                           double duration, const std::vector<SweepRun>& runs,
                           const SweepRun& reference, const std::vector<FloatRun>& floats);

}  // namespace app::sweep
