// tests/app/pair_order_cli_test.cpp -- the pair order a user can choose (`--pair-order`, scene
// key `pair_order`, bench rows `hgrid:found`): runs in found order are bit-identical to each
// other and write the same frames, trace and pause dumps as sorted order; the checks that look
// pairs up (--check-broadphase, expect: pairs) hold in found order; bad values exit 2.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "check.h"
#include "cli_run.h"
#include "engine/scene.h"

namespace {

namespace fs = std::filesystem;
using Result = cdlab_test::CliResult;
using cdlab_test::runCdlab;
using cdlab_test::slurp;

fs::path orderDir(const std::string& name) { return cdlab_test::tempDir("cdlab_order_", name); }

// scenes/crowd.yaml (1,500 bodies, hgrid) for 3 frames, checked against brute force every
// step, with a trace and a pause dump: twice in found order and once sorted.
TEST(PairOrderCli, CrowdInFoundOrderIsBitIdenticalAndWritesWhatSortedOrderWrites) {
    const fs::path work = orderDir("crowd");
    for (const char* run : {"found_a", "found_b", "sorted"}) {
        const std::string order = std::string(run).starts_with("found") ? "found" : "sorted";
        const fs::path out = work / run;
        const Result r = runCdlab(
            "run scenes/crowd.yaml --frames 3 --no-video --no-hud-timing "
            "--quiet --check-broadphase --pause-at 2 --pair-order " +
                order + " --trace " + (out / "trace.jsonl").string() + " --out " + out.string(),
            work);
        ASSERT_EQ(r.exit_code, 0) << run << ": " << r.err;
        if (order == "found") {
            EXPECT_NE(r.out.find("pairs in found order"), std::string::npos) << r.out;
        }
        const nlohmann::json summary = nlohmann::json::parse(slurp(out / "summary.json"));
        EXPECT_EQ(summary["pair_order"], order);
    }
    const auto same = [&](const std::string& file) {
        const std::string a = slurp(work / "found_a" / file);
        EXPECT_FALSE(a.empty()) << file;
        // EXPECT_TRUE, not EXPECT_EQ: gtest's line diff of two multi-megabyte texts that
        // differ would need gigabytes.
        EXPECT_TRUE(a == slurp(work / "found_b" / file)) << file << ": found order, run twice";
        EXPECT_TRUE(a == slurp(work / "sorted" / file)) << file << ": found against sorted";
    };
    for (int f = 0; f < 3; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%05d.png", f);
        same(name);
    }
    same("trace.jsonl");
    same("pause_2.json");
    const auto hash = [&](const char* run) {
        return nlohmann::json::parse(slurp(work / run / "summary.json"))["state_hash"];
    };
    EXPECT_EQ(hash("found_a"), hash("sorted"));
    // The trace lists pairs, or the comparison above proves little.
    EXPECT_NE(slurp(work / "sorted" / "trace.jsonl").find("\"colliding_pairs\":[["),
              std::string::npos);
    fs::remove_all(work);
}

TEST(PairOrderCli, BadValuesExit2WithAMessage) {
    const fs::path work = orderDir("bad");
    const std::string tiny = "tests/data/tiny.yaml";
    Result r = runCdlab(
        "run " + tiny + " --pair-order unsorted --no-video --out " + (work / "o").string(), work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--pair-order: unknown pair order 'unsorted' (expected one of: sorted, "
                         "found)"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(work / "o" / "frame_00000.png"));
    r = runCdlab("run " + tiny + " --pair-order '' --no-video --out " + (work / "o").string(),
                 work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--pair-order: must not be empty"), std::string::npos) << r.err;
    r = runCdlab("run --help", work);
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("--pair-order"), std::string::npos) << r.out;
    // A broad phase without an order of its own has no found row in the bench.
    r = runCdlab("bench broadphase --sizes 50 --frames 2 --methods sap:found", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("unknown method 'sap:found'"), std::string::npos) << r.err;
    fs::remove_all(work);
}

// Four tori in a row along x, each cutting through its neighbours, numbered from +x down, so
// hgrid meets (2, 3) first and (0, 1) last: the confirmed pairs come unsorted, and the pair
// expectations (looked up by body pair) still hold, and fail where they should.
TEST(PairOrderCli, PairExpectationsHoldInFoundOrder) {
    std::string text =
        "world: {bounds: {min: [-6, -4, -4], max: [6, 4, 4]}, frames: 3}\n"
        "broadphase: hgrid\n"
        "pair_order: found\n"
        "bodies:\n";
    int i = 0;
    for (const char* x : {"2.4", "0.8", "-0.8", "-2.4"}) {
        text += "  - {name: t" + std::to_string(i++) +
                ", shape: mesh, file: ../assets/torus.obj, position: [" + x + ", 0, 0]}\n";
    }
    text +=
        "expect:\n"
        "  broadphases: [hgrid]\n"
        "  pairs:\n"
        "    - {a: t0, b: t1, frames: [0, 2], colliding: true}\n"
        "    - {a: t1, b: t2, frames: [0, 2], colliding: true}\n"
        "    - {a: t3, b: t2, frames: [0, 2], colliding: true}\n"
        "    - {a: t0, b: t2, frames: [0, 2], flagged: false}\n";
    const fs::path scenes = fs::path(CDLAB_SOURCE_DIR) / "scenes";
    const fs::path dir = orderDir("tori");
    engine::Scene scene = engine::parseScene(text, "t.yaml", scenes);
    ASSERT_EQ(scene.world.pair_order, collision::PairOrder::Found);
    for (const app::CheckRow& r : app::checkScene(scene, 3, dir)) {
        EXPECT_TRUE(r.pass) << r.expectation << ": " << r.reason;
    }
    // And a false expectation still fails: (t0, t3) are apart.
    text += "    - {a: t0, b: t3, frames: [0, 2], flagged: true}\n";
    scene = engine::parseScene(text, "t.yaml", scenes);
    int failed = 0;
    for (const app::CheckRow& r : app::checkScene(scene, 3, dir)) failed += !r.pass;
    EXPECT_EQ(failed, 1);
    fs::remove_all(dir);
}

// hgrid:found in the bench: the same pairs as hgrid (checked on every frame against the
// reference), one-shot and moving.
TEST(PairOrderCli, BenchRowsInFoundOrderFindTheSamePairs) {
    const fs::path work = orderDir("bench");
    const fs::path json = work / "bp.json";
    const Result r = runCdlab(
        "bench broadphase --workload boxpruning --sizes 3000 --frames 4 "
        "--methods hgrid,hgrid:found --json " +
            json.string(),
        work);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    const nlohmann::json doc = nlohmann::json::parse(slurp(json));
    ASSERT_EQ(doc["rows"].size(), 4u);
    int found_rows = 0;
    std::map<std::string, std::set<std::int64_t>> pairs_by_workload;
    for (const nlohmann::json& row : doc["rows"]) {
        EXPECT_EQ(row["mismatched_frames"], 0) << row.dump();
        found_rows += row["method"] == "hgrid:found";
        pairs_by_workload[row["workload"]].insert(row["pairs"].get<std::int64_t>());
    }
    EXPECT_EQ(found_rows, 2);
    EXPECT_EQ(pairs_by_workload.size(), 2u);
    for (const auto& [workload, pairs] : pairs_by_workload) EXPECT_EQ(pairs.size(), 1u) << workload;
    fs::remove_all(work);
}

}  // namespace
