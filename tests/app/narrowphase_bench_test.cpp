// `cdlab bench narrowphase` end to end on small tori: table and JSON fields, every cdlab volume
// type agrees with the brute force on every pose, half the poses collide; bad options exit 2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench_narrowphase.h"
#include "cli_run.h"
#include "collision/bvh/bvh.h"

namespace {

namespace fs = std::filesystem;
using Result = cdlab_test::CliResult;
using cdlab_test::runCdlab;
using cdlab_test::slurp;

fs::path npBenchDir(const std::string& name) { return cdlab_test::tempDir("cdlab_np_bench_", name); }

TEST(NarrowphaseBench, SmallToriTableAndJsonAgreeWithBruteForce) {
    const fs::path work = npBenchDir("small");
    const fs::path json = work / "np.json";
    const Result r = runCdlab(
        "bench narrowphase --triangles 600 --poses 6 --reps 1 --json " + json.string(), work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("first_us"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Cv_ns"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Nu"), std::string::npos) << r.out;
    const nlohmann::json j = nlohmann::json::parse(slurp(json));
    EXPECT_EQ(j["poses"], 6);
    EXPECT_EQ(j["colliding_poses"], 3);
    EXPECT_GE(j["triangles"].get<int>(), 500);
    int cdlab_rows = 0;
    for (const auto& row : j["rows"]) {
        for (const char* key :
             {"method", "build_ms", "first_us", "all_us", "bool_mismatches", "pair_mismatches"}) {
            EXPECT_TRUE(row.contains(key)) << key;
        }
        if (row["library"] == "cdlab") {
            ++cdlab_rows;
            EXPECT_EQ(row["bool_mismatches"], 0) << row["method"];
            EXPECT_EQ(row["pair_mismatches"], 0) << row["method"];
            EXPECT_GT(row["all_nv"].get<double>(), 0) << row["method"];
            EXPECT_GT(row["all_np"].get<double>(), 0) << row["method"];
            // Cv and Cp measured on batches of at least 2e5 and 1e5 tests drawn from the
            // queries' own tests (some poses collide, so triangle tests exist); none for the
            // wide tree (WideObbTreeRunsByNameAndAgreesWithBruteForce).
            if (row["method"] == "obb4") {
                EXPECT_TRUE(row["bv_test_ns"].is_null());
            } else {
                EXPECT_GT(row["bv_test_ns"].get<double>(), 0) << row["method"];
                EXPECT_GT(row["triangle_test_ns"].get<double>(), 0) << row["method"];
                EXPECT_GE(row["bv_tests_timed"].get<std::int64_t>(), 200000) << row["method"];
                EXPECT_GE(row["triangle_tests_timed"].get<std::int64_t>(), 100000)
                    << row["method"];
                EXPECT_TRUE(row["triangle_tests_from_queries"].get<bool>()) << row["method"];
            }
            // Refit updates every node of a one-triangle-leaf tree (2 n - 1) and still answers
            // as the brute force on the deformed torus.
            EXPECT_EQ(row["refit_nu"].get<int>(), 2 * j["triangles"].get<int>() - 1)
                << row["method"];
            EXPECT_TRUE(row["refit_ok"].get<bool>()) << row["method"];
            EXPECT_GT(row["refit_ms"].get<double>(), 0) << row["method"];
        }
    }
    EXPECT_EQ(cdlab_rows, static_cast<int>(collision::bvhVolumeNames().size()));
}

TEST(NarrowphaseBench, BottomUpBuildsAreCheckedToo) {
    const fs::path work = npBenchDir("bu");
    const fs::path json = work / "np.json";
    const Result r = runCdlab(
        "bench narrowphase --triangles 600 --poses 4 --reps 1 --methods "
        "obb-bu,aabb-bu,obb --json " +
            json.string(),
        work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(slurp(json));
    ASSERT_EQ(j["rows"].size(), 3u);
    EXPECT_EQ(j["rows"][0]["method"], "obb-bu");
    for (const auto& row : j["rows"]) {
        EXPECT_EQ(row["library"], "cdlab");
        EXPECT_EQ(row["pair_mismatches"], 0) << row["method"];
    }
}

// The wide OBB tree runs by name, answers as the brute force at every pose (and after the
// refit), and has no unit costs (null in JSON, "-" in the table, with the reason): the replay
// times single node-pair tests, the wide tree tests four boxes at once.
TEST(NarrowphaseBench, WideObbTreeRunsByNameAndAgreesWithBruteForce) {
    const fs::path work = npBenchDir("wide");
    const fs::path json = work / "np.json";
    const Result r = runCdlab(
        "bench narrowphase --triangles 600 --poses 6 --reps 1 --methods obb4,obb --json " +
            json.string(),
        work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(slurp(json));
    ASSERT_EQ(j["rows"].size(), 2u);
    const auto& wide = j["rows"][0];
    EXPECT_EQ(wide["method"], "obb4");
    EXPECT_EQ(wide["bool_mismatches"], 0);
    EXPECT_EQ(wide["pair_mismatches"], 0);
    EXPECT_TRUE(wide["refit_ok"].get<bool>());
    EXPECT_TRUE(wide["bv_test_ns"].is_null());
    EXPECT_TRUE(wide["triangle_test_ns"].is_null());
    EXPECT_GT(j["rows"][1]["bv_test_ns"].get<double>(), 0);  // obb's are measured
    EXPECT_NE(r.out.find("not measured: obb4"), std::string::npos) << r.out;
    EXPECT_GT(wide["all_nv"].get<double>(), 0);
    EXPECT_GT(wide["all_np"].get<double>(), 0);
}

// Every FCL row runs the path an FCL user gets (one object per mesh, setTransform per query;
// RSS through FCL's RSS traversal node) and any of FCL's split rules by suffix, and answers as
// the brute force does on every pose.
TEST(NarrowphaseBench, FclRowsTakeSplitRulesAndAgreeWithBruteForce) {
    const auto& names = app::narrowphaseBenchMethods();
    if (std::find(names.begin(), names.end(), "fcl-obb") == names.end()) {
        GTEST_SKIP() << "built without FCL";
    }
    const fs::path work = npBenchDir("fcl");
    const fs::path json = work / "np.json";
    const Result r = runCdlab(
        "bench narrowphase --triangles 600 --poses 6 --reps 1 --methods "
        "fcl-obb,fcl-rss,fcl-obb-median,fcl-kios-center --json " +
            json.string(),
        work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(slurp(json));
    ASSERT_EQ(j["rows"].size(), 4u);
    EXPECT_EQ(j["rows"][2]["method"], "fcl-obb-median");
    for (const auto& row : j["rows"]) {
        EXPECT_EQ(row["library"], "fcl");
        EXPECT_EQ(row["bool_mismatches"], 0) << row["method"];
    }
}

// With rounds, every method is measured once per round (in order, then in reverse) and each
// time reported is the median of its rounds' times; answers are checked in every round.
TEST(NarrowphaseBench, RoundsReportTheMedianOfEachRoundsTimes) {
    const fs::path work = npBenchDir("rounds");
    const fs::path json = work / "np.json";
    const Result r = runCdlab("bench narrowphase --triangles 600 --poses 2 --reps 1 --rounds 3 "
                              "--methods obb,aabb --json " +
                                  json.string(),
                              work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("median of 3 rounds"), std::string::npos) << r.out;
    const nlohmann::json j = nlohmann::json::parse(slurp(json));
    EXPECT_EQ(j["rounds"], 3);
    ASSERT_EQ(j["rows"].size(), 2u);
    for (const auto& row : j["rows"]) {
        EXPECT_EQ(row["bool_mismatches"], 0) << row["method"];
        EXPECT_EQ(row["pair_mismatches"], 0) << row["method"];
        for (const char* key : {"build_ms", "first_us", "all_us"}) {
            std::vector<double> times = row[std::string(key) + "_by_round"];
            ASSERT_EQ(times.size(), 3u) << row["method"] << ' ' << key;
            std::sort(times.begin(), times.end());
            EXPECT_EQ(row[key].get<double>(), times[1]) << row["method"] << ' ' << key;
        }
    }
}

TEST(NarrowphaseBench, BadOptionsExitTwo) {
    const fs::path work = npBenchDir("bad");
    Result r = runCdlab("bench narrowphase --poses 3", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--poses"), std::string::npos) << r.err;
    for (const char* rounds : {"0", "51"}) {
        r = runCdlab(std::string("bench narrowphase --poses 2 --rounds ") + rounds, work);
        EXPECT_EQ(r.exit_code, 2) << rounds;
        EXPECT_NE(r.err.find("--rounds must be in 1..50"), std::string::npos) << r.err;
    }
    r = runCdlab("bench narrowphase --methods obb,octree --poses 2", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("unknown method 'octree'"), std::string::npos) << r.err;
    r = runCdlab("bench narrowphase --triangles 600 --poses 2 --reps 1 --methods obb --json " +
                     (work / "no" / "such" / "dir.json").string(),
                 work);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("cannot write"), std::string::npos) << r.err;
}

}  // namespace
