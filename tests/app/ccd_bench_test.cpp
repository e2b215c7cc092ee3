// `cdlab bench ccd` end to end on the small unit-tests query set: table and JSON fields, zero
// false negatives for the conservative method; malformed input gets file:line:col and exit 2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "bench_ccd.h"
#include "bench_ccd_peer.h"
#include "cli_run.h"

namespace {

namespace fs = std::filesystem;
using Result = cdlab_test::CliResult;
using cdlab_test::runCdlab;
using cdlab_test::slurp;

fs::path ccdBenchDir(const std::string& name) { return cdlab_test::tempDir("cdlab_ccd_bench_", name); }

// From a working directory other than the repository's root, the defaults still find the query
// sets and the tunnelling scenes (in the source tree the program was built from): the full
// table, the tunnelling table, nothing silently dropped.
TEST(CcdBench, DefaultsWorkOutsideTheRepositoryRoot) {
    const fs::path work = ccdBenchDir("elsewhere");
    const Result r = runCdlab("bench ccd --method conservative", work, "", work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("conservative all"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("erleben-spikes"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("tunnel_bar"), std::string::npos) << r.out;
    EXPECT_EQ(r.err.find("skipped"), std::string::npos) << r.err;
}

TEST(CcdBench, UnitTestSetTableAndJsonWithNoFalseNegatives) {
    const fs::path work = ccdBenchDir("unit");
    const fs::path json = work / "ccd.json";
    const Result r = runCdlab(
        "bench ccd tests/data/ccd-sample-queries/unit-tests --json " + json.string(), work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* column :
         {"method", "set", "kind", "queries", "FN", "FP", "mean_us", "median_us", "p99_us"}) {
        EXPECT_NE(r.out.find(column), std::string::npos) << column;
    }
    EXPECT_NE(r.out.find("conservative"), std::string::npos);
    EXPECT_NE(r.out.find("naive"), std::string::npos);
    ASSERT_TRUE(fs::exists(json));
    EXPECT_FALSE(fs::exists(json.string() + ".partial"));
    const nlohmann::json doc = nlohmann::json::parse(slurp(json));
    ASSERT_TRUE(doc.contains("rows"));
    int conservative_rows = 0;
    int naive_false_negatives = 0;
    for (const nlohmann::json& row : doc["rows"]) {
        for (const char* key :
             {"method", "set", "kind", "queries", "false_negatives", "false_positives", "failed",
              "inexact_inputs", "mean_us", "median_us", "p99_us"}) {
            EXPECT_TRUE(row.contains(key)) << key;
        }
        EXPECT_GE(row["p99_us"].get<double>(), row["median_us"].get<double>());
        EXPECT_GE(row["max_us"].get<double>(), row["p99_us"].get<double>());
        if (row["set"] != "unit-tests") continue;
        const int queries = row["queries"].get<int>();
        EXPECT_EQ(queries, row["kind"] == "vertex-face" ? 250 : 74);
        EXPECT_EQ(row["inexact_inputs"].get<int>(), 0);
        if (row["method"] == "conservative") {
            ++conservative_rows;
            EXPECT_EQ(row["false_negatives"].get<int>(), 0) << row.dump();
        } else {
            naive_false_negatives += row["false_negatives"].get<int>();
        }
    }
    EXPECT_EQ(conservative_rows, 2);
    // The tunnelling scenes, off vs on: the stage does nothing when off and acts when on.
    ASSERT_TRUE(doc.contains("scenes"));
    ASSERT_EQ(doc["scenes"].size(), 4u);
    for (const nlohmann::json& row : doc["scenes"]) {
        for (const char* key : {"scene", "ccd", "frames", "step_us_per_frame", "ccd_us_per_frame",
                                "toi_queries_per_frame", "toi_events"}) {
            EXPECT_TRUE(row.contains(key)) << key;
        }
        if (row["ccd"] == "off") {
            EXPECT_EQ(row["toi_events"].get<int>(), 0);
            EXPECT_EQ(row["toi_queries_per_frame"].get<double>(), 0.0);
            EXPECT_EQ(row["ccd_us_per_frame"].get<double>(), 0.0);
        } else {
            EXPECT_EQ(row["ccd"], "conservative_advancement");
            EXPECT_GT(row["toi_events"].get<int>(), 0) << row.dump();
        }
    }
    // Sphere pairs of scenes/ccd_spheres.yaml: the exact root needs one iteration per query
    // and stops no later than the advancement (both at the target gap, to rounding).
    ASSERT_TRUE(doc.contains("sphere_pairs"));
    ASSERT_EQ(doc["sphere_pairs"].size(), 2u);
    const nlohmann::json& advance = doc["sphere_pairs"][0];
    const nlohmann::json& exact = doc["sphere_pairs"][1];
    EXPECT_EQ(advance["ccd_spheres"], "advancement");
    EXPECT_EQ(exact["ccd_spheres"], "exact");
    EXPECT_EQ(exact["toi_iterations"].get<int>(), exact["toi_queries"].get<int>());
    EXPECT_GT(advance["toi_iterations"].get<int>(), advance["toi_queries"].get<int>());
    EXPECT_GT(exact["first_toi_s"].get<double>(), 0.0);
    EXPECT_NEAR(exact["first_toi_s"].get<double>(), advance["first_toi_s"].get<double>(), 1e-12);
    EXPECT_NE(r.out.find("ccd_us/frame"), std::string::npos);
    // Measured: the naive cubic misses 5 of the unit-test edge-edge contacts.
    EXPECT_GT(naive_false_negatives, 0);
}

TEST(CcdBench, MethodFilterAndBadInput) {
    const fs::path work = ccdBenchDir("bad");
    const Result only =
        runCdlab("bench ccd tests/data/ccd-sample-queries/unit-tests --method naive --no-scenes",
                 work);
    ASSERT_EQ(only.exit_code, 0) << only.err;
    EXPECT_EQ(only.out.find("conservative"), std::string::npos);

    const Result method = runCdlab("bench ccd --method fastest", work);
    EXPECT_EQ(method.exit_code, 2);

    const Result no_scenes = runCdlab(
        "bench ccd tests/data/ccd-sample-queries/unit-tests --method naive --scenes " +
            (work / "nope").string(),
        work);
    EXPECT_EQ(no_scenes.exit_code, 2);
    EXPECT_NE(no_scenes.err.find("no tunnel_sphere.yaml"), std::string::npos) << no_scenes.err;

    const Result missing = runCdlab("bench ccd " + (work / "nope").string(), work);
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_NE(missing.err.find("not a directory"), std::string::npos) << missing.err;

    // A malformed CSV: the message names file, line and column.
    const fs::path dir = work / "broken" / "vertex-face";
    fs::create_directories(dir);
    {
        std::ofstream f(dir / "data.csv");
        for (int i = 0; i < 7; ++i) f << "0,1,0,1,0,1,0\n";
        f << "0,1,x,1,0,1,0\n";
    }
    std::ostringstream out, err;
    app::BenchCcdOptions options;
    options.dirs = {work / "broken"};
    EXPECT_EQ(app::runBenchCcd(options, out, err), 2);
    EXPECT_NE(err.str().find("data.csv:8:5: not an integer"), std::string::npos) << err.str();
}

// Tight-Inclusion is a peer only when the build found an installed copy: then its rows and the
// ratio lines appear (with its own FN/FP counts); without it, asking for it is an error that
// says what to configure, and `all` says so once on stderr and runs the rest.
TEST(CcdBench, TightInclusionPeerWhenBuiltInElseAClearNote) {
    const fs::path work = ccdBenchDir("peer");
    const std::string set = "bench ccd tests/data/ccd-sample-queries/unit-tests --no-scenes";
    const Result all = runCdlab(set, work);
    ASSERT_EQ(all.exit_code, 0) << all.err;
    if (app::tightInclusionBuiltIn()) {
        EXPECT_NE(all.out.find("tight-inclusion unit-tests"), std::string::npos) << all.out;
        EXPECT_NE(all.out.find("conservative / tight-inclusion"), std::string::npos) << all.out;
        EXPECT_EQ(all.err.find("not found"), std::string::npos) << all.err;
    } else {
        const Result peer = runCdlab(set + " --method tight-inclusion", work);
        EXPECT_EQ(peer.exit_code, 2);
        EXPECT_NE(peer.err.find("Tight-Inclusion: not found"), std::string::npos) << peer.err;
        EXPECT_NE(peer.err.find("CDLAB_TIGHT_INCLUSION_ROOT"), std::string::npos) << peer.err;
        EXPECT_NE(all.err.find("Tight-Inclusion: not found"), std::string::npos) << all.err;
        EXPECT_EQ(all.out.find("tight-inclusion"), std::string::npos) << all.out;
    }
    std::ostringstream out, err;
    app::BenchCcdOptions options;
    options.dirs = {fs::path(CDLAB_SOURCE_DIR) / "tests/data/ccd-sample-queries/unit-tests"};
    options.reps = 0;
    EXPECT_EQ(app::runBenchCcd(options, out, err), 2);
    EXPECT_NE(err.str().find("--reps"), std::string::npos) << err.str();
}

}  // namespace
