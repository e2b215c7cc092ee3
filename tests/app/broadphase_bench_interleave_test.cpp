// tests/app/broadphase_bench_interleave_test.cpp -- `cdlab bench broadphase --interleave`: rows
// measured together, in turns, each on its own copy of the workload.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bench_broadphase.h"
#include "bench_method.h"
#include "bench_rows.h"
#include "bench_workload.h"
#include "cli_run.h"

namespace {

namespace fs = std::filesystem;

// A registry method that writes what it is asked to do into a shared log: "A+" when created and
// filled, "A3" when it moves its boxes to frame 3 (the frame it reads from the workload).
class LoggedMethod final : public app::BenchMethod {
public:
    LoggedMethod(std::string name, std::unique_ptr<app::BenchMethod> inner,
                 std::vector<std::string>& log)
        : name_(std::move(name)), inner_(std::move(inner)), log_(log) {}
    void insertAll(const app::MovingBoxes& boxes,
                   std::span<const collision::ProxyVolumes> volumes) override {
        log_.push_back(name_ + "+");
        inner_->insertAll(boxes, volumes);
    }
    void moveAll(const app::MovingBoxes& boxes,
                 std::span<const collision::ProxyVolumes> volumes) override {
        log_.push_back(name_ + std::to_string(boxes.frame()));
        inner_->moveAll(boxes, volumes);
    }
    void findPairs() override { inner_->findPairs(); }
    app::PairSummary summary(const app::MovingBoxes& boxes) override {
        return inner_->summary(boxes);
    }

private:
    std::string name_;
    std::unique_ptr<app::BenchMethod> inner_;
    std::vector<std::string>& log_;
};

app::BenchMethodEntry logged(const std::string& name, const std::string& inner,
                             std::vector<std::string>& log) {
    const app::BenchMethodEntry* real = app::findBenchMethod(inner);
    EXPECT_NE(real, nullptr) << inner;
    app::BenchMethodEntry entry = *real;
    entry.name = name;
    entry.create = [name, real, &log] {
        return std::unique_ptr<app::BenchMethod>(
            std::make_unique<LoggedMethod>(name, real->create(), log));
    };
    return entry;
}

// A table to measure: the uniform workload of n boxes, its reference pairs for `frames` frames,
// and the options (`frames` frames, in-process) and streams of a run of it.
struct Table {
    Table(int n, int frames) : workload(app::WorkloadKind::Uniform, n, 1) {
        app::MovingBoxes boxes = workload;
        app::PairReference sweep;
        reference.push_back(sweep.count(boxes));
        for (int f = 1; f <= frames; ++f) {
            boxes.step();
            reference.push_back(sweep.count(boxes));
        }
        options.frames = frames;
        options.isolate = false;
    }
    app::TableRun run(bool one_shot) {
        return {workload, reference, options, one_shot, out, err, failed};
    }

    app::MovingBoxes workload;
    std::vector<app::PairSummary> reference;
    app::BenchOptions options;
    std::ostringstream out, err;
    bool failed = false;
};

// Moving: every method is created and filled first, then each runs its frames in turns of
// turn_frames, the order reversed every turn, each on its own copy of the workload (every frame
// agrees with the reference); a method that has run all its frames sits out the rest.
TEST(BroadphaseBenchInterleave, MovingRowsRunTheirFramesInTurnsOnTheirOwnWorkload) {
    std::vector<std::string> log;
    const app::BenchMethodEntry a = logged("A", "sap", log);
    const app::BenchMethodEntry b = logged("B", "hgrid", log);
    Table t(300, 5);
    const std::vector<app::RunResult> results = app::measureTogether({&a, &b}, t.run(false), 2);
    const std::vector<std::string> expected{"A+", "B+", "A1", "A2", "B1", "B2",
                                            "B3", "B4", "A3", "A4", "A5", "B5"};
    EXPECT_EQ(log, expected);
    ASSERT_EQ(results.size(), 2u);
    for (const app::RunResult& r : results) {
        EXPECT_EQ(r.failed, 0) << r.note;
        EXPECT_EQ(r.frames_run, 5);
        EXPECT_EQ(r.mismatched_frames, 0);
        EXPECT_EQ(r.pairs_last, t.reference.back().pairs);
        EXPECT_GT(r.median_ms, 0);
    }
    EXPECT_FALSE(t.failed);
}

// One-shot: one repetition (create, fill, find) per turn, alternating A B, B A, ...
TEST(BroadphaseBenchInterleave, OneShotRowsTakeOneRepetitionPerTurn) {
    std::vector<std::string> log;
    const app::BenchMethodEntry a = logged("A", "sap", log);
    const app::BenchMethodEntry b = logged("B", "hgrid", log);
    Table t(300, 0);
    t.options.frames = 3;  // repetitions, each of frame 0
    const std::vector<app::RunResult> results = app::measureTogether({&a, &b}, t.run(true), 7);
    const std::vector<std::string> expected{"A+", "B+", "B+", "A+", "A+", "B+"};
    EXPECT_EQ(log, expected);
    for (const app::RunResult& r : results) {
        EXPECT_EQ(r.frames_run, 3);
        EXPECT_EQ(r.mismatched_frames, 0);
    }
}

// Forked (the default): the results come back from the child in the entries' order, a method
// that disagrees with the reference is reported as such, and one that crashes fails its rows
// with the signal named instead of ending the run.
TEST(BroadphaseBenchInterleave, AForkedRoundReportsEachRowAndSurvivesACrash) {
    Table t(200, 4);
    t.options.isolate = true;
    const app::TableRun run = t.run(false);
    std::vector<std::string> unused;
    const app::BenchMethodEntry good = logged("good", "sap", unused);
    app::BenchMethodEntry wrong = logged("wrong", "sap", unused);
    wrong.create = [] {
        struct Wrong final : app::BenchMethod {
            void insertAll(const app::MovingBoxes&,
                           std::span<const collision::ProxyVolumes>) override {}
            void moveAll(const app::MovingBoxes&,
                         std::span<const collision::ProxyVolumes>) override {}
            void findPairs() override {}
            app::PairSummary summary(const app::MovingBoxes&) override { return {}; }
        };
        return std::unique_ptr<app::BenchMethod>(std::make_unique<Wrong>());
    };
    std::vector<app::RunResult> results = app::measureTogether({&good, &wrong}, run, 1);
    ASSERT_EQ(results.size(), 2u);
    EXPECT_EQ(results[0].failed, 0) << results[0].note;
    EXPECT_EQ(results[0].mismatched_frames, 0);
    EXPECT_EQ(results[0].frames_run, 4);
    EXPECT_EQ(results[1].mismatched_frames, 5);  // frame 0 and the 4 frames
    app::BenchMethodEntry crash = wrong;
    crash.create = []() -> std::unique_ptr<app::BenchMethod> { std::abort(); };
    results = app::measureTogether({&good, &crash}, run, 1);
    ASSERT_EQ(results.size(), 2u);
    for (const app::RunResult& r : results) {
        EXPECT_EQ(r.failed, 1);
        EXPECT_NE(std::string(r.note).find("signal"), std::string::npos) << r.note;
    }
}

// Methods alive at once keep their own settings: Bullet's DBVT margin is one global of Bullet's
// (gDbvtMargin), and two configurations measured together each hold the pair cache that margin
// gives them alone.
TEST(BroadphaseBenchInterleave, PeersMeasuredTogetherKeepTheirOwnSettings) {
    const app::BenchMethodEntry* wide = app::findBenchMethod("bullet-dbvt:m0.3");
    const app::BenchMethodEntry* narrow = app::findBenchMethod("bullet-dbvt:m0.1");
    if (wide == nullptr || narrow == nullptr) GTEST_SKIP() << "built without Bullet";
    Table t(2000, 20);
    const app::TableRun run = t.run(false);
    const std::int64_t wide_alone = app::measureTogether({wide}, run, 5).front().raw_pairs_last;
    const std::int64_t narrow_alone = app::measureTogether({narrow}, run, 5).front().raw_pairs_last;
    ASSERT_GT(wide_alone, narrow_alone);  // the margins differ enough to tell apart
    const std::vector<app::RunResult> together = app::measureTogether({wide, narrow}, run, 5);
    EXPECT_EQ(together[0].raw_pairs_last, wide_alone);
    EXPECT_EQ(together[1].raw_pairs_last, narrow_alone);
    for (const app::RunResult& r : together) EXPECT_EQ(r.mismatched_frames, 0);
}

// The command: after the first pass, --rounds rounds measured together; each row reports those
// rounds, its figures their medians, and the JSON says how it was measured.
TEST(BroadphaseBenchInterleave, InterleavedRoundsAreTheRowsFigures) {
    const fs::path work = cdlab_test::tempDir("cdlab_bp_interleave_", "rounds");
    const fs::path json = work / "rounds.json";
    const cdlab_test::CliResult r = cdlab_test::runCdlab(
        "bench broadphase --sizes 200 --frames 6 --workload uniform --rounds 3 --interleave 2 "
        "--methods sap,hgrid --json " +
            json.string(),
        work);
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("timed 3 more times measured together"), std::string::npos) << r.out;
    for (int round = 1; round <= 3; ++round) {
        EXPECT_NE(
            r.err.find("] round " + std::to_string(round) + " of 3, 2 rows measured together"),
            std::string::npos)
            << r.err;
    }
    std::ifstream in(json);
    const nlohmann::json doc = nlohmann::json::parse(in);
    EXPECT_EQ(doc["interleave"], 2);
    EXPECT_EQ(doc["rounds"], 3);
    ASSERT_EQ(doc["rows"].size(), 2u);
    for (const nlohmann::json& row : doc["rows"]) {
        ASSERT_EQ(row["rounds"].size(), 3u) << row.dump();
        std::vector<double> medians;
        for (const nlohmann::json& round : row["rounds"]) {
            medians.push_back(round["ms_per_frame_median"].get<double>());
        }
        std::sort(medians.begin(), medians.end());
        EXPECT_EQ(row["ms_per_frame_median"].get<double>(), medians[1]) << row.dump();
        EXPECT_EQ(row["frames"], 6) << row.dump();
    }
    for (const char* bad : {"-1", "1001"}) {
        const cdlab_test::CliResult b = cdlab_test::runCdlab(
            std::string("bench broadphase --sizes 50 --frames 2 --interleave ") + bad, work);
        EXPECT_EQ(b.exit_code, 2) << bad << b.out << b.err;
        EXPECT_NE(b.err.find("--interleave"), std::string::npos) << b.err;
    }
    fs::remove_all(work);
}

}  // namespace
