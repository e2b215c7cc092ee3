// tests/app/sweep_html_test.cpp -- `cdlab sweep`'s report.html, loaded in headless Chromium: the
// table holds results.csv's rows and sorts numbers as numbers, the charts are drawn, and runs
// that failed are shown as such (a banner and a marked row).
#include "sweep_html.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "browser.h"
#include "cli_run.h"
#include "render/image.h"
#include "sweep.h"

namespace {

namespace fs = std::filesystem;
using namespace cdlab_test;

// The cells' texts of the results table's rows whose class is one of `classes` ("run",
// "failed"), in the DOM's order. (Plain string search: std::regex draws a false
// -Wmaybe-uninitialized from GCC 12 in the sanitizer build.)
std::vector<std::vector<std::string>> tableRows(const std::string& dom,
                                                const std::vector<std::string>& classes) {
    std::vector<std::vector<std::string>> rows;
    const std::string open = "<tr class=\"";
    for (std::size_t at = dom.find(open); at != std::string::npos; at = dom.find(open, at + 1)) {
        const std::size_t begin = at + open.size();
        const std::string cls = dom.substr(begin, dom.find('"', begin) - begin);
        if (std::find(classes.begin(), classes.end(), cls) == classes.end()) continue;
        const std::size_t end = dom.find("</tr>", at);
        rows.emplace_back();
        for (std::size_t td = dom.find("<td", at); td < end; td = dom.find("<td", td + 1)) {
            const std::size_t text = dom.find('>', td) + 1;
            rows.back().push_back(dom.substr(text, dom.find("</td>", text) - text));
        }
    }
    return rows;
}

// The first cell of every run or failed row of the results table, in the DOM's order.
std::vector<std::string> runLabels(const std::string& dom) {
    std::vector<std::string> labels;
    for (const std::vector<std::string>& row : tableRows(dom, {"run", "failed"})) {
        labels.push_back(row.at(0));
    }
    return labels;
}

// The data rows of a CSV file without quoted fields, split at commas.
std::vector<std::vector<std::string>> csvRows(const fs::path& file) {
    std::istringstream lines(slurp(file));
    std::vector<std::vector<std::string>> rows;
    std::string line;
    std::getline(lines, line);
    while (std::getline(lines, line)) {
        std::istringstream fields(line);
        rows.emplace_back();
        for (std::string f; std::getline(fields, f, ',');) rows.back().push_back(f);
    }
    return rows;
}

// Lines of a file but the first (a CSV's data rows).
int dataLines(const fs::path& file) {
    std::istringstream lines(slurp(file));
    int n = -1;
    for (std::string line; std::getline(lines, line);) ++n;
    return n;
}

}  // namespace

// Three time steps over the same 0.1 s: 2, 10 and 50 steps. Sorted by steps, descending, the
// rows go 50, 10, 2 (as text they would go 50, 2, 10); every chart of report.md is drawn.
TEST(SweepHtml, TableHoldsTheCsvRowsSortsNumbersAndChartsAreDrawn) {
    ASSERT_FALSE(chromiumBinary().empty()) << kNoChromium;
    app::SweepOptions o;
    o.scene = fs::path(CDLAB_SOURCE_DIR) / "tests/data/tunnel_small.yaml";
    o.vary = {"world.time_step=0.05,0.01,0.002"};
    o.repeat = 1;
    const fs::path work = tempDir("cdlab_html_", "sweep");
    o.out_dir = work / "out";
    std::ostringstream out, err;
    ASSERT_EQ(app::runSweep(o, out, err), 0) << err.str();
    const fs::path page = o.out_dir / "report.html";
    ASSERT_TRUE(fs::exists(page)) << out.str();

    const std::string dom = runChromium(page, "?sort=steps&order=desc", "--dump-dom", work);
    ASSERT_NE(dom.find("<body data-rendered=\"1\""), std::string::npos)
        << "the page's script did not finish: " << slurp(work / "chromium.log");
    EXPECT_EQ(int(runLabels(dom).size()), dataLines(o.out_dir / "results.csv"));
    EXPECT_EQ(runLabels(dom),
              (std::vector<std::string>{"world.time_step=0.002", "world.time_step=0.01",
                                        "world.time_step=0.05"}));
    EXPECT_NE(dom.find("aria-sort=\"descending\">steps</th>"), std::string::npos);
    // Cell for cell the CSV's rows, in the sorted order (the CSV has them as --vary gave them).
    const std::vector<std::vector<std::string>> csv = csvRows(o.out_dir / "results.csv");
    ASSERT_EQ(csv.size(), 3u);
    EXPECT_EQ(tableRows(dom, {"run"}),
              (std::vector<std::vector<std::string>>{csv[2], csv[1], csv[0]}));
    EXPECT_EQ(dom.find("id=\"failures\""), std::string::npos);
    for (int chart = 0; chart < 5; ++chart) {
        EXPECT_EQ(attribute(startTag(dom, "chart-" + std::to_string(chart)), "data-rendered"), "1")
            << chart;
    }

    const fs::path shot = work / "sweep.png";
    runChromium(page, "", "--screenshot=" + shot.string(), work);
    ASSERT_TRUE(fs::exists(shot)) << slurp(work / "chromium.log");
    const std::string rect = attribute(startTag(dom, "chart-0"), "data-rect");
    const render::Image image = render::readPng(shot);
    EXPECT_GT(pixelsInRect(image, rect, {0x48, 0x78, 0xd0}), 500) << rect;  // the runs' bars
    EXPECT_GT(pixelsInRect(image, rect, {0xee, 0x85, 0x4a}), 100) << rect;  // the reference's
    fs::remove_all(work);
}

// A collected sweep whose third job failed: a banner names it with its reason, its row is marked
// failed, and it stays below the runs whichever way the table is sorted.
TEST(SweepHtml, FailedRunIsShownByABannerAndAMarkedRow) {
    ASSERT_FALSE(chromiumBinary().empty()) << kNoChromium;
    app::SweepOptions o;
    o.scene = "scene.yaml";
    o.vary = {"broadphase=sap,brute,hgrid"};
    std::vector<app::SweepRun> runs(2);
    runs[0].label = "broadphase=sap";
    runs[0].flagged = 3;
    runs[1].label = "broadphase=brute";
    runs[1].flagged = 5;
    app::SweepRun reference;
    reference.label = "reference";
    const std::vector<app::SweepFailure> failures{
        {"broadphase=hgrid", "job 3 exited with status 137 <killed>"}};
    const fs::path work = tempDir("cdlab_html_", "sweep_failed");
    app::writeSweepHtml(work / "report.html", o, runs, reference, {}, failures);

    const std::string dom = runChromium(work / "report.html", "?sort=run", "--dump-dom", work);
    ASSERT_NE(dom.find("<body data-rendered=\"1\""), std::string::npos)
        << "the page's script did not finish: " << slurp(work / "chromium.log");
    const std::string banner = startTag(dom, "failures");
    ASSERT_NE(banner, "");
    EXPECT_EQ(banner.find("hidden"), std::string::npos);
    EXPECT_NE(dom.find("1 of 3 runs failed or are missing"), std::string::npos);
    EXPECT_NE(dom.find("broadphase=hgrid: job 3 exited with status 137 &lt;killed&gt;"),
              std::string::npos);
    EXPECT_NE(dom.find("failed: job 3 exited with status 137 &lt;killed&gt;</td>"),
              std::string::npos);
    EXPECT_EQ(runLabels(dom),
              (std::vector<std::string>{"broadphase=brute", "broadphase=sap", "broadphase=hgrid"}));
    fs::remove_all(work);
}
