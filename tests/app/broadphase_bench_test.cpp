// `cdlab bench broadphase` end to end at the size of smallBenchOptions(): every default method
// (cdlab's AABB broad phases and the peers compiled in) appears in the table and the JSON with
// every field, agrees on the pair count with a brute-force count written here, and is checked
// frame by frame; bad options exit 2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "bench_broadphase.h"
#include "bench_broadphase_report.h"
#include "bench_method.h"
#include "bench_workload.h"
#include "cli_run.h"

namespace {

namespace fs = std::filesystem;
using Result = cdlab_test::CliResult;
using cdlab_test::runCdlab;
using cdlab_test::slurp;

fs::path bpBenchDir(const std::string& name) { return cdlab_test::tempDir("cdlab_bp_bench_", name); }

// Calls visit(a, b) for every overlapping pair of the workload after `frames` steps, by testing
// every pair of boxes with the closed interval test on each axis (touching counts): independent
// of every broad phase and of the bench's own reference sweep.
template <class Visit>
void forEachOverlappingPair(app::WorkloadKind kind, int n, std::uint64_t seed, int frames,
                            Visit visit) {
    app::MovingBoxes boxes(kind, n, seed);
    for (int f = 0; f < frames; ++f) boxes.step();
    for (int a = 0; a < n; ++a) {
        for (int b = a + 1; b < n; ++b) {
            const collision::Aabb& ba = boxes.aabb(a);
            const collision::Aabb& bb = boxes.aabb(b);
            bool overlap = true;
            for (int k = 0; k < 3; ++k) {
                overlap = overlap && ba.min[k] <= bb.max[k] && bb.min[k] <= ba.max[k];
            }
            if (overlap) visit(a, b);
        }
    }
}

// Overlapping pairs of the workload after `frames` steps (forEachOverlappingPair).
std::int64_t bruteForcePairs(app::WorkloadKind kind, int n, std::uint64_t seed, int frames) {
    std::int64_t pairs = 0;
    forEachOverlappingPair(kind, n, seed, frames, [&](int, int) { ++pairs; });
    return pairs;
}

std::string joined(const std::vector<int>& values) {
    std::string out;
    for (int v : values) {
        if (!out.empty()) out += ',';
        out += std::to_string(v);
    }
    return out;
}

TEST(BroadphaseBench, SmallRunReportsEveryMethodWithTheSamePairsInTableAndJson) {
    const app::BenchOptions small = app::smallBenchOptions();
    ASSERT_EQ(small.sizes.size(), 1u);
    ASSERT_EQ(small.workload, "both");
    const int n = small.sizes.front();
    const fs::path work = bpBenchDir("small");
    const fs::path json = work / "bp.json";
    const Result r =
        runCdlab("bench broadphase --sizes " + joined(small.sizes) + " --frames " +
                     std::to_string(small.frames) + " --workload " + small.workload + " --seed " +
                     std::to_string(small.seed) + " --peers default --json " + json.string(),
                 work);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_FALSE(fs::exists(json.string() + ".partial"));

    // The default method set is what the binary runs: the same library is linked here.
    std::set<std::string> expected_methods;
    std::set<std::string> peers;
    std::set<std::string> threaded;  // left out by the default thread-CPU clock
    for (const app::BenchMethodEntry& m : app::benchMethods()) {
        if (!m.default_set) continue;
        expected_methods.insert(m.name);
        if (m.peer) peers.insert(m.name);
        if (m.threads > 1) threaded.insert(m.name);
    }
    EXPECT_TRUE(threaded.count("hgrid2"));
    for (const char* cdlab : {"brute", "sap", "sap1", "grid", "hash", "hgrid", "tree", "octree"}) {
        EXPECT_TRUE(expected_methods.count(cdlab)) << cdlab << " missing from the default set";
    }

    const nlohmann::json doc = nlohmann::json::parse(slurp(json));
    EXPECT_EQ(doc["frames"], small.frames);
    EXPECT_EQ(doc["seed"], small.seed);
    ASSERT_TRUE(doc["rows"].is_array());
    EXPECT_EQ(doc["rows"].size(), 2 * expected_methods.size());

    std::map<std::string, std::set<std::string>> methods_by_workload;
    std::map<std::string, int> best_peer_rows;
    for (const nlohmann::json& row : doc["rows"]) {
        const std::string method = row.value("method", "");
        const std::string workload = row.value("workload", "");
        SCOPED_TRACE(method + " / " + workload);
        if (threaded.count(method)) {
            ASSERT_TRUE(row.contains("skipped")) << row.dump();
            EXPECT_NE(row["skipped"].get<std::string>().find("--clock wall"), std::string::npos);
            methods_by_workload[workload].insert(method);
            continue;
        }
        EXPECT_FALSE(row.contains("skipped")) << row.dump();
        EXPECT_FALSE(row.contains("failed")) << row.dump();
        bool complete = true;
        for (const char* key :
             {"method", "workload", "n", "peer", "insert_ms", "ms_per_frame_median",
              "ms_per_frame_mean", "ms_per_frame_first100_median", "ms_per_frame_last100_median",
              "pairs", "ratio_to_best_peer", "ms_per_frame_median_exact_pairs",
              "ratio_to_best_peer_exact_pairs", "peak_mb", "frames", "mismatched_frames"}) {
            EXPECT_TRUE(row.contains(key)) << key;
            complete = complete && row.contains(key);
        }
        if (!complete) continue;
        methods_by_workload[workload].insert(method);
        EXPECT_EQ(row["n"], n);
        EXPECT_EQ(row["peer"].get<bool>(), peers.count(method) == 1);
        EXPECT_EQ(row["frames"], small.frames);
        EXPECT_EQ(row["mismatched_frames"], 0);
        for (const char* key : {"insert_ms", "ms_per_frame_median", "ms_per_frame_mean"}) {
            ASSERT_TRUE(row[key].is_number()) << key << ": " << row[key];
            EXPECT_GE(row[key].get<double>(), 0) << key;
        }
        // The exact-pairs rule times the same frames and the delivery of exact pairs after them.
        ASSERT_TRUE(row["ms_per_frame_median_exact_pairs"].is_number()) << row.dump();
        EXPECT_GE(row["ms_per_frame_median_exact_pairs"].get<double>(),
                  row["ms_per_frame_median"].get<double>());
        // Fewer than 100 frames: the first-100 and last-100 medians are the whole run's median.
        ASSERT_LE(small.frames, 100);
        EXPECT_EQ(row["ms_per_frame_first100_median"], row["ms_per_frame_median"]);
        EXPECT_EQ(row["ms_per_frame_last100_median"], row["ms_per_frame_median"]);
        // Isolated runs (the default) fork per method and report the child's peak growth.
        ASSERT_TRUE(row["peak_mb"].is_number()) << row["peak_mb"];
        EXPECT_GE(row["peak_mb"].get<double>(), 0);
        if (peers.empty()) {
            EXPECT_TRUE(row["ratio_to_best_peer"].is_null()) << row["ratio_to_best_peer"];
        } else {
            ASSERT_TRUE(row["ratio_to_best_peer"].is_number()) << row["ratio_to_best_peer"];
            const double ratio = row["ratio_to_best_peer"].get<double>();
            EXPECT_GT(ratio, 0);
            if (row["peer"].get<bool>()) {
                EXPECT_GE(ratio, 1.0) << "a peer is faster than the best peer";
                if (ratio == 1.0) ++best_peer_rows[workload];
                ASSERT_TRUE(row["ratio_to_best_peer_exact_pairs"].is_number()) << row.dump();
                EXPECT_GE(row["ratio_to_best_peer_exact_pairs"].get<double>(), 1.0)
                    << "a peer delivers exact pairs faster than the best peer by that rule";
            }
        }
    }

    // Both workloads, each with exactly the default methods.
    ASSERT_EQ(methods_by_workload.size(), 2u);
    for (const auto& [workload, methods] : methods_by_workload) {
        EXPECT_EQ(methods, expected_methods) << workload;
        if (!peers.empty()) {
            EXPECT_GE(best_peer_rows[workload], 1) << workload;
        }
    }

    // Every method reports the pairs a brute-force count of the last frame finds, so they all
    // agree with each other; the workload is calibrated to overlap, so the count is not 0.
    for (const auto& [name, kind] :
         {std::pair{"uniform", app::WorkloadKind::Uniform}, {"mixed", app::WorkloadKind::Mixed}}) {
        const std::int64_t truth = bruteForcePairs(kind, n, small.seed, small.frames);
        EXPECT_GT(truth, n / 2) << name;
        for (const nlohmann::json& row : doc["rows"]) {
            if (row["workload"] != name || row.contains("skipped")) continue;
            EXPECT_EQ(row["pairs"].get<std::int64_t>(), truth) << row["method"] << " / " << name;
        }
    }

    // The table: a heading per workload, the column header, one checked row per method.
    EXPECT_NE(r.out.find("== workload uniform, N = " + std::to_string(n)), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("== workload mixed, N = " + std::to_string(n)), std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("median_ms"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("peak_MB"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("MISMATCH"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("FAILED"), std::string::npos) << r.out;
    for (const std::string& method : expected_methods) {
        const std::string label = method + (peers.count(method) ? " [peer]" : "");
        int rows = 0;
        std::istringstream lines(r.out);
        for (std::string line; std::getline(lines, line);) {
            if (line.rfind(label + " ", 0) != 0) continue;
            ++rows;
            if (threaded.count(method)) {
                EXPECT_NE(line.find("--clock wall"), std::string::npos) << line;
            } else {
                EXPECT_EQ(line.substr(line.size() - 2), "ok") << line;
            }
        }
        EXPECT_EQ(rows, 2) << label << " rows in the table\n" << r.out;
    }
    EXPECT_NE(r.out.find("fastest cdlab: "), std::string::npos) << r.out;
    if (!peers.empty()) {
        EXPECT_NE(r.out.find("; best peer: "), std::string::npos) << r.out;
    }
    fs::remove_all(work);
}

// --clock wall times every method by elapsed time, the two-thread hgrid2 included; at 5000
// boxes (over its 4096 threshold) it runs both lanes and must report hgrid's pairs, here on
// the 1:10^4 size mix (--workload wide).
TEST(BroadphaseBench, WallClockRunsTheTwoThreadMethodWithTheSamePairs) {
    const fs::path work = bpBenchDir("wall");
    const fs::path json = work / "wall.json";
    const Result r = runCdlab(
        "bench broadphase --sizes 5000 --frames 4 --methods hgrid,hgrid2 "
        "--workload wide --clock wall --in-process --json " +
            json.string(),
        work);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("elapsed (wall-clock) time"), std::string::npos) << r.out;
    const nlohmann::json doc = nlohmann::json::parse(slurp(json));
    EXPECT_EQ(doc["clock"], "wall");
    ASSERT_EQ(doc["rows"].size(), 2u);
    for (const nlohmann::json& row : doc["rows"]) {
        ASSERT_FALSE(row.contains("skipped")) << row.dump();
        EXPECT_EQ(row["mismatched_frames"], 0) << row.dump();
        EXPECT_EQ(row["frames"], 4) << row.dump();
        EXPECT_EQ(row["workload"], "wide") << row.dump();
    }
    EXPECT_EQ(doc["rows"][0]["method"], "hgrid");
    EXPECT_EQ(doc["rows"][1]["method"], "hgrid2");
    EXPECT_EQ(doc["rows"][0]["pairs"], doc["rows"][1]["pairs"]);
    EXPECT_GT(doc["rows"][0]["pairs"].get<std::int64_t>(), 5000);
    fs::remove_all(work);
}

// Boxes of the workload after `frames` steps that overlap at least one other box (closed
// intervals, like bruteForcePairs): each must be in a potentially colliding set.
std::int64_t boxesInSomePair(app::WorkloadKind kind, int n, std::uint64_t seed, int frames) {
    std::vector<char> paired(static_cast<std::size_t>(n), 0);
    forEachOverlappingPair(kind, n, seed, frames, [&](int a, int b) {
        paired[static_cast<std::size_t>(a)] = 1;
        paired[static_cast<std::size_t>(b)] = 1;
    });
    return std::count(paired.begin(), paired.end(), 1);
}

// cullide renders on llvmpipe's threads, which the thread's CPU clock does not see: under the
// default clock it is timed by the process's CPU time, and the table and JSON say so. Beside its
// pairs it reports the size of its potentially colliding set in the last frame, which holds every
// box that overlaps another and no more boxes than there are.
TEST(BroadphaseBench, CullideReportsItsPotentiallyCollidingSetAndItsClock) {
    const fs::path work = bpBenchDir("cullide");
    const fs::path json = work / "cullide.json";
    const int n = 400;
    const int frames = 3;
    const std::uint64_t seed = 1;
    const Result r =
        runCdlab("bench broadphase --sizes " + std::to_string(n) + " --frames " +
                     std::to_string(frames) + " --methods cullide,sap --workload uniform --seed " +
                     std::to_string(seed) + " --json " + json.string(),
                 work);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    const nlohmann::json doc = nlohmann::json::parse(slurp(json));
    ASSERT_EQ(doc["rows"].size(), 2u) << doc.dump();
    const nlohmann::json& cullide = doc["rows"][0];
    const nlohmann::json& sap = doc["rows"][1];
    ASSERT_EQ(cullide["method"], "cullide");
    ASSERT_FALSE(cullide.contains("skipped")) << cullide.dump();
    EXPECT_EQ(cullide["mismatched_frames"], 0);
    EXPECT_EQ(cullide["clock"], "process");
    EXPECT_EQ(sap["clock"], "thread");
    EXPECT_FALSE(sap.contains("potentially_colliding")) << sap.dump();
    ASSERT_TRUE(cullide.contains("potentially_colliding")) << cullide.dump();
    const std::int64_t pcs = cullide["potentially_colliding"].get<std::int64_t>();
    const std::int64_t paired = boxesInSomePair(app::WorkloadKind::Uniform, n, seed, frames);
    EXPECT_GT(paired, 0);
    EXPECT_GE(pcs, paired);
    EXPECT_LE(pcs, n);

    bool clock_noted = false;
    bool pcs_noted = false;
    std::istringstream lines(r.out);
    for (std::string line; std::getline(lines, line);) {
        if (line.find("cullide: timed by the process's CPU time") != std::string::npos) {
            clock_noted = true;
        }
        const std::string pcs_text = "cullide: potentially colliding set held " +
                                     std::to_string(pcs) + " of " + std::to_string(n) + " boxes";
        if (line.find(pcs_text) != std::string::npos) {
            pcs_noted = true;
            EXPECT_NE(line.find("(pairs: " + cullide["pairs"].dump() + ")"), std::string::npos)
                << line;
        }
    }
    EXPECT_TRUE(clock_noted) << r.out;
    EXPECT_TRUE(pcs_noted) << r.out;

    // Under --clock wall every method is timed by elapsed time, cullide too.
    const Result wall = runCdlab(
        "bench broadphase --sizes 200 --frames 2 --methods cullide "
        "--workload uniform --clock wall --json " +
            json.string(),
        work);
    ASSERT_EQ(wall.exit_code, 0) << wall.out << wall.err;
    EXPECT_EQ(nlohmann::json::parse(slurp(json))["rows"][0]["clock"], "wall");
    EXPECT_EQ(wall.out.find("timed by the process's CPU time"), std::string::npos) << wall.out;
    fs::remove_all(work);
}

// Tuned peers: every configuration of each peer's grid runs as many frames as the measured run
// (120 here: a trial of the first 100 would rank a DBVT whose tree degrades later by its good
// start), and the peer row of the table is the configuration whose median was the lowest of
// its peer's; the fastest by the exact-pairs median is a peer row too (the same row when one
// configuration is the fastest by both).
TEST(BroadphaseBench, TunedPeersRunTheirWholeGridAndReportTheFastestConfiguration) {
    std::map<std::string, std::set<std::string>> grid;
    for (const app::BenchMethodEntry& m : app::benchMethods()) {
        if (!m.family.empty()) grid[m.family].insert(m.name);
    }
    if (grid.empty()) GTEST_SKIP() << "built without Bullet and FCL";
    const fs::path work = bpBenchDir("tuned");
    const fs::path json = work / "tuned.json";
    const Result r = runCdlab(
        "bench broadphase --sizes 150 --frames 120 --workload uniform "
        "--peers all --json " +
            json.string(),
        work);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    const nlohmann::json doc = nlohmann::json::parse(slurp(json));
    // family -> method -> median, and the same by the exact-pairs rule
    std::map<std::string, std::map<std::string, double>> swept, swept_exact;
    std::map<std::string, std::string> chosen, chosen_exact;  // family -> method
    for (const nlohmann::json& row : doc["rows"]) {
        const std::string method = row["method"];
        if (row["workload"] == "uniform sweep") {
            ASSERT_FALSE(row.contains("failed")) << row.dump();
            ASSERT_EQ(row["mismatched_frames"], 0) << row.dump();
            EXPECT_EQ(row["frames"], 120) << row.dump();
            const std::string family = method.substr(0, method.find(':'));
            swept[family][method] = row["ms_per_frame_median"].get<double>();
            swept_exact[family][method] = row["ms_per_frame_median_exact_pairs"].get<double>();
        } else if (row.contains("tuned_peer")) {
            EXPECT_EQ(row["frames"], 120) << row.dump();
            EXPECT_EQ(row["mismatched_frames"], 0) << row.dump();
            const std::string by = row["tuned_by"];
            if (by != "exact_ms") chosen[row["tuned_peer"]] = method;
            if (by != "median_ms") chosen_exact[row["tuned_peer"]] = method;
            EXPECT_TRUE(row["peer"].get<bool>());
        } else {
            // No default peer configuration runs beside the tuned ones.
            EXPECT_FALSE(row["peer"].get<bool>()) << row.dump();
        }
    }
    const auto fastest = [](const std::map<std::string, double>& medians) {
        return std::min_element(medians.begin(), medians.end(),
                                [](const auto& a, const auto& b) { return a.second < b.second; })
            ->second;
    };
    ASSERT_EQ(swept.size(), grid.size());
    for (const auto& [family, methods] : grid) {
        SCOPED_TRACE(family);
        std::set<std::string> ran;
        for (const auto& [method, ms] : swept[family]) ran.insert(method);
        EXPECT_EQ(ran, methods);
        ASSERT_TRUE(chosen.count(family));
        ASSERT_TRUE(chosen_exact.count(family));
        EXPECT_EQ(swept[family].at(chosen[family]), fastest(swept[family])) << chosen[family];
        EXPECT_EQ(swept_exact[family].at(chosen_exact[family]), fastest(swept_exact[family]))
            << chosen_exact[family];
        // The table names the winner and how many configurations it was chosen from.
        EXPECT_NE(r.out.find(chosen[family] + " [peer]"), std::string::npos) << r.out;
    }
    EXPECT_NE(r.out.find("(best of "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("peer configurations swept"), std::string::npos) << r.out;
    fs::remove_all(work);
}

// Terdiman's BoxPruning scene ("Box pruning revisited", 2017): his generator, MSVC's rand()
// seeded with 42, gives 11,811 overlapping pairs at 10,000 boxes, counted here by brute force.
TEST(BroadphaseBench, BoxPruningWorkloadIsTerdimansScene) {
    const app::MovingBoxes boxes(app::WorkloadKind::BoxPruning, 10000, /*seed=*/1);
    EXPECT_EQ(bruteForcePairs(app::WorkloadKind::BoxPruning, 10000, 1, 0), 11811);
    app::PairReference reference;
    EXPECT_EQ(reference.count(boxes).pairs, 11811);
    // Integer centres in [-2048, 2047] and half extents in [0, 127], both ends reached.
    collision::Real lo = 1e9, hi = -1e9, half_max = 0;
    for (int i = 0; i < boxes.size(); ++i) {
        for (int k = 0; k < 3; ++k) {
            const collision::Real c = boxes.centers()[i][k];
            const collision::Real h = boxes.halfExtents()[i][k];
            ASSERT_EQ(c, std::floor(c));
            ASSERT_EQ(h, std::floor(h));
            ASSERT_GE(h, 0);
            lo = std::min(lo, c);
            hi = std::max(hi, c);
            half_max = std::max(half_max, h);
        }
    }
    EXPECT_EQ(lo, -2048);
    EXPECT_EQ(hi, 2047);
    EXPECT_EQ(half_max, 127);
    // Moving: each centre moves by -1, 0 or +1 per axis per frame (all three occur) and stays
    // in range; the sizes do not change.
    app::MovingBoxes moved = boxes;
    moved.step();
    std::set<int> steps;
    for (int i = 0; i < boxes.size(); ++i) {
        for (int k = 0; k < 3; ++k) {
            const collision::Real d = moved.centers()[i][k] - boxes.centers()[i][k];
            ASSERT_LE(std::abs(d), 1);
            steps.insert(static_cast<int>(d));
            ASSERT_GE(moved.centers()[i][k], -2048);
            ASSERT_LE(moved.centers()[i][k], 2047);
        }
        ASSERT_EQ(moved.halfExtents()[i], boxes.halfExtents()[i]);
    }
    EXPECT_EQ(steps, (std::set<int>{-1, 0, 1}));
    EXPECT_EQ(reference.count(moved).pairs,
              bruteForcePairs(app::WorkloadKind::BoxPruning, 10000, 1, 1));
}

// `--workload boxpruning` measures one-shot (create + insert + find pairs, repeated) and moving
// tables, every method checked against the reference.
TEST(BroadphaseBench, BoxPruningRunsOneShotAndMovingTables) {
    const fs::path work = bpBenchDir("boxpruning");
    const fs::path json = work / "bp.json";
    const Result r = runCdlab(
        "bench broadphase --workload boxpruning --sizes 400 --frames 4 "
        "--methods brute,sap-packed,hgrid --json " +
            json.string(),
        work);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("== workload boxpruning one-shot, N = 400"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("== workload boxpruning, N = 400"), std::string::npos) << r.out;
    const nlohmann::json doc = nlohmann::json::parse(slurp(json));
    ASSERT_EQ(doc["rows"].size(), 6u);
    const std::int64_t first = bruteForcePairs(app::WorkloadKind::BoxPruning, 400, 1, 0);
    const std::int64_t last = bruteForcePairs(app::WorkloadKind::BoxPruning, 400, 1, 4);
    for (const nlohmann::json& row : doc["rows"]) {
        EXPECT_EQ(row["mismatched_frames"], 0) << row.dump();
        EXPECT_EQ(row["frames"], 4) << row.dump();
        const bool one_shot = row["workload"] == "boxpruning one-shot";
        EXPECT_EQ(row["pairs"].get<std::int64_t>(), one_shot ? first : last) << row.dump();
    }
    fs::remove_all(work);
}

// A peer that disagrees with the reference (FCL's SaP misses pairs of the boxpruning scene) is
// shown as a mismatch and left out of the ratios: the best peer and every ratio come from the
// peers that agreed, and the run still succeeds, since the defect is not ours.
TEST(BroadphaseBench, APeerThatDisagreesIsShownAndLeftOutOfTheRatios) {
    if (app::findBenchMethod("fcl-sap:update") == nullptr ||
        app::findBenchMethod("bullet-dbvt") == nullptr) {
        GTEST_SKIP() << "built without Bullet and FCL";
    }
    const fs::path work = bpBenchDir("peer_mismatch");
    const fs::path json = work / "bp.json";
    const Result r = runCdlab(
        "bench broadphase --workload boxpruning --sizes 400 --frames 3 "
        "--methods hgrid,fcl-sap:update,bullet-dbvt --json " +
            json.string(),
        work);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("MISMATCH: fcl-sap:update"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("best peer: fcl-sap"), std::string::npos) << r.out;
    const nlohmann::json doc = nlohmann::json::parse(slurp(json));
    int mismatched_peers = 0;
    for (const nlohmann::json& row : doc["rows"]) {
        if (row["mismatched_frames"].get<int>() > 0) {
            ++mismatched_peers;
            EXPECT_EQ(row["method"], "fcl-sap:update") << row.dump();
            EXPECT_TRUE(row["ratio_to_best_peer"].is_null()) << row.dump();
        } else {
            EXPECT_TRUE(row["ratio_to_best_peer"].is_number()) << row.dump();
        }
    }
    EXPECT_GE(mismatched_peers, 1) << "the peer agreed: the test shows nothing";
    fs::remove_all(work);
}

TEST(BroadphaseBench, BadOptionsExitTwoBeforeAnyWork) {
    const fs::path work = bpBenchDir("bad");
    Result r = runCdlab("bench broadphase --sizes 1 --frames 2", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--sizes: 1 boxes"), std::string::npos) << r.err;
    r = runCdlab("bench broadphase --sizes 50 --frames 0", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--frames: 0"), std::string::npos) << r.err;
    r = runCdlab("bench broadphase --sizes 50 --frames 2 --clock cpu", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--clock"), std::string::npos) << r.err;
    r = runCdlab("bench broadphase --sizes 50 --frames 2 --peers best", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--peers"), std::string::npos) << r.err;
    r = runCdlab("bench broadphase --sizes 50 --frames 2 --methods sap,nope", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("unknown method 'nope'"), std::string::npos) << r.err;
    const fs::path unwritable = work / "no" / "such" / "dir.json";
    r = runCdlab(
        "bench broadphase --sizes 50 --frames 2 --methods sap --json " + unwritable.string(), work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("cannot write"), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("== workload"), std::string::npos) << "measured before failing";
    // Regression: 2e9 boxes ended in an uncaught bad_alloc (exit 134).
    r = runCdlab("bench broadphase --sizes 2000000000 --frames 2 --methods sap", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--sizes: 2000000000 boxes; need at least 2 and at most 10000000"),
              std::string::npos)
        << r.err;
    // Regression: a JSON path that is a directory (or any non-regular file) is refused up front.
    r = runCdlab("bench broadphase --sizes 50 --frames 2 --methods sap --json " + work.string(),
                 work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find(": exists and is a directory"), std::string::npos) << r.err;
    fs::remove_all(work);
}

// --rounds R runs each row R times, interleaved (A B, B A, A B): every row reports each round,
// its figures are the medians over them, and in every round the best peer has ratio 1.
TEST(BroadphaseBench, RoundsInterleaveTheRowsAndReportMediansOverThem) {
    std::string peer;
    for (const app::BenchMethodEntry& m : app::benchMethods()) {
        if (m.peer && m.default_set && m.family.empty()) {
            peer = m.name;
            break;
        }
    }
    if (peer.empty()) GTEST_SKIP() << "built without Bullet and FCL";
    const fs::path work = bpBenchDir("rounds");
    const fs::path json = work / "rounds.json";
    const Result r = runCdlab("bench broadphase --sizes 200 --frames 6 --workload uniform "
                              "--in-process --rounds 3 --methods sap-packed," +
                                  peer + " --json " + json.string(),
                              work);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    const nlohmann::json doc = nlohmann::json::parse(slurp(json));
    EXPECT_EQ(doc["rounds"], 3);
    ASSERT_EQ(doc["rows"].size(), 2u);
    std::vector<double> best_ratio(3, 1e300);
    for (const nlohmann::json& row : doc["rows"]) {
        ASSERT_TRUE(row.contains("rounds")) << row.dump();
        ASSERT_EQ(row["rounds"].size(), 3u) << row.dump();
        std::vector<double> medians, exact;
        for (std::size_t k = 0; k < 3; ++k) {
            const nlohmann::json& round = row["rounds"][k];
            medians.push_back(round["ms_per_frame_median"].get<double>());
            exact.push_back(round["ms_per_frame_median_exact_pairs"].get<double>());
            if (row["peer"].get<bool>()) {
                best_ratio[k] = std::min(best_ratio[k], round["ratio_to_best_peer"].get<double>());
            }
        }
        std::sort(medians.begin(), medians.end());
        std::sort(exact.begin(), exact.end());
        EXPECT_EQ(row["ms_per_frame_median"].get<double>(), medians[1]) << row.dump();
        EXPECT_EQ(row["ms_per_frame_median_exact_pairs"].get<double>(), exact[1]) << row.dump();
        EXPECT_EQ(row["frames"], 6) << row.dump();
    }
    for (double ratio : best_ratio) EXPECT_EQ(ratio, 1.0);
    // The progress lines name the methods in the order they ran: A B, then B A, then A B.
    std::vector<std::string> ran;
    std::istringstream err(r.err);
    for (std::string line; std::getline(err, line);) {
        for (const std::string& method : {std::string("sap-packed"), peer}) {
            if (line.find("] " + method + ": ") != std::string::npos) ran.push_back(method);
        }
    }
    const std::vector<std::string> expected{"sap-packed", peer, peer, "sap-packed", "sap-packed",
                                            peer};
    EXPECT_EQ(ran, expected) << r.err;
    EXPECT_NE(r.out.find("(by round: "), std::string::npos) << r.out;
    const Result bad = runCdlab("bench broadphase --sizes 50 --frames 2 --rounds 0", work);
    EXPECT_EQ(bad.exit_code, 2) << bad.out << bad.err;
    EXPECT_NE(bad.err.find("--rounds"), std::string::npos) << bad.err;
    fs::remove_all(work);
}

// A row whose mean frame is far above its median (a DBVT with a wide margin re-inserts rarely,
// at great cost) is ranked by its median like every row, and the report says what the median
// hides; a steady row gets no such note.
TEST(BroadphaseBench, ARowWhoseMeanIsFarAboveItsMedianIsNoted) {
    using app::Row;
    auto row = [](const std::string& method, bool peer, double median_ms, double mean_ms) {
        Row r;
        r.method = method;
        r.peer = peer;
        r.n = 1000;
        r.result.median_ms = median_ms;
        r.result.exact_median_ms = median_ms;
        r.result.mean_ms = mean_ms;
        r.result.frames_run = 100;
        return r;
    };
    std::vector<Row> rows{row("steady", false, 1.0, 1.1), row("spiky", true, 0.5, 7.0)};
    app::BenchOptions options;
    options.frames = 100;
    std::ostringstream out;
    app::reportWorkload(out, rows, options, options.frames);
    const std::string text = out.str();
    EXPECT_NE(text.find("spiky: mean 7.0000 ms/frame is 14.0x its median"), std::string::npos)
        << text;
    EXPECT_EQ(text.find("steady: mean"), std::string::npos) << text;
    EXPECT_DOUBLE_EQ(rows[0].ratio, 2.0);  // still ranked by the median
}

}  // namespace

// sap-packed-loose is held to the Bullet rows' rule: findPairs() leaves its loose list (rawPairs()
// its size, at least the exact count and more once fat boxes are in use), deliverExact() filters
// it, and summary() must equal an independent count of the exact pairs every frame.
TEST(BroadphaseBench, LooseSapPackedFiltersItsCandidatesToTheExactPairs) {
    const app::BenchMethodEntry* entry = app::findBenchMethod("sap-packed-loose");
    ASSERT_NE(entry, nullptr);
    EXPECT_FALSE(entry->peer);
    app::MovingBoxes boxes(app::WorkloadKind::Mixed, 400, 3);
    std::vector<collision::ProxyVolumes> volumes;
    boxes.volumes(volumes);
    std::unique_ptr<app::BenchMethod> method = entry->create();
    method->insertAll(boxes, volumes);
    method->findPairs();
    app::PairReference reference;
    int looser_frames = 0;
    for (int frame = 1; frame <= 60; ++frame) {
        boxes.step();
        boxes.volumes(volumes);
        method->moveAll(boxes, volumes);
        method->findPairs();
        method->deliverExact(boxes);
        const app::PairSummary expected = reference.count(boxes);
        ASSERT_EQ(method->summary(boxes), expected) << "frame " << frame;
        ASSERT_GE(method->rawPairs(), expected.pairs) << "frame " << frame;
        looser_frames += method->rawPairs() > expected.pairs;
    }
    EXPECT_GT(looser_frames, 30);
}
