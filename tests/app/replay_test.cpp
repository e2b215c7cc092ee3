// tests/app/replay_test.cpp -- recordings end to end: `cdlab run --record` writes every frame a
// run reaches, `cdlab replay` says what a recording holds, `replay --check` passes on the run's
// own recording and names the first frame, body and quantity of one changed by a single bit; a
// scene changed or moved since is refused by name; a demo session of a recording (what `serve
// --replay` shows) shows the frames of the simulated session, whatever commands move it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "cli_run.h"
#include "demo/demo_session.h"
#include "engine/recording.h"
#include "engine/scene.h"
#include "pause_dump.h"

namespace replay_test {

namespace fs = std::filesystem;
using cdlab_test::runCdlab;
using cdlab_test::slurp;
using cdlab_test::tempDir;

bool has(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

// A copy of `from` with frame `frame` changed by `change`, as another build's run would differ.
void copyWithChange(const fs::path& from, const fs::path& to, int frame,
                    const std::function<void(engine::RecordedFrame&)>& change) {
    const engine::Recording r = engine::Recording::open(from);
    engine::RecordingWriter w(to, r.header());
    for (int k = 0; k < r.frames(); ++k) {
        engine::RecordedFrame f = r.frame(k);
        if (k == frame) change(f);
        w.write(f);
    }
    w.finish(r.ended());
}

TEST(Replay, CheckPassesOnTheRunsRecordingAndNamesTheFirstFrameThatDiffers) {
    const fs::path work = tempDir("cdlab_replay_", "check");
    const fs::path rec = work / "c.rec";
    const auto run = runCdlab("run scenes/coursework.yaml --frames 40 --no-video --no-frames --out " +
                                  (work / "run").string() + " --record " + rec.string(),
                              work);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_TRUE(has(run.out, "recorded 40 frames to " + rec.string())) << run.out;

    const auto info = runCdlab("replay " + rec.string(), work);
    EXPECT_EQ(info.exit_code, 0) << info.err;
    EXPECT_TRUE(has(info.out, "frames      40 of 40")) << info.out;
    EXPECT_TRUE(has(info.out, "scene       " + (fs::path(CDLAB_SOURCE_DIR) / "scenes" /
                                                 "coursework.yaml").lexically_normal().string()))
        << info.out;
    EXPECT_TRUE(has(info.out, "bytes per body per frame")) << info.out;

    const auto same = runCdlab("replay " + rec.string() + " --check", work);
    EXPECT_EQ(same.exit_code, 0) << same.err;
    EXPECT_TRUE(has(same.out, "frames 0..39 match the simulation")) << same.out;

    // One bit of crate3's x at frame 17 (the last bit of the mantissa), its hash left as it was.
    const fs::path moved = work / "moved.rec";
    copyWithChange(rec, moved, 17, [](engine::RecordedFrame& f) {
        engine::Vec3& x = f.state.bodies[3].position;
        x.x() = std::nextafter(x.x(), 1e9);
    });
    const auto diverged = runCdlab("replay " + moved.string() + " --check", work);
    EXPECT_EQ(diverged.exit_code, 3) << diverged.out << diverged.err;
    EXPECT_TRUE(has(diverged.out, "frame 17 differs from the simulation")) << diverged.out;
    EXPECT_TRUE(has(diverged.out, "first body crate3's position")) << diverged.out;
    EXPECT_TRUE(has(diverged.out, "frames 0..16 match")) << diverged.out;

    // A momentum alone, and the pairs alone (with the hash that says they differ).
    const fs::path pushed = work / "pushed.rec";
    copyWithChange(rec, pushed, 25, [](engine::RecordedFrame& f) {
        f.state.bodies[0].angular_momentum.z() *= -1;
    });
    const auto spun = runCdlab("replay " + pushed.string() + " --check", work);
    EXPECT_EQ(spun.exit_code, 3);
    EXPECT_TRUE(has(spun.out, "frame 25 differs")) << spun.out;
    EXPECT_TRUE(has(spun.out, "body ball0's angular momentum")) << spun.out;

    // --frames checks a prefix only: frame 17 is past it.
    const auto prefix = runCdlab("replay " + moved.string() + " --check --frames 17", work);
    EXPECT_EQ(prefix.exit_code, 0) << prefix.out;
    EXPECT_TRUE(has(prefix.out, "frames 0..16 match the simulation")) << prefix.out;
    EXPECT_TRUE(has(prefix.out, "(of 40 recorded)")) << prefix.out;
}

TEST(Replay, ASceneChangedOrMovedSinceTheRecordingIsRefusedByName) {
    const fs::path work = tempDir("cdlab_replay_", "scene");
    const fs::path scene = work / "two.yaml";
    std::ofstream(scene) << "world: {bounds: {min: [-4, -3, -3], max: [4, 3, 3]}, time_step: 0.02, "
                            "steps_per_frame: 2, frames: 9}\n"
                            "output: {width: 64, height: 48, fps: 25}\n"
                            "bodies:\n"
                            "  - {name: left, shape: sphere, radius: 0.5, position: [-1, 0, 0], "
                            "velocity: [2, 0, 0]}\n"
                            "  - {name: right, shape: box, half_extents: [0.4, 0.3, 0.2], "
                            "position: [1, 0, 0], velocity: [-2, 0.1, 0], "
                            "angular_velocity: [1, 2, 3]}\n";
    const fs::path rec = work / "t.rec";
    ASSERT_EQ(runCdlab("run " + scene.string() + " --no-video --no-frames --out " +
                           (work / "run").string() + " --record " + rec.string() +
                           " --set world.frames=4",
                       work)
                  .exit_code,
              0);
    const auto ok = runCdlab("replay " + rec.string() + " --check", work);
    EXPECT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_TRUE(has(ok.out, "frames 0..3 match")) << ok.out;  // --set recorded and applied

    fs::rename(scene, work / "elsewhere.yaml");
    const auto gone = runCdlab("replay " + rec.string() + " --check", work);
    EXPECT_EQ(gone.exit_code, 2);
    EXPECT_TRUE(has(gone.err, rec.string() + ": its scene " + scene.string() +
                                  " cannot be read (moved? --scene FILE names it)"))
        << gone.err;
    const auto found = runCdlab(
        "replay " + rec.string() + " --check --scene " + (work / "elsewhere.yaml").string(), work);
    EXPECT_EQ(found.exit_code, 0) << found.err;

    std::ofstream(work / "elsewhere.yaml", std::ios::app) << "# one more line\n";
    const auto changed = runCdlab(
        "replay " + rec.string() + " --check --scene " + (work / "elsewhere.yaml").string(), work);
    EXPECT_EQ(changed.exit_code, 2);
    EXPECT_TRUE(has(changed.err, "has changed since it was recorded")) << changed.err;

    const auto not_one = runCdlab("replay " + (work / "elsewhere.yaml").string(), work);
    EXPECT_EQ(not_one.exit_code, 2);
    EXPECT_TRUE(has(not_one.err, "elsewhere.yaml: not a cdlab recording")) << not_one.err;
    const auto serve = runCdlab("serve --replay " + (work / "elsewhere.yaml").string(), work);
    EXPECT_EQ(serve.exit_code, 2);
    EXPECT_TRUE(has(serve.err, "not a cdlab recording")) << serve.err;
    const auto with_set = runCdlab("serve --replay " + rec.string() + " --set world.frames=3", work);
    EXPECT_EQ(with_set.exit_code, 2);
    EXPECT_TRUE(has(with_set.err, "--replay: --broadphase and --set do not apply")) << with_set.err;
    const auto neither = runCdlab("serve", work);
    EXPECT_EQ(neither.exit_code, 2);
    EXPECT_TRUE(has(neither.err, "a scene file, or --replay RECORDING, is required")) << neither.err;
}

TEST(Replay, ARunOfAnEventsTrackRecordsEveryFrameItReaches) {
    const fs::path work = tempDir("cdlab_replay_", "events");
    const fs::path rec = work / "walk.rec";
    const std::string walk = " --events scenes/events/coursework_walkthrough.yaml";
    const auto run = runCdlab("run scenes/coursework.yaml --no-video --no-frames --out " +
                                  (work / "run").string() + walk + " --record " + rec.string(),
                              work);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    // The walk steps back and forth and switches broad phases; its frames are recorded once each.
    const engine::Recording r = engine::Recording::open(rec);
    EXPECT_EQ(r.frames(), 300);
    EXPECT_EQ(r.frame(31).broad_phase, "sap");
    EXPECT_EQ(r.frame(61).broad_phase, "hgrid-levels");
    const auto check = runCdlab("replay " + rec.string() + " --check", work);
    EXPECT_EQ(check.exit_code, 0) << check.out << check.err;

    // In found order the switches change the motion, which a check could not reproduce.
    const auto found = runCdlab("run scenes/coursework.yaml --no-video --no-frames --out " +
                                    (work / "found").string() + walk +
                                    " --pair-order found --record " + (work / "f.rec").string(),
                                work);
    EXPECT_EQ(found.exit_code, 2);
    EXPECT_TRUE(has(found.err, "--record " + (work / "f.rec").string() +
                                   ": the events switch the broad phase"))
        << found.err;
    EXPECT_FALSE(fs::exists(work / "f.rec"));
}

TEST(Replay, ASessionOfARecordingShowsTheSimulatedSessionsFrames) {
    const fs::path work = tempDir("cdlab_replay_", "session");
    const fs::path rec = work / "c.rec";
    ASSERT_EQ(runCdlab("run scenes/coursework.yaml --frames 60 --no-video --no-frames --out " +
                           (work / "run").string() + " --record " + rec.string(),
                       work)
                  .exit_code,
              0);
    const engine::Recording recording = engine::Recording::open(rec);
    const engine::Scene scene = engine::loadScene(fs::path(CDLAB_SOURCE_DIR) / "scenes" /
                                                  "coursework.yaml");
    app::DemoSession live(scene, false);
    app::DemoSession replay(scene, false, recording);
    EXPECT_TRUE(replay.replaying());
    EXPECT_EQ(replay.lastFrame(), 59);
    const auto expectSame = [&](const std::string& after) {
        SCOPED_TRACE(after);
        EXPECT_EQ(replay.frame(), live.frame());
        EXPECT_EQ(replay.world().stateHash(), live.world().stateHash());
        EXPECT_EQ(replay.world().broadPhase().name(), live.world().broadPhase().name());
        // Once another broad phase is chosen the live session steps with it, which a replay
        // cannot: its HUD counters (line 2) are then a detection's, the rest the same.
        std::string want = live.hudText(true, false), got = replay.hudText(true, false);
        if (live.world().broadPhase().name() != "sap") {
            for (std::string* hud : {&want, &got}) {
                const std::size_t a = hud->find('\n'), b = hud->find('\n', a + 1);
                hud->erase(a, b == std::string::npos ? std::string::npos : b - a);
            }
        }
        EXPECT_EQ(got, want);
        EXPECT_EQ(app::pauseDumpJson(replay.world(), replay.frame(), replay.frameOptions().draw),
                  app::pauseDumpJson(live.world(), live.frame(), live.frameOptions().draw));
    };
    expectSame("frame 0");
    for (const std::string text :
         {"{seek: {frame: 30}}", "{step: -3}", "{broadphase: hgrid, show: [obb]}", "{step: 2}",
          "{select: ring4, camera: {orbit: [30, 10]}}", "{seek: {frame: 5}}", "{step: 40}",
          "{broadphase: tree}", "{seek: {frame: 59}}"}) {
        const engine::DemoCommands c = engine::parseDemoCommands(text, "test", scene);
        ASSERT_EQ(live.apply(c), "") << text;
        ASSERT_EQ(replay.apply(c), "") << text;
        expectSame(text);
    }
    // A recording's own broad-phase switch (frame by frame) keeps the layers shown too.
    {
        const fs::path walk = work / "walk.rec";
        ASSERT_EQ(runCdlab("run scenes/coursework.yaml --no-video --no-frames --out " +
                               (work / "walk").string() +
                               " --events scenes/events/coursework_walkthrough.yaml --record " +
                               walk.string(),
                           work)
                      .exit_code,
                  0);
        const engine::Recording walked = engine::Recording::open(walk);
        engine::Scene free_volumes = scene;
        free_volumes.draw.volumes_given = false;
        app::DemoSession viewer(free_volumes, false, walked);
        ASSERT_EQ(viewer.apply(engine::parseDemoCommands("{show: [labels], seek: {frame: 62}}",
                                                         "test", scene)),
                  "");
        EXPECT_EQ(viewer.world().broadPhase().name(), "hgrid-levels");
        EXPECT_TRUE(viewer.shows(engine::DemoLayer::Labels));
    }
    // The replay ends where the recording does.
    const engine::DemoCommands past = engine::parseDemoCommands("{step: 1}", "test", scene);
    EXPECT_NE(replay.apply(past), "");
    EXPECT_EQ(replay.frame(), 59);
    EXPECT_FALSE(replay.advance());
}

}  // namespace replay_test
