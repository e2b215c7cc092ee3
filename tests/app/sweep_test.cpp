// cdlab sweep: the Cartesian product of --vary, the reference run, missed contacts when the
// time step lets a fast sphere tunnel, identical answers across broad phases, bad input.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.h"
#include "render/image.h"
#include "sweep.h"
#include "sweep_measure.h"
#include "sweep_report.h"

namespace {

// GCC defines __SANITIZE_ADDRESS__; clang 14 answers __has_feature(address_sanitizer).
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

namespace fs = std::filesystem;
using cdlab_test::slurp;

const fs::path kScene = fs::path(CDLAB_SOURCE_DIR) / "tests/data/tunnel_small.yaml";

fs::path sweepDir(const std::string& name) { return cdlab_test::tempDir("cdlab_sweep_", name); }

// A CSV file as one map per row, column name -> text.
std::vector<std::map<std::string, std::string>> readCsv(const fs::path& file) {
    std::ifstream f(file);
    std::string line;
    std::vector<std::string> header;
    std::vector<std::map<std::string, std::string>> rows;
    while (std::getline(f, line)) {
        // RFC 4180 fields: quoted when they hold commas, "" for a quote inside.
        std::vector<std::string> cells(1);
        bool quoted = false;
        for (std::size_t i = 0; i < line.size(); ++i) {
            const char c = line[i];
            if (quoted) {
                if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
                    cells.back() += '"';
                    ++i;
                } else if (c == '"') {
                    quoted = false;
                } else {
                    cells.back() += c;
                }
            } else if (c == '"') {
                quoted = true;
            } else if (c == ',') {
                cells.emplace_back();
            } else {
                cells.back() += c;
            }
        }
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
    o.out_dir = sweepDir("tunnel");
    const Outcome r = sweep(o);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = readCsv(o.out_dir / "results.csv");
    ASSERT_EQ(rows.size(), 8u);  // 4 broad phases x 2 time steps, last --vary fastest
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto& row = rows[i];
        const bool coarse = i % 2 == 0;
        const std::vector<std::string> methods{"brute", "sap", "hgrid", "tree"};
        const std::string label =
            "broadphase=" + methods[i / 2] + " world.time_step=" + (coarse ? "0.05" : "0.005");
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

// CCD as a sweep choice: with conservative advancement the bullet is stopped at its time of
// impact (x = -0.1, t = 0.07 s) even at dt = 0.05, which counts as the contact; without it the
// coarse step misses the plate and the fine step sees the bullet inside it.
TEST(Sweep, CcdStopsCountAsContactsWithTheirTimeOfImpact) {
    app::SweepOptions o;
    o.scene = kScene;
    o.vary = {"world.ccd=off,conservative_advancement", "world.time_step=0.05,0.005"};
    o.reference = {"world.ccd=conservative_advancement"};
    o.out_dir = sweepDir("ccd");
    const Outcome r = sweep(o);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = readCsv(o.out_dir / "results.csv");
    ASSERT_EQ(rows.size(), 4u);
    // off, dt 0.05: never sees the plate.
    EXPECT_EQ(rows[0].at("missed_pairs"), "1");
    EXPECT_EQ(rows[0].at("toi_events"), "0");
    // off, dt 0.005: confirmed at the end of a step with the sphere inside the plate: the
    // bullet moves 0.1 m per step, so the first confirmed sample overlaps by up to 0.1 m.
    EXPECT_EQ(rows[1].at("missed_pairs"), "0");
    EXPECT_GT(std::stod(rows[1].at("max_penetration_m")), 0);
    EXPECT_LE(std::stod(rows[1].at("max_penetration_m")), 0.1 + 1e-9);
    for (int i : {2, 3}) {
        EXPECT_EQ(rows[i].at("missed_pairs"), "0") << i;
        EXPECT_GE(std::stoi(rows[i].at("toi_events")), 1) << i;
        EXPECT_EQ(std::stod(rows[i].at("max_penetration_m")), 0) << i;
        // Both this run and the reference stop at the time of impact, 0.07 s, short by the
        // stage's target gap (about 1e-4 m at 20 m/s: 5e-6 s).
        EXPECT_LT(std::stod(rows[i].at("max_first_contact_error_s")), 1e-5) << i;
    }
    fs::remove_all(o.out_dir);
}

// The CCD tolerance as a sweep choice (docs/sweeps.sh runs the same on the full scene): the
// spinning bar of tunnel_bar_ccd.yaml against a 1e-6 reference at dt / 10. The first-contact
// error grows with the tolerance, and stays within what the tolerance allows: a stop leaves at
// most (tolerance + target gap 1e-3) of the bar's 1 m bounding radius, closed at >= 45 m/s.
TEST(Sweep, CcdToleranceIsSweepableAndLooserIsLessAccurate) {
    app::SweepOptions o;
    o.scene = fs::path(CDLAB_SOURCE_DIR) / "scenes/tunnel_bar_ccd.yaml";
    o.vary = {"world.ccd_tolerance=1e-6,1e-3,1e-1"};
    o.reference = {"world.ccd_tolerance=1e-6"};
    o.duration = 0.1;  // the first stop is at 0.0721 s
    o.report_timing = false;
    o.out_dir = sweepDir("ccd_tolerance");
    const Outcome r = sweep(o);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = readCsv(o.out_dir / "results.csv");
    ASSERT_EQ(rows.size(), 3u);
    double previous = -1;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const double tolerance =
            std::stod(rows[i].at("run").substr(rows[i].at("run").find('=') + 1));
        EXPECT_EQ(rows[i].at("missed_pairs"), "0") << i;
        EXPECT_GE(std::stoi(rows[i].at("toi_events")), 1) << i;
        const double error = std::stod(rows[i].at("max_first_contact_error_s"));
        EXPECT_GT(error, previous) << i;
        EXPECT_LE(error, (tolerance + 1e-3) / 45 + 1e-6) << i;
        previous = error;
    }
    fs::remove_all(o.out_dir);
}

TEST(Sweep, ReportWithoutTimingIsBitIdentical) {
    app::SweepOptions o;
    o.scene = kScene;
    o.vary = {"world.time_step=0.02,0.01"};
    o.report_timing = false;
    o.out_dir = sweepDir("det1");
    ASSERT_EQ(sweep(o).code, 0);
    const std::string first = slurp(o.out_dir / "report.md");
    fs::remove_all(o.out_dir);
    ASSERT_EQ(sweep(o).code, 0);
    EXPECT_EQ(slurp(o.out_dir / "report.md"), first);
    EXPECT_EQ(first.find("ms/step"), std::string::npos);
    fs::remove_all(o.out_dir);
}

// Memory per run: the peak resident set a run adds (Linux VmHWM). 1500 bodies need their own
// pages (bodies, volumes, broad-phase structures), so each run reports a positive figure; the
// markdown table carries it beside the times.
TEST(Sweep, MemoryPerRunIsMeasured) {
    app::SweepOptions o;
    o.scene = std::filesystem::path(CDLAB_SOURCE_DIR) / "scenes/crowd.yaml";
    o.vary = {"broadphase=sap,octree"};
    o.duration = 0.1;
    o.out_dir = sweepDir("memory");
    const Outcome r = sweep(o);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = readCsv(o.out_dir / "results.csv");
    ASSERT_EQ(rows.size(), 2u);
    for (const auto& row : rows) {
        const double mib = std::stod(row.at("memory_mib"));
        EXPECT_TRUE(std::isfinite(mib) && mib >= 0) << row.at("run");
        // ASan's allocator keeps freed pages in quarantine, so a run may add nothing there.
        if (!kAddressSanitizer) {
            EXPECT_GT(mib, 0) << row.at("run");
        }
    }
    EXPECT_NE(slurp(o.out_dir / "report.md").find("memory (MiB)"), std::string::npos);
    fs::remove_all(o.out_dir);
}

// Regression: single wall-clock samples ranked the runs (sphere at dt 0.0333 measured 0.011,
// 0.079 and 0.010 ms/step in three identical sweeps, and report.md named "the cheapest run").
// The ranking is a pure function of medians and min..max ranges: a winner only when its range
// lies wholly below every other's. Fixed numbers, no timing.
TEST(Sweep, RankingNamesAWinnerOnlyWhenTheRangesAreSeparated) {
    using State = app::sweep::Ranking::State;
    // The issue's three samples: median 0.011, range 0.010..0.079.
    const app::Timed sphere = app::sweep::summarize({0.011, 0.079, 0.010});
    EXPECT_EQ(sphere.median, 0.011);
    EXPECT_EQ(sphere.min, 0.010);
    EXPECT_EQ(sphere.max, 0.079);
    EXPECT_EQ(app::sweep::summarize({4, 1, 3, 2}).median, 2.5);
    const app::Timed sap{0.014, 0.013, 0.020};
    const app::Timed octree{0.30, 0.28, 0.33};
    // sphere's lower median, but its range covers sap's: no winner, both listed, best first.
    app::sweep::Ranking r = app::sweep::rankLowest({sap, sphere, octree}, 3);
    EXPECT_EQ(r.state, State::WithinSpread);
    EXPECT_EQ(r.best, 1u);
    EXPECT_EQ(r.overlapping, (std::vector<std::size_t>{1, 0}));
    // sap's slowest repeat (0.020) beats octree's fastest (0.28): sap is named.
    r = app::sweep::rankLowest({octree, sap}, 3);
    EXPECT_EQ(r.state, State::Separated);
    EXPECT_EQ(r.best, 1u);
    EXPECT_TRUE(r.overlapping.empty());
    // Touching ranges are not separated.
    r = app::sweep::rankLowest({{1.0, 0.9, 1.1}, {1.2, 1.1, 1.3}}, 3);
    EXPECT_EQ(r.state, State::WithinSpread);
    // One repeat has no spread: no winner, however far apart; one run: nothing to rank.
    EXPECT_EQ(app::sweep::rankLowest({{1, 1, 1}, {9, 9, 9}}, 1).state, State::NoSpread);
    EXPECT_EQ(app::sweep::rankLowest({sap}, 3).state, State::Only);
    EXPECT_EQ(app::sweep::rankLowest({}, 3).state, State::Empty);
}

// The reading of report.md on fixed runs: the cheapest accurate run is named when separated,
// and "none named" with every run within the spread otherwise.
TEST(Sweep, ReadingNamesTheCheapestRunOnlyBeyondTheSpread) {
    auto run = [](const std::string& label, app::Timed cost) {
        app::SweepRun r;
        r.label = label;
        r.time_step = 0.01;
        r.steps = 10;
        r.repeats = 3;
        r.ms_per_simulated_s = cost;
        r.ms_step = {cost.median / 100, cost.min / 100, cost.max / 100};
        return r;
    };
    app::SweepOptions o;
    o.scene = kScene;
    app::SweepRun reference = run("", {10, 9, 11});
    reference.time_step = 0.001;
    engine::Scene base;
    base.world.time_step = 0.01;
    std::vector<app::SweepRun> runs = {run("broadphase=sap", {1.4, 1.3, 2.0}),
                                       run("broadphase=sphere", {1.1, 1.0, 7.9})};
    std::string md = app::sweep::markdownReport(o, base, 0.1, runs, reference, {});
    EXPECT_NE(md.find("- Cheapest of the runs that confirm exactly the reference's pairs in time: none "
                      "named, the lowest costs are within measurement spread of each other"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("**broadphase=sphere** 1.1 (1..7.9), **broadphase=sap** 1.4 (1.3..2)"),
              std::string::npos)
        << md;
    EXPECT_EQ(md.find("Cheapest of the runs that confirm exactly the reference's pairs in time: **"),
              std::string::npos)
        << md;
    runs[1].ms_per_simulated_s = {3.0, 2.9, 3.2};
    md = app::sweep::markdownReport(o, base, 0.1, runs, reference, {});
    EXPECT_NE(md.find("- Cheapest of the runs that confirm exactly the reference's pairs in time: "
                      "**broadphase=sap** (1.4 (1.3..2) ms per simulated second, median "
                      "(min..max of 3 repeats))"),
              std::string::npos)
        << md;
    EXPECT_EQ(md.find("within measurement spread"), std::string::npos) << md;
    EXPECT_NE(md.find("| 1.4 (1.3..2) |"), std::string::npos) << md;
}

// Regression: tunnel_sphere's reading named a CCD-off run the cheapest accurate one: it confirms
// the reference's pair, but 0.48 s late, on a later pass after a bounce. A run is accurate only
// when every first contact is within its step plus the reference's.
TEST(Sweep, LateFirstContactIsNotAccurate) {
    auto run = [](const std::string& label, double cost, double late) {
        app::SweepRun r;
        r.label = label;
        r.time_step = 0.01;
        r.steps = 10;
        r.repeats = 3;
        r.ms_per_simulated_s = {cost, cost, cost};
        r.ms_step = {cost / 100, cost / 100, cost / 100};
        r.max_first_contact_error = late;
        return r;
    };
    app::SweepOptions o;
    o.scene = kScene;
    app::SweepRun reference = run("", 10, 0);
    reference.time_step = 0.001;
    engine::Scene base;
    base.world.time_step = 0.01;
    // On time: late by less than 0.01 + 0.001 s.
    std::vector<app::SweepRun> runs = {run("world.ccd=off", 1, 0.48),
                                       run("world.ccd=conservative_advancement", 2, 0.0105)};
    const std::string md = app::sweep::markdownReport(o, base, 0.1, runs, reference, {});
    EXPECT_NE(md.find("- **world.ccd=off** confirms the reference's pairs, but a first contact "
                      "comes 0.48 s off the reference's, more than its step plus the reference's "
                      "(0.011 s): found by chance"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("- Only one of the runs that confirm exactly the reference's pairs in "
                      "time: **world.ccd=conservative_advancement**"),
              std::string::npos)
        << md;
    runs.pop_back();
    EXPECT_NE(app::sweep::markdownReport(o, base, 0.1, runs, reference, {})
                  .find("- No run coarser than the reference confirms exactly the reference's "
                        "pairs in time"),
              std::string::npos);
}

// Regression: `--repeat 0` (or less) must be refused before anything runs, on the command line
// too.
TEST(Sweep, RepeatBelowOneIsBadInput) {
    app::SweepOptions o;
    o.scene = kScene;
    o.out_dir = sweepDir("repeat0");
    for (int n : {0, -2}) {
        o.repeat = n;
        const Outcome r = sweep(o);
        EXPECT_EQ(r.code, 2) << n;
        EXPECT_NE(r.err.find("--repeat " + std::to_string(n) + ": must be >= 1"), std::string::npos)
            << r.err;
        EXPECT_EQ(r.out, "") << n;
    }
    EXPECT_FALSE(fs::exists(o.out_dir / "results.csv"));
    const cdlab_test::CliResult cli = cdlab_test::runCdlab(
        "sweep tests/data/tunnel_small.yaml --repeat 0 --out " + (o.out_dir / "cli").string(),
        o.out_dir);
    EXPECT_EQ(cli.exit_code, 2) << cli.err;
    EXPECT_NE(cli.err.find("--repeat 0: must be >= 1"), std::string::npos) << cli.err;
    EXPECT_FALSE(fs::exists(o.out_dir / "cli" / "results.csv"));
    fs::remove_all(o.out_dir);
}

// Regression: a varied run at the reference's time step (the scene's 0.01 / 10 = 0.001, typed
// as 0.001) compared the reference with itself and reported "0 missed" as if it proved
// something. It is flagged in results.csv, in the table's dt cell and in the reading; a finer
// run too.
TEST(Sweep, RunAtTheReferenceTimeStepIsFlagged) {
    app::SweepOptions o;
    o.scene = kScene;
    o.vary = {"world.time_step=0.005,0.001,0.0005"};
    o.repeat = 1;
    o.out_dir = sweepDir("at_reference");
    const Outcome r = sweep(o);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = readCsv(o.out_dir / "results.csv");
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[0].at("dt_vs_reference"), "coarser");
    EXPECT_EQ(rows[1].at("dt_vs_reference"), "same");
    EXPECT_EQ(rows[2].at("dt_vs_reference"), "finer");
    const std::string report = slurp(o.out_dir / "report.md");
    EXPECT_NE(report.find("| world.time_step=0.001 | 0.001 (= reference) |"), std::string::npos)
        << report;
    EXPECT_NE(report.find("| world.time_step=0.0005 | 0.0005 (< reference) |"), std::string::npos)
        << report;
    EXPECT_NE(report.find("| world.time_step=0.005 | 0.005 |"), std::string::npos) << report;
    EXPECT_NE(report.find("- **world.time_step=0.001** runs at the reference's time step (0.001 "
                          "s against 0.001 s): its missed, extra and first-contact figures "
                          "compare the reference's step with itself, so they prove nothing"),
              std::string::npos)
        << report;
    EXPECT_NE(report.find("- **world.time_step=0.0005** runs at a time step finer than the "
                          "reference's"),
              std::string::npos)
        << report;
    fs::remove_all(o.out_dir);
    EXPECT_EQ(app::sweep::stepVsReference(0.01 / 10, 0.001), app::StepVsReference::Same);
    EXPECT_EQ(app::sweep::stepVsReference(0.0010001, 0.001), app::StepVsReference::Coarser);
}

// results.csv gives every timed column as median, min and max over the repeats and names the
// clock; the deterministic columns of a sweep timed 3 times equal those of one timed once.
TEST(Sweep, RepeatsGiveMedianAndRangeAndIdenticalDeterministicColumns) {
    app::SweepOptions o;
    o.scene = kScene;
    o.vary = {"broadphase=sap,hgrid", "world.time_step=0.05,0.005"};
    o.out_dir = sweepDir("repeats");
    o.repeat = 1;
    Outcome r = sweep(o);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto once = readCsv(o.out_dir / "results.csv");
    o.repeat = 3;
    r = sweep(o);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("repeat 3/3: 5 runs timed again, deterministic columns identical"),
              std::string::npos)
        << r.out;
    const auto thrice = readCsv(o.out_dir / "results.csv");
    ASSERT_EQ(thrice.size(), 4u);
    ASSERT_EQ(once.size(), 4u);
    for (std::size_t i = 0; i < thrice.size(); ++i) {
        const auto& row = thrice[i];
        EXPECT_EQ(row.at("repeats"), "3");
        EXPECT_EQ(once[i].at("repeats"), "1");
        EXPECT_EQ(row.at("clock"), "steady_clock");
        for (const char* timed : {"ms_integrate", "ms_volumes", "ms_broad", "ms_narrow", "ms_ccd",
                                  "ms_response", "ms_step", "ms_per_simulated_s"}) {
            const std::string t = timed;
            const double median = std::stod(row.at(t + "_median"));
            EXPECT_LE(std::stod(row.at(t + "_min")), median) << t;
            EXPECT_LE(median, std::stod(row.at(t + "_max"))) << t;
        }
        for (const char* det :
             {"run", "time_step", "steps", "flagged", "confirmed", "broad_false_positives",
              "bv_tests", "narrow_tests", "triangle_tests", "toi_events", "max_penetration_m",
              "pairs_confirmed_total", "missed_pairs", "extra_pairs", "max_first_contact_error_s",
              "max_energy_drift", "max_angular_momentum_drift", "state_hash"}) {
            EXPECT_EQ(row.at(det), once[i].at(det)) << det << " row " << i;
        }
    }
    const std::string report = slurp(o.out_dir / "report.md");
    EXPECT_NE(report.find("std::chrono::steady_clock"), std::string::npos);
    EXPECT_NE(report.find("ms/step, median (min..max)"), std::string::npos);
    fs::remove_all(o.out_dir);
}

// A timing repeat must reproduce the first's deterministic columns; the check names the first
// column that differs (the sweep then fails: determinism is a guarantee of the engine).
TEST(Sweep, DeterministicDifferenceNamesTheColumnThatDiffers) {
    app::SweepRun first;
    first.steps = 20;
    first.flagged = 1.5;
    first.bv_tests = 12;
    first.toi_events = 2;
    first.state_hash = 42;
    first.ms_step = {0.1, 0.1, 0.1};
    app::SweepRun again = first;
    again.ms_step = {0.7, 0.7, 0.7};  // times may differ
    again.memory_mib = 3;             // measured in the first repeat only
    EXPECT_EQ(app::sweep::deterministicDifference(first, again), "");
    again.state_hash = 43;
    EXPECT_EQ(app::sweep::deterministicDifference(first, again), "state_hash: 42 vs 43");
    again = first;
    again.bv_tests = 12.5;
    EXPECT_EQ(app::sweep::deterministicDifference(first, again), "bv_tests: 12 vs 12.5");
    again = first;
    again.toi_events = 3;
    EXPECT_EQ(app::sweep::deterministicDifference(first, again), "toi_events: 2 vs 3");
    // Combining keeps the first repeat's deterministic columns and summarises the times.
    std::vector<app::SweepRun> repeats = {first, first, first};
    repeats[1].ms_step = {0.3, 0.3, 0.3};
    repeats[2].ms_step = {0.2, 0.2, 0.2};
    const app::SweepRun combined = app::sweep::combineRepeats(repeats);
    EXPECT_EQ(combined.repeats, 3);
    EXPECT_EQ(combined.ms_step.median, 0.2);
    EXPECT_EQ(combined.ms_step.min, 0.1);
    EXPECT_EQ(combined.ms_step.max, 0.3);
    EXPECT_EQ(combined.state_hash, 42u);
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

// Regression: `--vary broadphase=sap --vary broadphase=grid` made one run labelled with both,
// and `--duration 1e20` overflowed llround and ran one step, exit 0.
TEST(Sweep, RepeatedVaryKeysAndEndlessDurationsAreBadInput) {
    app::SweepOptions o;
    o.scene = kScene;
    o.out_dir = sweepDir("repeated");
    o.vary = {"broadphase=sap", "broadphase=grid"};
    Outcome r = sweep(o);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--vary broadphase: given twice"), std::string::npos) << r.err;
    o.vary = {"broadphase=sap"};
    o.duration = 1e20;
    r = sweep(o);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--duration 1e+20: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("more than the limit of 1e+09"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(o.out_dir / "results.csv"));
    fs::remove_all(o.out_dir);
}

TEST(Sweep, BadInputIsExitTwoWithTheKeyNamed) {
    app::SweepOptions o;
    o.scene = kScene;
    o.out_dir = sweepDir("bad");
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

TEST(Sweep, FloatComparisonAgainstTheSameBuildFindsNoDifference) {
    // The plumbing of --float-binary (cdlab run --set ... --trace in a child process, values
    // with spaces and brackets quoted for the shell) checked with this double build standing in
    // for the float one: bit-identical runs, so every deviation is exactly zero.
    app::SweepOptions o;
    o.scene = kScene;
    o.vary = {"world.time_step=0.01,0.005", "world.gravity=[0, -9.81, 0]"};
    o.float_binary = fs::path(CDLAB_BINARY);
    o.out_dir = sweepDir("float");
    const Outcome r = sweep(o);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = readCsv(o.out_dir / "float_vs_double.csv");
    ASSERT_EQ(rows.size(), 2u);
    for (const auto& row : rows) {
        EXPECT_EQ(row.at("frames"), "11");
        EXPECT_EQ(row.at("first_pair_difference"), "-1");
        EXPECT_EQ(row.at("max_position_deviation"), "0");
        EXPECT_EQ(row.at("max_orientation_deviation"), "0");
        EXPECT_EQ(row.count("error") ? row.at("error") : "", "");
    }
    EXPECT_NE(slurp(o.out_dir / "report.md").find("## Float against double"), std::string::npos);
    EXPECT_NE(
        slurp(o.out_dir / "report.md")
            .find("- Float and double trajectories are identical in every frame of every run."),
        std::string::npos);
    EXPECT_FALSE(fs::exists(o.out_dir / "traces"));  // removed unless --keep-traces
    fs::remove_all(o.out_dir);

    o.float_binary = fs::path("/nonexistent/cdlab");
    EXPECT_EQ(sweep(o).code, 2);
}

// Regression: the reading called float "the same" from confirmed pairs alone while
// docs/sweeps/tunnel_bar/float_vs_double.csv showed 8.43 m and 3.14 rad of divergence with no
// pair differing. The reading now always names the largest deviations and their runs. Figures
// from that file.
TEST(Sweep, FloatReadingStatesTheLargestDeviationEvenWhenPairsAgree) {
    auto run = [](const std::string& label, int first, int differing, double dp, double dq) {
        app::FloatRun f;
        f.label = label;
        f.comparison.frames = 150;
        f.comparison.first_pair_difference = first;
        f.comparison.pair_frames_differing = differing;
        f.comparison.max_position_deviation = dp;
        f.comparison.max_orientation_deviation = dq;
        return f;
    };
    std::vector<app::FloatRun> floats = {
        run("world.ccd=off", -1, 0, 0.0025882, 0.0211288),
        run("world.ccd=conservative_advancement", -1, 0, 8.43303, 3.13846),
        run("world.ccd=off world.time_step=0.000521", -1, 0, 1.10413e-05, 8.50651e-07)};
    std::string text = app::floatReading(floats, 20.4);
    EXPECT_NE(text.find("Float confirms the same pairs as double in every frame of every run."),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("Largest trajectory divergence of float from double: position 8.43 m "
                        "(4.13e-01 of the scene size) in **world.ccd=conservative_advancement**; "
                        "orientation 3.14 rad in **world.ccd=conservative_advancement**."),
              std::string::npos)
        << text;
    // Position and orientation maxima in different runs are named separately; a run whose
    // pairs differ keeps its own line; an errored comparison is left out of the maxima.
    floats[0].comparison.max_orientation_deviation = 4;
    floats[2].comparison.first_pair_difference = 14;
    floats[2].comparison.pair_frames_differing = 4;
    floats.push_back(run("broken", -1, 0, 99, 99));
    floats.back().comparison.error = "unreadable";
    text = app::floatReading(floats, 20.4);
    EXPECT_NE(text.find("- Float changes the answers of **world.ccd=off "
                        "world.time_step=0.000521** from frame 14 on (4 of 150 frames)."),
              std::string::npos)
        << text;
    EXPECT_EQ(text.find("same pairs"), std::string::npos) << text;
    EXPECT_NE(text.find("position 8.43 m (4.13e-01 of the scene size) in "
                        "**world.ccd=conservative_advancement**; orientation 4 rad in "
                        "**world.ccd=off**."),
              std::string::npos)
        << text;
    // Identical builds: said so, no deviation line.
    const std::vector<app::FloatRun> same = {run("a", -1, 0, 0, 0), run("b", -1, 0, 0, 0)};
    text = app::floatReading(same, 1);
    EXPECT_NE(text.find("identical in every frame of every run"), std::string::npos) << text;
    EXPECT_EQ(text.find("Largest"), std::string::npos) << text;
}

TEST(Sweep, CompareTracesFindsTheFirstDifferingFrameAndTheLargestDeviation) {
    const fs::path dir = sweepDir("traces");
    fs::create_directories(dir);
    auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(dir / name) << text;
        return dir / name;
    };
    const std::string f0 =
        R"({"frame":0,"time":0,"positions":[[0,0,0],[1,0,0]],"orientations_wxyz":[[1,0,0,0],[1,0,0,0]],"colliding_pairs":[[0,1]]})"
        "\n";
    const std::string f1 =
        R"({"frame":1,"time":0.1,"positions":[[0,0,0],[2,0,0]],"orientations_wxyz":[[1,0,0,0],[1,0,0,0]],"colliding_pairs":[]})"
        "\n";
    const std::string f1_moved =
        R"({"frame":1,"time":0.1,"positions":[[0,0,0.5],[2,0,0]],"orientations_wxyz":[[1,0,0,0],[0,1,0,0]],"colliding_pairs":[[0,1]]})"
        "\n";
    const fs::path a = write("a.jsonl", f0 + f1);
    const fs::path b = write("b.jsonl", f0 + f1_moved);
    app::TraceComparison same = app::compareTraces(a, a);
    EXPECT_EQ(same.error, "");
    EXPECT_EQ(same.frames, 2);
    EXPECT_EQ(same.first_pair_difference, -1);
    EXPECT_EQ(same.max_position_deviation, 0);
    app::TraceComparison diff = app::compareTraces(a, b);
    EXPECT_EQ(diff.error, "");
    EXPECT_EQ(diff.first_pair_difference, 1);
    EXPECT_EQ(diff.pair_frames_differing, 1);
    EXPECT_DOUBLE_EQ(diff.max_position_deviation, 0.5);
    EXPECT_DOUBLE_EQ(diff.final_position_deviation, 0.5);
    EXPECT_NEAR(diff.max_orientation_deviation, M_PI, 1e-12);  // half a turn about x
    const fs::path one_body = write(
        "c.jsonl",
        R"({"frame":0,"time":0,"positions":[[0,0,0]],"orientations_wxyz":[[1,0,0,0]],"colliding_pairs":[]})"
        "\n");
    EXPECT_NE(app::compareTraces(a, one_body).error.find("body counts"), std::string::npos);
    EXPECT_NE(app::compareTraces(a, write("bad.jsonl", "{not json\n")).error.find("malformed"),
              std::string::npos);
    EXPECT_NE(app::compareTraces(a, dir / "missing.jsonl").error.find("cannot read"),
              std::string::npos);
    fs::remove_all(dir);
}

}  // namespace
