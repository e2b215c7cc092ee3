// tests/app/sweep_test.cpp -- `cdlab sweep`: every combination in a fixed order, AABB broad
// phases agreeing pair for pair, the derived columns consistent, deterministic counts, and bad
// keys and values rejected before anything runs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "sweep_command.h"

namespace app {
namespace {

namespace fs = std::filesystem;

const fs::path kTiny = fs::path(CDLAB_SOURCE_DIR) / "tests/data/tiny.yaml";

fs::path tempDir(const std::string& name) {
    const fs::path d =
        fs::temp_directory_path() / ("cdlab_sweep_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    return d;
}

using Row = std::map<std::string, std::string>;

std::vector<Row> readCsv(const fs::path& file) {
    std::ifstream f(file);
    std::string line;
    std::vector<std::string> header;
    std::vector<Row> rows;
    auto split = [](const std::string& s) {
        std::vector<std::string> out;
        std::stringstream ss(s);
        std::string cell;
        while (std::getline(ss, cell, ',')) out.push_back(cell);
        return out;
    };
    std::getline(f, line);
    header = split(line);
    while (std::getline(f, line)) {
        const std::vector<std::string> cells = split(line);
        EXPECT_EQ(cells.size(), header.size()) << line;
        Row r;
        for (std::size_t i = 0; i < cells.size() && i < header.size(); ++i) r[header[i]] = cells[i];
        rows.push_back(r);
    }
    return rows;
}

SweepOptions tinySweep(const fs::path& out) {
    SweepOptions o;
    o.scene = kTiny;
    o.out_dir = out;
    o.frames = 20;
    o.axes = {parseSweepAxis("broadphase=sap,brute,sphere,tree"),
              parseSweepAxis("time_step=0.02,0.01")};
    return o;
}

TEST(Sweep, EveryCombinationInOrderWithConsistentColumns) {
    const fs::path out = tempDir("all");
    std::ostringstream o, e;
    ASSERT_EQ(runSweep(tinySweep(out), o, e), 0) << e.str();
    const std::vector<Row> rows = readCsv(out / "results.csv");
    ASSERT_EQ(rows.size(), 8u);
    const char* const phases[] = {"sap", "brute", "sphere", "tree"};
    const char* const steps[] = {"0.02", "0.01"};
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const Row& r = rows[i];
        EXPECT_EQ(r.at("run"), std::to_string(i));
        EXPECT_EQ(r.at("broadphase"), phases[i / 2]);
        EXPECT_EQ(r.at("time_step"), steps[i % 2]);
        EXPECT_EQ(r.at("steps"), "19");
        const long flagged = std::stol(r.at("flagged_pairs"));
        const long narrow = std::stol(r.at("narrow_tests"));
        const long colliding = std::stol(r.at("colliding_pairs"));
        EXPECT_EQ(std::stol(r.at("narrow_rejections")), narrow - colliding);
        EXPECT_GE(flagged, colliding);
        EXPECT_GT(colliding, 0) << "the tiny scene has a colliding pair on every step";
        EXPECT_EQ(r.at("energy_drift"), "0") << "no gravity: kinetic energy is kept exactly";
    }
    // Every AABB broad phase flags exactly brute force's pairs, so everything downstream agrees.
    for (std::size_t i : {0u, 1u, 6u, 7u}) {
        const Row& a = rows[i];
        const Row& brute = rows[2 + i % 2];
        for (const char* col :
             {"flagged_pairs", "narrow_tests", "colliding_pairs", "narrow_rejections"}) {
            EXPECT_EQ(a.at(col), brute.at(col)) << "run " << i << " " << col;
        }
        EXPECT_EQ(a.at("state_hash"), brute.at("state_hash")) << "run " << i;
    }
    // Bounding spheres of the box and capsule are looser than their AABBs here.
    EXPECT_GT(std::stol(rows[4].at("narrow_rejections")),
              std::stol(rows[2].at("narrow_rejections")));
    std::ifstream md(out / "report.md");
    std::stringstream text;
    text << md.rdbuf();
    EXPECT_NE(text.str().find("| 5 | sphere | 0.01 |"), std::string::npos) << text.str();
    fs::remove_all(out);
}

TEST(Sweep, CountsAreDeterministic) {
    const fs::path a = tempDir("det_a");
    const fs::path b = tempDir("det_b");
    std::ostringstream o, e;
    ASSERT_EQ(runSweep(tinySweep(a), o, e), 0);
    ASSERT_EQ(runSweep(tinySweep(b), o, e), 0);
    const std::vector<Row> ra = readCsv(a / "results.csv");
    const std::vector<Row> rb = readCsv(b / "results.csv");
    ASSERT_EQ(ra.size(), rb.size());
    for (std::size_t i = 0; i < ra.size(); ++i) {
        for (const auto& [col, value] : ra[i]) {
            if (col.find("ms") != std::string::npos) continue;  // wall clock
            EXPECT_EQ(value, rb[i].at(col)) << "run " << i << " " << col;
        }
    }
    fs::remove_all(a);
    fs::remove_all(b);
}

TEST(Sweep, NoAxesIsOneRun) {
    const fs::path out = tempDir("none");
    SweepOptions opt = tinySweep(out);
    opt.axes.clear();
    std::ostringstream o, e;
    ASSERT_EQ(runSweep(opt, o, e), 0) << e.str();
    EXPECT_EQ(readCsv(out / "results.csv").size(), 1u);
    fs::remove_all(out);
}

TEST(Sweep, BadKeysAndValuesExit2BeforeRunning) {
    const fs::path out = tempDir("bad");
    auto run = [&](std::vector<std::string> axes, std::string& err) {
        SweepOptions opt = tinySweep(out);
        opt.axes.clear();
        for (const std::string& a : axes) opt.axes.push_back(parseSweepAxis(a));
        std::ostringstream o, e;
        const int code = runSweep(opt, o, e);
        err = e.str();
        return code;
    };
    std::string err;
    EXPECT_EQ(run({"integrator=euler"}, err), 2);
    EXPECT_EQ(err,
              "--vary integrator: unknown key 'integrator' (expected one of: broadphase, "
              "time_step, steps_per_frame)\n");
    EXPECT_EQ(run({"broadphase=sap,nope"}, err), 2);
    EXPECT_NE(err.find("--vary broadphase: unknown broad phase 'nope'"), std::string::npos);
    EXPECT_EQ(run({"time_step=0.01,0"}, err), 2);
    EXPECT_EQ(err, "--vary time_step: '0' is not a time step in (0, 1] s\n");
    EXPECT_EQ(run({"time_step=0.01x"}, err), 2);
    EXPECT_EQ(run({"time_step=nan"}, err), 2);
    EXPECT_EQ(run({"steps_per_frame=2,0"}, err), 2);
    EXPECT_EQ(err, "--vary steps_per_frame: '0' is not an integer >= 1\n");
    EXPECT_EQ(run({"time_step=0.01", "time_step=0.02"}, err), 2);
    EXPECT_EQ(err, "--vary time_step: given twice\n");
    EXPECT_FALSE(fs::exists(out)) << "nothing is written for bad input";

    EXPECT_THROW(parseSweepAxis("broadphase"), std::invalid_argument);
    EXPECT_THROW(parseSweepAxis("=sap"), std::invalid_argument);
    EXPECT_THROW(parseSweepAxis("broadphase=sap,,brute"), std::invalid_argument);
    EXPECT_THROW(parseSweepAxis("broadphase="), std::invalid_argument);
}

}  // namespace
}  // namespace app
