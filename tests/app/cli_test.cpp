// End-to-end: the cdlab binary writes frames, the video, pause dumps and a summary; bad input
// gets a precise message and exit code 2; output failures a message and a non-zero exit.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct Result {
    int exit_code = -1;
    std::string out;
    std::string err;
};

std::string slurp(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

fs::path tempDir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() / ("cdlab_cli_" + name + "_" +
                                                    std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

Result runCdlab(const std::string& args, const fs::path& work) {
    const fs::path out = work / "stdout.txt";
    const fs::path err = work / "stderr.txt";
    const std::string cmd = std::string("cd ") + CDLAB_SOURCE_DIR + " && " + CDLAB_BINARY + " " +
                            args + " > " + out.string() + " 2> " + err.string() + " < /dev/null";
    const int status = std::system(cmd.c_str());
    Result r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

bool haveFfmpeg() { return std::system("ffmpeg -version > /dev/null 2>&1") == 0; }

const std::string kTiny = "tests/data/tiny.yaml";

TEST(Cli, RunWritesFramesVideoPauseDumpsAndSummary) {
    const fs::path work = tempDir("run");
    const fs::path out = work / "out";
    const bool video = haveFfmpeg();
    const Result r = runCdlab("run " + kTiny + " --out " + out.string() +
                                  " --pause-at 0 --pause-at 3" + (video ? "" : " --no-video"),
                              work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (int f = 0; f < 6; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%05d.png", f);
        EXPECT_GT(fs::file_size(out / name), 100u) << name;
    }
    EXPECT_FALSE(fs::exists(out / "frame_00006.png"));
    if (video) {
        EXPECT_GT(fs::file_size(out / "tiny.mp4"), 1000u);
    }
    EXPECT_TRUE(fs::exists(out / "pause_0.png"));
    EXPECT_TRUE(fs::exists(out / "pause_3.png"));

    const nlohmann::json p0 = nlohmann::json::parse(slurp(out / "pause_0.json"));
    EXPECT_EQ(p0["frame"], 0);
    EXPECT_EQ(p0["time"], 0.0);
    EXPECT_EQ(p0["broadphase"], "sap");
    ASSERT_EQ(p0["bodies"].size(), 5u);
    const nlohmann::json& left = p0["bodies"][0];
    EXPECT_EQ(left["name"], "left");
    EXPECT_EQ(left["shape"], "sphere");
    EXPECT_EQ(left["position"][0], -0.45);
    EXPECT_EQ(left["orientation_wxyz"].size(), 4u);
    EXPECT_NEAR(left["sphere"]["radius"].get<double>(), 0.5, 1e-9);
    EXPECT_EQ(left["aabb"]["min"].size(), 3u);
    EXPECT_EQ(left["obb"]["axes"].size(), 3u);
    // The two spheres overlap at load time: a confirmed pair, both bodies "colliding".
    EXPECT_EQ(left["state"], "colliding");
    EXPECT_EQ(p0["bodies"][4]["state"], "apart");
    bool found = false;
    for (const auto& pair : p0["colliding_pairs"]) found |= pair == nlohmann::json({0, 1});
    EXPECT_TRUE(found) << p0["colliding_pairs"];
    for (const char* key : {"flagged_pairs", "colliding_pairs"}) {
        for (const auto& pair : p0[key]) EXPECT_LT(pair[0].get<int>(), pair[1].get<int>());
    }
    EXPECT_GE(p0["flagged_pairs"].size(), p0["colliding_pairs"].size());

    const nlohmann::json p3 = nlohmann::json::parse(slurp(out / "pause_3.json"));
    EXPECT_EQ(p3["frame"], 3);
    EXPECT_NEAR(p3["time"].get<double>(), 3 * 0.02, 1e-12);

    const nlohmann::json summary = nlohmann::json::parse(slurp(out / "summary.json"));
    EXPECT_EQ(summary["frames"], 6);
    EXPECT_EQ(summary["bodies"], 5);
    fs::remove_all(work);
}

TEST(Cli, SameSceneGivesBitIdenticalFramesAndState) {
    const fs::path work = tempDir("determinism");
    for (const char* run : {"a", "b"}) {
        const Result r = runCdlab("run " + kTiny + " --no-video --no-hud-timing --out " +
                                      (work / run).string(),
                                  work);
        ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    for (int f = 0; f < 6; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%05d.png", f);
        EXPECT_EQ(slurp(work / "a" / name), slurp(work / "b" / name)) << name;
    }
    const auto hash = [&](const char* run) {
        return nlohmann::json::parse(slurp(work / run / "summary.json"))["state_hash"];
    };
    EXPECT_EQ(hash("a"), hash("b"));
    fs::remove_all(work);
}

TEST(Cli, BadSceneReportsFileLineColumnAndExits2) {
    const fs::path work = tempDir("bad");
    const fs::path scene = work / "bad.yaml";
    std::ofstream(scene) << "world:\n  bounds: {min: [-1, -1, -1], max: [1, 1, 1]}\n"
                            "bodies:\n  - shape: sphere\n    radius: -2\n    position: [0, 0, 0]\n";
    const Result r = runCdlab("run " + scene.string() + " --no-video --out " +
                                  (work / "out").string(),
                              work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("bad.yaml:5:13: bodies[0].radius"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(work / "out" / "frame_00000.png"));
    fs::remove_all(work);
}

TEST(Cli, BadFlagsExit2WithAMessage) {
    const fs::path work = tempDir("flags");
    Result r = runCdlab("run " + kTiny + " --broadphase nope --no-video --out " +
                            (work / "o").string(),
                        work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("unknown broad phase 'nope'"), std::string::npos) << r.err;
    r = runCdlab("run " + kTiny + " --pause-at 99 --no-video --out " + (work / "o").string(),
                 work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--pause-at 99"), std::string::npos) << r.err;
    r = runCdlab("run no/such/scene.yaml --no-video", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("no/such/scene.yaml"), std::string::npos) << r.err;
    r = runCdlab("frobnicate", work);
    EXPECT_EQ(r.exit_code, 2);
    r = runCdlab("--help", work);
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_NE(r.out.find("run"), std::string::npos);
    fs::remove_all(work);
}

TEST(Cli, UnwritableOutputIsAClearFailure) {
    const fs::path work = tempDir("unwritable");
    const fs::path blocker = work / "file";
    std::ofstream(blocker) << "x";
    const Result r = runCdlab("run " + kTiny + " --no-video --out " + (blocker / "sub").string(),
                              work);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.err.find("cannot create output directory"), std::string::npos) << r.err;
    fs::remove_all(work);
}

TEST(Cli, BroadPhaseFlagOverridesTheScene) {
    const fs::path work = tempDir("override");
    const Result r = runCdlab("run " + kTiny + " --broadphase sphere --no-video --frames 2 "
                              "--pause-at 1 --out " + (work / "o").string(),
                              work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json p = nlohmann::json::parse(slurp(work / "o" / "pause_1.json"));
    EXPECT_EQ(p["broadphase"], "sphere");
    EXPECT_TRUE(fs::exists(work / "o" / "frame_00001.png"));
    EXPECT_FALSE(fs::exists(work / "o" / "frame_00002.png"));
    fs::remove_all(work);
}

TEST(Cli, StatsCsvHasOneRowPerFrameAndCheckBroadphasePasses) {
    const fs::path work = tempDir("stats");
    const fs::path csv = work / "stats" / "run.csv";
    const Result r = runCdlab("run " + kTiny + " --no-video --check-broadphase --draw-structure "
                              "--broadphase hgrid --pause-at 5 --stats " + csv.string() +
                                  " --out " + (work / "o").string(),
                              work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("every step checked"), std::string::npos) << r.out;
    std::istringstream lines(slurp(csv));
    std::string line;
    std::getline(lines, line);
    EXPECT_EQ(line.rfind("frame,time,broadphase,bodies,flagged,colliding,volume_tests", 0), 0u);
    int rows = 0;
    std::string last;
    while (std::getline(lines, line)) {
        EXPECT_EQ(std::count(line.begin(), line.end(), ','), 16) << line;
        last = line;
        ++rows;
    }
    EXPECT_EQ(rows, 6);
    // The last row's flagged/colliding counts are those of the frame-5 pause dump.
    const nlohmann::json p = nlohmann::json::parse(slurp(work / "o" / "pause_5.json"));
    std::vector<std::string> cells;
    std::stringstream row(last);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    ASSERT_EQ(cells.size(), 17u);
    EXPECT_EQ(cells[0], "5");
    EXPECT_EQ(cells[2], "hgrid");
    EXPECT_EQ(std::stoul(cells[4]), p["flagged_pairs"].size());
    EXPECT_EQ(std::stoul(cells[5]), p["colliding_pairs"].size());
    fs::remove_all(work);
}

}  // namespace
