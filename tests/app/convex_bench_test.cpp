// `cdlab bench convex` end to end on a few queries: every workload row present, the JSON
// complete, no failed query, cdlab's depth, normal and witnesses exact against the long-double
// reference, and (when Bullet is built in) each row run by the Bullet path it names, with
// Bullet's closed forms agreeing with the reference (so the conventions of the comparison hold);
// a bad option gets exit code 2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "cli_run.h"

namespace {

namespace fs = std::filesystem;
using Result = cdlab_test::CliResult;
using cdlab_test::runCdlab;
using cdlab_test::slurp;

fs::path convexBenchDir(const std::string& name) { return cdlab_test::tempDir("cdlab_convex_bench_", name); }

TEST(ConvexBench, FewQueriesNoMismatchAndCompleteJson) {
    const fs::path work = convexBenchDir("smoke");
    const fs::path json = work / "convex.json";
    const Result r =
        runCdlab("bench convex --queries 200 --passes 1 --json " + json.string(), work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* column : {"workload", "bullet_path", "cdlab_us", "bullet_us", "cdlab_err",
                               "bullet_err", "bullet_nrm", "cdlab_ext"}) {
        EXPECT_NE(r.out.find(column), std::string::npos) << column;
    }
    ASSERT_TRUE(fs::exists(json));
    EXPECT_FALSE(fs::exists(json.string() + ".partial"));
    const nlohmann::json doc = nlohmann::json::parse(slurp(json));
    ASSERT_EQ(doc["rows"].size(), 14u);
    const bool bullet = doc["bullet"].get<bool>();
    std::set<std::string> paths;
    int separated_rows = 0;
    int penetrating_rows = 0;
    for (const nlohmann::json& row : doc["rows"]) {
        const std::string name = row["workload"].get<std::string>();
        EXPECT_EQ(row["queries"].get<int>(), 200) << name;
        EXPECT_EQ(row["cdlab_failed"].get<int>(), 0) << name;
        EXPECT_GT(row["cdlab_us"].get<double>(), 0) << name;
        const nlohmann::json& ours = row["cdlab_accuracy"];
        EXPECT_EQ(ours["wrong"].get<int>(), 0) << name;
        EXPECT_LE(ours["depth_error"].get<double>(), 1e-12) << name;
        EXPECT_LE(ours["witness_error"].get<double>(), 1e-12) << name;
        EXPECT_LE(ours["normal_error"].get<double>(), 1e-9) << name;
        // cdlab's answers survive translation by 1e6 and scaling by 1e-4 / 1e4 (relative to size).
        EXPECT_EQ(row["cdlab_variant_failed"].get<int>(), 0) << name;
        for (const char* key : {"cdlab_far_error", "cdlab_small_error", "cdlab_large_error"}) {
            EXPECT_LE(row[key].get<double>(), 1e-9) << name << " " << key;
        }
        if (name.find("separated") != std::string::npos) {
            EXPECT_EQ(row["colliding"].get<int>(), 0) << name;
            ++separated_rows;
        }
        if (name.find("penetrating") != std::string::npos) {
            EXPECT_EQ(row["colliding"].get<int>(), 200) << name;
            ++penetrating_rows;
        }
        if (bullet) {
            const std::string path = row["bullet_path"].get<std::string>();
            paths.insert(path);
            EXPECT_EQ(row["bullet_failed"].get<int>(), 0) << name << " " << path;
            if (name.rfind("sphere-sphere", 0) == 0) {
                const nlohmann::json& theirs = row["bullet_accuracy"];
                EXPECT_EQ(theirs["wrong"].get<int>(), 0) << name << " " << path;
                EXPECT_LE(theirs["normal_error"].get<double>(), 1e-9) << name << " " << path;
                EXPECT_LE(theirs["witness_error"].get<double>(), 1e-9) << name << " " << path;
            }
        }
    }
    EXPECT_EQ(separated_rows, 2);
    EXPECT_EQ(penetrating_rows, 8);
    if (bullet) {
        for (const char* path : {"btBoxBoxDetector", "btSphereSphere", "capsuleCapsuleDistance",
                                 "btConvexConvex(GJK+EPA)", "btSphereBox(disabled)",
                                 "btGjkPairDetector+EPA"}) {
            EXPECT_EQ(paths.count(path), 1u) << path;
        }
    }
    fs::remove_all(work);
}

TEST(ConvexBench, WorkloadOptionSelectsRowsByName) {
    const fs::path work = convexBenchDir("select");
    const fs::path json = work / "convex.json";
    const Result r = runCdlab(
        "bench convex --queries 20 --passes 1 --workload sphere-sphere --json " + json.string(),
        work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json doc = nlohmann::json::parse(slurp(json));
    ASSERT_EQ(doc["rows"].size(), 2u);
    for (const nlohmann::json& row : doc["rows"]) {
        EXPECT_EQ(row["workload"].get<std::string>().rfind("sphere-sphere", 0), 0u);
    }
    const Result none = runCdlab("bench convex --queries 20 --workload cone-cone", work);
    EXPECT_EQ(none.exit_code, 2);
    EXPECT_NE(none.err.find("cone-cone"), std::string::npos) << none.err;
    fs::remove_all(work);
}

TEST(ConvexBench, BadOptionExitsTwo) {
    const fs::path work = convexBenchDir("bad");
    const Result r = runCdlab("bench convex --queries 0", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--queries"), std::string::npos) << r.err;
    fs::remove_all(work);
}

}  // namespace
