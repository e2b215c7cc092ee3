// app/lab/sweep_html.h -- a sweep's report.html: the figures of the PNG charts drawn by Chart.js
// and results.csv as a table sortable by any column, with every run that failed or never
// reported shown as such. One self-contained file beside report.md (html_page.h).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "sweep.h"

namespace app {

/// report.html's text: a banner naming every failure (none: no banner), the charts of
/// sweep::charts() (timed ones only with options.report_timing; `reference` last, in the
/// accent colour) and float_deviation's figures when `floats` is not empty, and a table with
/// results.csv's header and one row per run in its order, then one row per failure marked
/// failed. Clicking a header sorts by that column (numbers numerically); `?sort=COLUMN` and
/// `&order=desc` in the page's URL sort on opening.
std::string sweepPageHtml(const SweepOptions& options, const std::vector<SweepRun>& runs,
                          const SweepRun& reference, const std::vector<FloatRun>& floats,
                          const std::vector<SweepFailure>& failures);

/// Writes sweepPageHtml() to `file` atomically. Throws render::RenderError naming the file.
void writeSweepHtml(const std::filesystem::path& file, const SweepOptions& options,
                    const std::vector<SweepRun>& runs, const SweepRun& reference,
                    const std::vector<FloatRun>& floats, const std::vector<SweepFailure>& failures);

}  // namespace app
