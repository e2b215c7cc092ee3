// app/lab/sweep_html.cpp -- see sweep_html.h. The table is results.csv itself (csvTable() parsed
// back into cells), so the page and the file cannot disagree; the charts are the values
// sweep::charts() draws into the PNGs, embedded as JSON for app/lab/page/sweep_page.js.
#include "sweep_html.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "html_page.h"
#include "output_files.h"
#include "page_assets.h"
#include "sweep_report.h"

namespace app {

namespace {

// RFC 4180 records of `text` (quoted fields may hold commas, quotes and newlines).
std::vector<std::vector<std::string>> parseCsv(const std::string& text) {
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> row;
    std::string field;
    bool quoted = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (quoted) {
            if (c != '"') {
                field += c;
            } else if (i + 1 < text.size() && text[i + 1] == '"') {
                field += '"';
                ++i;
            } else {
                quoted = false;
            }
        } else if (c == '"') {
            quoted = true;
        } else if (c == ',') {
            row.push_back(std::move(field));
            field.clear();
        } else if (c == '\n') {
            row.push_back(std::move(field));
            field.clear();
            rows.push_back(std::move(row));
            row.clear();
        } else {
            field += c;
        }
    }
    if (!field.empty() || !row.empty()) {
        row.push_back(std::move(field));
        rows.push_back(std::move(row));
    }
    return rows;
}

// A number as JSON can hold it: NaN and infinities (no bar) become null.
nlohmann::ordered_json number(double v) {
    return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json();
}

// The charts' data: title, log scale, and one bar per run, the reference last.
nlohmann::ordered_json chartsJson(const SweepOptions& options, const std::vector<SweepRun>& runs,
                                  const SweepRun& reference, const std::vector<FloatRun>& floats) {
    nlohmann::ordered_json charts = nlohmann::ordered_json::array();
    for (const sweep::Chart& c : sweep::charts()) {
        if (c.timing && !options.report_timing) continue;
        nlohmann::ordered_json labels = nlohmann::ordered_json::array();
        nlohmann::ordered_json values = nlohmann::ordered_json::array();
        for (const SweepRun& r : runs) {
            labels.push_back(r.label);
            values.push_back(number(c.value(r)));
        }
        labels.push_back("reference");
        values.push_back(number(c.value(reference)));
        charts.push_back({{"file", c.file},
                          {"title", c.title},
                          {"log_scale", c.log_scale},
                          {"labels", labels},
                          {"values", values},
                          {"highlight_last", true}});
    }
    if (!floats.empty()) {
        nlohmann::ordered_json labels = nlohmann::ordered_json::array();
        nlohmann::ordered_json values = nlohmann::ordered_json::array();
        for (const FloatRun& f : floats) {
            labels.push_back(f.label);
            values.push_back(number(f.comparison.max_position_deviation));
        }
        charts.push_back({{"file", "float_deviation.png"},
                          {"title", "float vs double: max position deviation (m, log scale)"},
                          {"log_scale", true},
                          {"labels", labels},
                          {"values", values},
                          {"highlight_last", false}});
    }
    return charts;
}

// The banner over the page when runs are missing: every one named with its reason.
std::string failureBanner(const std::vector<SweepFailure>& failures, std::size_t runs) {
    if (failures.empty()) return "";
    std::string out = "<div class=\"banner\" id=\"failures\" role=\"alert\"><strong>" +
                      std::to_string(failures.size()) + " of " +
                      std::to_string(runs + failures.size()) +
                      " runs failed or are missing: the charts and the table show only the "
                      "others.</strong>\n<ul>\n";
    for (const SweepFailure& f : failures) {
        out += "<li>" + html::escape(f.label) + ": " + html::escape(f.reason) + "</li>\n";
    }
    return out + "</ul></div>\n";
}

// results.csv as a table, then a row per failure.
std::string resultsTable(const std::vector<SweepRun>& runs,
                         const std::vector<SweepFailure>& failures) {
    const std::vector<std::vector<std::string>> csv = parseCsv(sweep::csvTable(runs));
    const std::vector<std::string>& header = csv.front();
    std::string out =
        "<div class=\"table-scroll\"><table class=\"results\" id=\"results\">\n"
        "<thead><tr>";
    for (const std::string& h : header) out += "<th>" + html::escape(h) + "</th>";
    out += "</tr></thead>\n<tbody>\n";
    for (std::size_t i = 1; i < csv.size(); ++i) {
        out += "<tr class=\"run\">";
        for (const std::string& cell : csv[i]) out += "<td>" + html::escape(cell) + "</td>";
        out += "</tr>\n";
    }
    for (const SweepFailure& f : failures) {
        out += "<tr class=\"failed\" data-failed=\"1\"><td>" + html::escape(f.label) +
               "</td><td colspan=\"" + std::to_string(header.size() - 1) +
               "\">failed: " + html::escape(f.reason) + "</td></tr>\n";
    }
    return out + "</tbody></table></div>\n";
}

}  // namespace

std::string sweepPageHtml(const SweepOptions& options, const std::vector<SweepRun>& runs,
                          const SweepRun& reference, const std::vector<FloatRun>& floats,
                          const std::vector<SweepFailure>& failures) {
    const std::string scene = options.scene.filename().string();
    std::string out = html::pageStart("cdlab sweep: " + scene);
    out +=
        "<header>\n<h1>Sweep of " + html::escape(scene) + "</h1>\n<p class=\"meta\">" +
        std::to_string(runs.size()) +
        " runs, each measured against the reference run (the last bar of each chart) "
        "&middot; <a href=\"report.md\">report.md</a> (the reading) &middot; "
        "<a href=\"results.csv\">results.csv</a></p>\n</header>\n<main>\n";
    out += failureBanner(failures, runs.size());
    out += "<section id=\"charts\">\n<h2>Charts</h2>\n</section>\n";
    out +=
        "<section id=\"table\">\n<h2>Results</h2>\n<p class=\"hint\">The rows of results.csv; "
        "click a column's header to sort by it, again to reverse.</p>\n";
    out += resultsTable(runs, failures);
    out += "</section>\n</main>\n";
    const nlohmann::ordered_json data = {{"charts", chartsJson(options, runs, reference, floats)}};
    out += html::jsonScript("sweep-data",
                            data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
    out += html::pageEnd(sweepPageJs());
    return out;
}

void writeSweepHtml(const std::filesystem::path& file, const SweepOptions& options,
                    const std::vector<SweepRun>& runs, const SweepRun& reference,
                    const std::vector<FloatRun>& floats,
                    const std::vector<SweepFailure>& failures) {
    writeTextAtomically(file, sweepPageHtml(options, runs, reference, floats, failures));
}

}  // namespace app
