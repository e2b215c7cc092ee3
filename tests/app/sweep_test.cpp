// cdlab sweep: the Cartesian product of --vary, the reference run, missed contacts when the
// time step lets a fast sphere tunnel, identical answers across broad phases, bad input.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "render/image.h"
#include "sweep_command.h"

namespace {

namespace fs = std::filesystem;

const fs::path kScene = fs::path(CDLAB_SOURCE_DIR) / "tests/data/tunnel_small.yaml";

fs::path tempDir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() /
                       ("cdlab_sweep_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    return d;
}

std::string slurp(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

// results.csv as one map per row, column name -> text (labels here have no commas).
std::vector<std::map<std::string, std::string>> readCsv(const fs::path& file) {
    std::ifstream f(file);
    std::string line;
    std::vector<std::string> header;
    std::vector<std::map<std::string, std::string>> rows;
    while (std::getline(f, line)) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ',')) cells.push_back(cell);
        if (header.empty()) {
            header = cells;
            continue;
        }
        std::map<std::string, std::string> row;
        for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) {
            row[header[i]] = cells[i];
        }
        rows.push_back(row);
    }
    return rows;
}

struct Outcome {
    int code;
    std::string out, err;
};

Outcome sweep(app::SweepOptions options) {
    std::ostringstream out, err;
    const int code = app::runSweep(options, out, err);
    return {code, out.str(), err.str()};
}

TEST(Sweep, TimeStepThatTunnelsMissesTheContactAndBroadPhasesAgree) {
    app::SweepOptions o;
    o.scene = kScene;
    o.vary = {"broadphase=brute,sap,hgrid,tree", "world.time_step=0.05,0.005"};
    o.out_dir = tempDir("tunnel");
    const Outcome r = sweep(o);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = readCsv(o.out_dir / "results.csv");
    ASSERT_EQ(rows.size(), 8u);  // 4 broad phases x 2 time steps, last --vary fastest
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto& row = rows[i];
        const bool coarse = i % 2 == 0;
        const std::vector<std::string> methods{"brute", "sap", "hgrid", "tree"};
        const std::string label = "broadphase=" + methods[i / 2] +
                                  " world.time_step=" + (coarse ? "0.05" : "0.005");
        EXPECT_EQ(row.at("run"), label);
        // 0.1 s simulated whatever the step: 2 or 20 steps.
        EXPECT_EQ(row.at("steps"), coarse ? "2" : "20");
        // The reference (dt 0.001) confirms bullet-plate; at dt 0.05 the bullet is sampled at
        // x = -0.5 and 0.5 only, so the pair is never confirmed.
        EXPECT_EQ(row.at("missed_pairs"), coarse ? "1" : "0") << row.at("run");
        EXPECT_EQ(row.at("pairs_confirmed_total"), coarse ? "0" : "1");
        EXPECT_EQ(row.at("extra_pairs"), "0");
        if (!coarse) {
            // First contact: reference at x = -0.1 (t = 0.07 s); dt 0.005 reaches x = -0.1 at
            // step 14 too: the error is at most a step.
            EXPECT_LE(std::stod(row.at("max_first_contact_error_s")), 0.005 + 1e-12);
        }
        // Every broad phase ends in the same state as brute force with the same step.
        EXPECT_EQ(row.at("state_hash"), rows[i % 2].at("state_hash"));
    }
    const std::string report = slurp(o.out_dir / "report.md");
    EXPECT_NE(report.find("| broadphase=hgrid world.time_step=0.05 |"), std::string::npos);
    EXPECT_NE(report.find("Most contacts missed"), std::string::npos);
    const render::Image chart = render::readPng(o.out_dir / "broad_false_positives.png");
    EXPECT_GT(chart.width, 0);
    fs::remove_all(o.out_dir);
}

TEST(Sweep, ReportWithoutTimingIsBitIdentical) {
    app::SweepOptions o;
    o.scene = kScene;
    o.vary = {"world.time_step=0.02,0.01"};
    o.report_timing = false;
    o.out_dir = tempDir("det1");
    ASSERT_EQ(sweep(o).code, 0);
    const std::string first = slurp(o.out_dir / "report.md");
    fs::remove_all(o.out_dir);
    ASSERT_EQ(sweep(o).code, 0);
    EXPECT_EQ(slurp(o.out_dir / "report.md"), first);
    EXPECT_EQ(first.find("ms/step"), std::string::npos);
    fs::remove_all(o.out_dir);
}

TEST(Sweep, ParseVaryKeepsBracketedValuesWhole) {
    std::string key, error;
    std::vector<std::string> values;
    ASSERT_TRUE(app::parseVary("world.gravity=[0, -9.81, 0],[0,0,0]", key, values, error));
    EXPECT_EQ(key, "world.gravity");
    EXPECT_EQ(values, (std::vector<std::string>{"[0, -9.81, 0]", "[0,0,0]"}));
    EXPECT_FALSE(app::parseVary("broadphase", key, values, error));
    EXPECT_FALSE(app::parseVary("broadphase=sap,,hgrid", key, values, error));
    EXPECT_FALSE(app::parseVary("world.gravity=[0,0", key, values, error));
}

TEST(Sweep, BadInputIsExitTwoWithTheKeyNamed) {
    app::SweepOptions o;
    o.scene = kScene;
    o.out_dir = tempDir("bad");
    o.vary = {"broadphase=sap,nonesuch"};
    Outcome r = sweep(o);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("broadphase=nonesuch"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("unknown broad phase"), std::string::npos) << r.err;

    o.vary = {"world.time_stepp=0.1"};
    r = sweep(o);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("time_stepp"), std::string::npos) << r.err;

    o.vary = {"world.time_step=-1"};
    r = sweep(o);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("world.time_step"), std::string::npos) << r.err;

    o.vary = {"bodies.7.radius=1"};
    r = sweep(o);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("not an index"), std::string::npos) << r.err;

    o.vary = {};
    o.duration = -1.0;
    r = sweep(o);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--duration"), std::string::npos) << r.err;
    // Nothing was written for a rejected sweep.
    EXPECT_FALSE(fs::exists(o.out_dir / "report.md"));
    fs::remove_all(o.out_dir);
}

}  // namespace
