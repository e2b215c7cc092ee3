// End-to-end: the cdlab binary writes frames, the video (checked by ffprobe), pause dumps and a
// summary; bad input gets a precise message and exit code 2; output failures (an unwritable
// directory, ffmpeg missing) a message and a non-zero exit.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.h"
#include "output_files.h"
#include "render/image.h"

namespace {

namespace fs = std::filesystem;
using Result = cdlab_test::CliResult;
using cdlab_test::runCdlab;
using cdlab_test::slurp;

fs::path cliDir(const std::string& name) { return cdlab_test::tempDir("cdlab_cli_", name); }

using cdlab_test::haveFfprobe;
using cdlab_test::probeVideo;

// Pixels that differ between two images of the same size, counting rows from `first_row` on.
int differingPixels(const render::Image& a, const render::Image& b, int first_row) {
    int n = 0;
    for (int y = first_row; y < a.height; ++y) {
        for (int x = 0; x < a.width; ++x) {
            const std::uint8_t* p = a.pixel(x, y);
            const std::uint8_t* q = b.pixel(x, y);
            n += p[0] != q[0] || p[1] != q[1] || p[2] != q[2];
        }
    }
    return n;
}

using cdlab_test::kTiny;

// `cdlab bench` runs cdlab-bench from cdlab's own folder, with the arguments after `bench`.
TEST(Cli, BenchRunsTheBenchExecutableBesideCdlab) {
    const fs::path work = cliDir("bench_forward");
    const Result help = runCdlab("bench --help", work);
    EXPECT_EQ(help.exit_code, 0) << help.err;
    EXPECT_NE(help.out.find("cdlab bench"), std::string::npos) << help.out;
    EXPECT_NE(help.out.find("broadphase"), std::string::npos) << help.out;
    const Result bad = runCdlab("bench nope", work);
    EXPECT_EQ(bad.exit_code, 2) << bad.err;
    EXPECT_NE(bad.err.find("subcommand"), std::string::npos) << bad.err;
}

// A cdlab without cdlab-bench beside it (the demo builds cdlab alone) says how to build the
// benches and exits 1; the other commands are unaffected.
TEST(Cli, BenchWithoutTheBenchExecutableSaysHowToBuildIt) {
    const fs::path work = cliDir("bench_missing");
    const fs::path alone = work / "cdlab";
    fs::copy_file(CDLAB_BINARY, alone);
    const std::string cmd = alone.string() + " bench broadphase --sizes 50 > " +
                            (work / "out.txt").string() + " 2> " + (work / "err.txt").string();
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1);
    const std::string err = slurp(work / "err.txt");
    EXPECT_NE(err.find((work / "cdlab-bench").string() + " is not built"), std::string::npos)
        << err;
    EXPECT_NE(err.find("--target cdlab-bench"), std::string::npos) << err;
    EXPECT_EQ(slurp(work / "out.txt"), "");
    const std::string help = alone.string() + " --help > " + (work / "help.txt").string();
    EXPECT_EQ(std::system(help.c_str()), 0);
    EXPECT_NE(slurp(work / "help.txt").find("bench"), std::string::npos);
}

TEST(Cli, RunWritesFramesPauseDumpsAndSummary) {
    const fs::path work = cliDir("run");
    const fs::path out = work / "out";
    const Result r = runCdlab(
        "run " + kTiny + " --out " + out.string() + " --pause-at 0 --pause-at 3 --no-video", work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (int f = 0; f < 6; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%05d.png", f);
        EXPECT_GT(fs::file_size(out / name), 100u) << name;
    }
    EXPECT_FALSE(fs::exists(out / "frame_00006.png"));
    EXPECT_FALSE(fs::exists(out / "tiny.mp4"));
    // tiny.yaml chose its volumes (spheres and AABBs), so the pause picture draws those and no
    // OBBs: below the HUD text (rows from 40 on; the text differs: "PAUSED", no step time) it is
    // the frame's picture. Each volume is coloured by its own test there, which in tiny.yaml
    // agrees with the frame's colours.
    for (const int f : {0, 3}) {
        const fs::path pause = out / ("pause_" + std::to_string(f) + ".png");
        ASSERT_TRUE(fs::exists(pause)) << pause;
        char name[32];
        std::snprintf(name, sizeof name, "frame_%05d.png", f);
        const render::Image frame_image = render::readPng(out / name);
        const render::Image pause_image = render::readPng(pause);
        ASSERT_EQ(pause_image.width, frame_image.width);
        ASSERT_EQ(pause_image.height, frame_image.height);
        ASSERT_GT(frame_image.height, 40);
        EXPECT_EQ(differingPixels(frame_image, pause_image, 40), 0) << pause;
    }

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
    EXPECT_EQ(summary["video"], "");
    fs::remove_all(work);
}

// The video as a browser needs it (H.264 in yuv420p) with one picture per frame, read back by
// ffprobe, which the ffmpeg package always brings along.
// Two runs into one folder: the second once deleted the first's partial video while the first
// still wrote it, and the first then said complete. The second is refused, touching nothing.
TEST(Cli, ASecondRunIntoAFolderBeingWrittenIsRefused) {
    const fs::path work = cdlab_test::tempDir("cdlab_cli_", "lock");
    const fs::path out = work / "out";
    fs::create_directories(out);
    std::ofstream(out / "frame_00000.png") << "the first run's";
    {
        const app::OutputLock first(out);
        EXPECT_THROW(app::OutputLock second(out), std::runtime_error);
        const auto r = runCdlab("run " + kTiny + " --no-video --out " + out.string(), work);
        EXPECT_EQ(r.exit_code, 1);
        EXPECT_NE(r.err.find("output directory " + out.string() +
                             " is being written by another cdlab run"),
                  std::string::npos)
            << r.err;
        EXPECT_EQ(slurp(out / "frame_00000.png"), "the first run's");
        EXPECT_FALSE(fs::exists(out / "summary.json"));
    }
    const auto after = runCdlab("run " + kTiny + " --no-video --out " + out.string(), work);
    EXPECT_EQ(after.exit_code, 0) << after.err;
    EXPECT_TRUE(fs::exists(out / "summary.json"));
    fs::remove_all(work);
}

TEST(Cli, RunWritesAnH264Yuv420pVideoWithEveryFrame) {
    if (!haveFfprobe()) GTEST_SKIP() << "ffprobe not on PATH (Debian package ffmpeg)";
    const fs::path work = cliDir("video");
    const fs::path out = work / "out";
    const Result r = runCdlab("run " + kTiny + " --out " + out.string(), work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const fs::path video = out / "tiny.mp4";
    ASSERT_TRUE(fs::exists(video));
    EXPECT_FALSE(fs::exists(out / "tiny.partial.mp4"));
    const std::map<std::string, std::string> probe = probeVideo(video, work);
    ASSERT_EQ(probe.count("error"), 0u) << probe.at("error");
    const render::Image first = render::readPng(out / "frame_00000.png");
    EXPECT_EQ(probe.count("codec_name") ? probe.at("codec_name") : "?", "h264");
    EXPECT_EQ(probe.count("pix_fmt") ? probe.at("pix_fmt") : "?", "yuv420p");
    EXPECT_EQ(probe.count("width") ? probe.at("width") : "?", std::to_string(first.width));
    EXPECT_EQ(probe.count("height") ? probe.at("height") : "?", std::to_string(first.height));
    EXPECT_EQ(probe.count("nb_read_frames") ? probe.at("nb_read_frames") : "?", "6");
    const nlohmann::json summary = nlohmann::json::parse(slurp(out / "summary.json"));
    EXPECT_EQ(summary["video"], video.string());
    fs::remove_all(work);
}

// --video picks the container by its extension: a WebM holds VP9 (not the H.264 that made ffmpeg
// fail with "Resource temporarily unavailable"), a GIF its own codec; an unsupported extension is
// bad input found before any output, with the list of supported containers.
TEST(Cli, RunWritesWebmAndGifAndRefusesUnsupportedContainers) {
    if (!haveFfprobe()) GTEST_SKIP() << "ffprobe not on PATH (Debian package ffmpeg)";
    const fs::path work = cliDir("containers");
    const fs::path out = work / "out";
    for (const auto& [name, codec] :
         {std::pair<std::string, std::string>{"tiny.webm", "vp9"}, {"tiny.gif", "gif"}}) {
        const fs::path video = work / name;
        const Result r = runCdlab(
            "run " + kTiny + " --out " + out.string() + " --video " + video.string(), work);
        ASSERT_EQ(r.exit_code, 0) << name << ": " << r.err;
        const std::map<std::string, std::string> probe = probeVideo(video, work);
        ASSERT_EQ(probe.count("error"), 0u) << probe.at("error");
        EXPECT_EQ(probe.count("codec_name") ? probe.at("codec_name") : "?", codec) << name;
        EXPECT_EQ(probe.count("nb_read_frames") ? probe.at("nb_read_frames") : "?", "6") << name;
    }
    const fs::path bad_out = work / "bad_out";
    const Result r = runCdlab(
        "run " + kTiny + " --out " + bad_out.string() + " --video " + (work / "tiny.avi").string(),
        work);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("unsupported video container '.avi' (supported: .mp4"), std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(bad_out)) << "output written before the check";
    fs::remove_all(work);
}

// ffmpeg missing: found before any output is written, a message that says what to do, exit 1.
// cdlab looks for ffmpeg on PATH, so an empty directory as PATH hides it; the same run with
// --no-video succeeds, so it is the missing encoder and nothing else that stops the first run.
TEST(Cli, MissingFfmpegIsAClearFailureBeforeAnyOutput) {
    const fs::path work = cliDir("noffmpeg");
    const fs::path empty = work / "empty_path";
    fs::create_directories(empty);
    const fs::path out = work / "out";
    const std::string env = "PATH=" + empty.string();
    Result r = runCdlab("run " + kTiny + " --out " + out.string(), work, env);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find("ffmpeg not found on PATH"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--no-video"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out / "summary.json"));
    EXPECT_FALSE(fs::exists(out)) << "output written before the check";

    r = runCdlab("run " + kTiny + " --out " + out.string() + " --no-video", work, env);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(fs::exists(out / "summary.json"));
    fs::remove_all(work);
}

TEST(Cli, SameSceneGivesBitIdenticalFramesAndState) {
    const fs::path work = cliDir("determinism");
    for (const char* run : {"a", "b"}) {
        const Result r = runCdlab(
            "run " + kTiny + " --no-video --no-hud-timing --out " + (work / run).string(), work);
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
    const fs::path work = cliDir("bad");
    const fs::path scene = work / "bad.yaml";
    std::ofstream(scene) << "world:\n  bounds: {min: [-1, -1, -1], max: [1, 1, 1]}\n"
                            "bodies:\n  - shape: sphere\n    radius: -2\n    position: [0, 0, 0]\n";
    const Result r =
        runCdlab("run " + scene.string() + " --no-video --out " + (work / "out").string(), work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("bad.yaml:5:13: bodies[0].radius"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(work / "out" / "frame_00000.png"));
    fs::remove_all(work);
}

TEST(Cli, AnUnknownOrMissingCommandIsNamedWithTheCommandsThereAre) {
    const fs::path work = cliDir("command");
    Result r = runCdlab("nope scenes/coursework.yaml", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("unknown command 'nope'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("run, check, query, sweep, serve, replay, bench"), std::string::npos) << r.err;
    r = runCdlab("", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("no command given"), std::string::npos) << r.err;
    fs::remove_all(work);
}

TEST(Cli, BadFlagsExit2WithAMessage) {
    const fs::path work = cliDir("flags");
    Result r = runCdlab(
        "run " + kTiny + " --broadphase nope --no-video --out " + (work / "o").string(), work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("unknown broad phase 'nope'"), std::string::npos) << r.err;
    r = runCdlab("run " + kTiny + " --pause-at 99 --no-video --out " + (work / "o").string(), work);
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
    const fs::path work = cliDir("unwritable");
    const fs::path blocker = work / "file";
    std::ofstream(blocker) << "x";
    const Result r =
        runCdlab("run " + kTiny + " --no-video --out " + (blocker / "sub").string(), work);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.err.find("cannot create output directory"), std::string::npos) << r.err;
    fs::remove_all(work);
}

// A frame that cannot be written in the middle of a run (here frame 3's name is taken by a
// directory), while the writer threads compress PNGs and feed the encoder behind the renderer:
// the run stops with the file named and exit 1, and leaves nothing that looks complete (no
// summary.json, no video under its final or partial name).
TEST(Cli, AFrameThatCannotBeWrittenStopsTheRun) {
    if (!haveFfprobe()) GTEST_SKIP() << "ffmpeg not on PATH (Debian package ffmpeg)";
    const fs::path work = cliDir("frame_unwritable");
    const fs::path out = work / "out";
    fs::create_directories(out / "frame_00003.png");
    const Result r = runCdlab("run " + kTiny + " --quiet --out " + out.string(), work);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("frame_00003.png: exists and is a directory"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out / "summary.json"));
    EXPECT_FALSE(fs::exists(out / "tiny.mp4"));
    EXPECT_FALSE(fs::exists(out / "tiny.partial.mp4"));
    fs::remove_all(work);
}

// --timing ends the run with one line saying where the time went, each stage named, and the
// writers' counts: every frame's PNG written, none given to an encoder that was not asked for.
TEST(Cli, TimingLineNamesEveryStage) {
    const fs::path work = cliDir("timing");
    const Result r = runCdlab(
        "run " + kTiny + " --quiet --no-video --timing --out " + (work / "out").string(), work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("timing: 6 frames in "), std::string::npos) << r.out;
    for (const char* stage : {"fps", "sim ", "render ", "readback ", "waiting for writers ", "png ",
                              "(cpu, 6 files)", "video feed ", "(cpu, 0 frames)"}) {
        EXPECT_NE(r.out.find(stage), std::string::npos) << stage << " in " << r.out;
    }
    fs::remove_all(work);
}

// Regression: every output was written to X.partial and renamed over X, whatever X was, so
// `--video /dev/null` as root replaced the machine's /dev/null with an mp4 (exit 0). An existing
// output path that is not a regular file is refused before any work, and left as it was: here a
// FIFO, a symbolic link (to a regular file, which stays untouched too) and a directory, through
// --video, --stats and --trace. (/dev/null itself is not used: a regression would replace it.)
TEST(Cli, OutputPathsThatAreNotRegularFilesAreRefusedAndLeftAlone) {
    const fs::path work = cliDir("special_outputs");
    const fs::path fifo = work / "pipe.mp4";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const fs::path target = work / "target.csv";
    std::ofstream(target) << "keep me";
    const fs::path link = work / "link.csv";
    fs::create_symlink(target, link);
    const fs::path dir = work / "dir";
    fs::create_directories(dir);
    const std::string out = " --out " + (work / "out").string();
    struct Case {
        std::string flags;
        fs::path path;
        std::string kind;
    };
    const Case cases[] = {
        {"--video " + fifo.string(), fifo, "a FIFO"},
        {"--no-video --stats " + link.string(), link, "a symbolic link"},
        {"--no-video --trace " + link.string(), link, "a symbolic link"},
        {"--no-video --stats " + dir.string(), dir, "a directory"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.flags);
        const Result r = runCdlab("run " + kTiny + out + " " + c.flags, work);
        EXPECT_EQ(r.exit_code, 1);
        EXPECT_NE(r.err.find(c.path.string() + ": exists and is " + c.kind), std::string::npos)
            << r.err;
        EXPECT_FALSE(fs::exists(work / "out" / "summary.json"));
        EXPECT_FALSE(fs::exists(work / "out" / "frame_00000.png")) << "refused after work began";
    }
    EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
    EXPECT_EQ(slurp(target), "keep me");
    EXPECT_TRUE(fs::is_directory(dir));
    EXPECT_TRUE(fs::is_empty(dir));
    // A planted partial file that is a link is not written through either.
    const fs::path victim = work / "victim.txt";
    std::ofstream(victim) << "untouched";
    fs::create_directories(work / "out2");
    fs::create_symlink(victim, work / "out2" / "frame_00000.png.partial");
    const Result r =
        runCdlab("run " + kTiny + " --no-video --out " + (work / "out2").string(), work);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("frame_00000.png.partial: exists and is a symbolic link"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(slurp(victim), "untouched");
    fs::remove_all(work);
}

// Regression: a rerun into the folder of a longer (or killed) run left the old frames and a
// .partial file beside the new summary.json. The run's own earlier outputs are cleared first;
// files that are not cdlab's stay.
TEST(Cli, RerunClearsTheEarlierRunsOutputsOnly) {
    const fs::path work = cliDir("rerun");
    const fs::path out = work / "out";
    ASSERT_EQ(
        runCdlab("run " + kTiny + " --no-video --pause-at 5 --out " + out.string(), work).exit_code,
        0);
    ASSERT_TRUE(fs::exists(out / "frame_00005.png"));
    std::ofstream(out / "frame_00004.png.partial") << "killed mid-write";
    std::ofstream(out / "notes.txt") << "mine";
    const Result r =
        runCdlab("run " + kTiny + " --no-video --frames 3 --out " + out.string(), work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(fs::exists(out / "frame_00002.png"));
    EXPECT_TRUE(fs::exists(out / "summary.json"));
    for (const char* stale : {"frame_00003.png", "frame_00005.png", "pause_5.png", "pause_5.json",
                              "frame_00004.png.partial"}) {
        EXPECT_FALSE(fs::exists(out / stale)) << stale;
    }
    EXPECT_EQ(slurp(out / "notes.txt"), "mine");
    fs::remove_all(work);
}

// Regression: contradictory or empty flags were accepted (`--video x.mp4 --no-video` ran with no
// video; `--broadphase ""` ran the scene's broad phase).
TEST(Cli, ContradictoryAndEmptyFlagsExit2) {
    const fs::path work = cliDir("flags");
    const std::string out = " --out " + (work / "out").string();
    Result r = runCdlab("run " + kTiny + out + " --video x.mp4 --no-video", work);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("excludes"), std::string::npos) << r.err;
    for (const char* flag : {"--broadphase", "--stats", "--trace", "--video", "--out"}) {
        r = runCdlab("run " + kTiny + " --no-frames " + flag + " ''", work);
        EXPECT_EQ(r.exit_code, 2) << flag;
        EXPECT_NE(r.err.find(std::string(flag) + ": must not be empty"), std::string::npos)
            << r.err;
    }
    EXPECT_FALSE(fs::exists(work / "out"));
    fs::remove_all(work);
}

TEST(Cli, BroadPhaseFlagOverridesTheScene) {
    const fs::path work = cliDir("override");
    const Result r = runCdlab("run " + kTiny +
                                  " --broadphase sphere --no-video --frames 2 "
                                  "--pause-at 1 --out " +
                                  (work / "o").string(),
                              work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json p = nlohmann::json::parse(slurp(work / "o" / "pause_1.json"));
    EXPECT_EQ(p["broadphase"], "sphere");
    EXPECT_TRUE(fs::exists(work / "o" / "frame_00001.png"));
    EXPECT_FALSE(fs::exists(work / "o" / "frame_00002.png"));
    fs::remove_all(work);
}

// The --stats CSV: header, then one row of cells per frame, columns named by the header.
struct StatsCsv {
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
    std::size_t column(const std::string& name) const {
        const auto it = std::find(header.begin(), header.end(), name);
        return it == header.end() ? header.size() : std::size_t(it - header.begin());
    }
    double sum(const std::string& name) const {
        const std::size_t c = column(name);
        double total = 0;
        for (const auto& row : rows) total += c < row.size() ? std::stod(row[c]) : 0.0;
        return total;
    }
};

std::vector<std::string> splitCsv(const std::string& line) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    return cells;
}

StatsCsv readStats(const fs::path& csv) {
    StatsCsv stats;
    std::istringstream lines(slurp(csv));
    std::string line;
    std::getline(lines, line);
    stats.header = splitCsv(line);
    while (std::getline(lines, line)) stats.rows.push_back(splitCsv(line));
    return stats;
}

const std::vector<std::string> kStatsColumns = {
    "frame",          "time",         "broadphase",      "bodies",     "flagged",
    "colliding",      "volume_tests", "volumes_updated", "swaps",      "narrow_tests",
    "triangle_tests", "bv_tests",     "integrate_ms",    "volumes_ms", "broadphase_ms",
    "narrowphase_ms", "ccd_ms",       "response_ms",     "step_ms",    "self_pairs",
    "refit_nodes",    "refit_ms",     "refit_node_ns",   "rebuilds",   "toi_queries",
    "toi_iterations", "toi_events",   "response_pairs",  "response_volume_tests",
    "ccd_pairs",      "ccd_volume_tests"};

TEST(Cli, StatsCsvHasOneRowPerFrameAndCheckBroadphasePasses) {
    const fs::path work = cliDir("stats");
    const fs::path csv = work / "stats" / "run.csv";
    const Result r = runCdlab("run " + kTiny +
                                  " --no-video --check-broadphase --draw-structure "
                                  "--broadphase hgrid --pause-at 5 --stats " +
                                  csv.string() + " --out " + (work / "o").string(),
                              work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("every step checked"), std::string::npos) << r.out;
    const StatsCsv stats = readStats(csv);
    EXPECT_EQ(stats.header, kStatsColumns);
    ASSERT_EQ(stats.rows.size(), 6u);
    for (const auto& row : stats.rows) EXPECT_EQ(row.size(), kStatsColumns.size());
    // The last row's flagged/colliding counts are those of the frame-5 pause dump.
    const nlohmann::json p = nlohmann::json::parse(slurp(work / "o" / "pause_5.json"));
    const std::vector<std::string>& last = stats.rows.back();
    ASSERT_EQ(last.size(), kStatsColumns.size());
    EXPECT_EQ(last[stats.column("frame")], "5");
    EXPECT_EQ(last[stats.column("broadphase")], "hgrid");
    EXPECT_EQ(std::stoul(last[stats.column("flagged")]), p["flagged_pairs"].size());
    EXPECT_EQ(std::stoul(last[stats.column("colliding")]), p["colliding_pairs"].size());
    // tiny.yaml runs without CCD and without contact response: those stages cost nothing.
    EXPECT_EQ(stats.sum("ccd_ms"), 0.0);
    EXPECT_EQ(stats.sum("response_ms"), 0.0);
    EXPECT_EQ(stats.sum("toi_queries"), 0.0);
    EXPECT_GT(stats.sum("step_ms"), 0.0);
    fs::remove_all(work);
}

// Every frame's line of --trace lists the flagged and the confirmed pairs, by id and by the
// bodies' names: at a pause frame, the same lists as the pause dump's.
TEST(Cli, TraceListsEachFramesFlaggedAndCollidingPairsByIdAndName) {
    const fs::path work = cliDir("trace_pairs");
    const Result r = runCdlab("run scenes/coursework.yaml --no-video --no-frames --frames 60 "
                              "--pause-at 20 --pause-at 59 --trace " +
                                  (work / "trace.jsonl").string() + " --out " +
                                  (work / "o").string(),
                              work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::vector<nlohmann::json> lines;
    std::istringstream in(slurp(work / "trace.jsonl"));
    for (std::string text; std::getline(in, text);) lines.push_back(nlohmann::json::parse(text));
    ASSERT_EQ(lines.size(), 60u);
    std::size_t flagged = 0;
    for (const int frame : {20, 59}) {
        const nlohmann::json& line = lines[std::size_t(frame)];
        EXPECT_EQ(line["frame"], frame);
        const nlohmann::json p =
            nlohmann::json::parse(slurp(work / "o" / ("pause_" + std::to_string(frame) + ".json")));
        for (const char* kind : {"flagged", "colliding"}) {
            const std::string ids = std::string(kind) + "_pairs";
            const std::string names = std::string(kind) + "_names";
            EXPECT_EQ(line[ids], p[ids]) << kind << " at frame " << frame;
            ASSERT_EQ(line[names].size(), line[ids].size()) << kind;
            for (std::size_t i = 0; i < line[ids].size(); ++i) {
                for (const int end : {0, 1}) {
                    const int id = line[ids][i][end];
                    EXPECT_EQ(line[names][i][end], p["bodies"][std::size_t(id)]["name"])
                        << kind << " pair " << i << " at frame " << frame;
                }
            }
        }
        flagged += line["flagged_pairs"].size();
    }
    // The coursework scene flags pairs at those frames, or the comparison above proves little.
    EXPECT_GT(flagged, 0u);
    fs::remove_all(work);
}

// With CCD and impulse response switched on, their stages get times of their own, and each
// stays within the step's total.
TEST(Cli, StatsCsvTimesTheCcdAndResponseStages) {
    const fs::path work = cliDir("stats_stages");
    const fs::path csv = work / "run.csv";
    const Result r = runCdlab("run " + kTiny +
                                  " --no-video --no-frames "
                                  "--set world.ccd=conservative_advancement "
                                  "--set world.response=impulse --stats " +
                                  csv.string() + " --out " + (work / "o").string(),
                              work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const StatsCsv stats = readStats(csv);
    EXPECT_EQ(stats.header, kStatsColumns);
    ASSERT_EQ(stats.rows.size(), 6u);
    EXPECT_GT(stats.sum("ccd_ms"), 0.0);
    EXPECT_GT(stats.sum("response_ms"), 0.0);
    // Every query takes at least one iteration.
    EXPECT_GE(stats.sum("toi_iterations"), stats.sum("toi_queries"));
    for (const auto& row : stats.rows) {
        ASSERT_EQ(row.size(), kStatsColumns.size());
        const double step = std::stod(row[stats.column("step_ms")]);
        // Rounded to 1e-6 ms in the file.
        EXPECT_LE(std::stod(row[stats.column("ccd_ms")]), step + 1e-6) << row[0];
        EXPECT_LE(std::stod(row[stats.column("response_ms")]), step + 1e-6) << row[0];
    }
    fs::remove_all(work);
}

}  // namespace
