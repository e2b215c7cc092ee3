// tests/app/check_events_test.cpp -- `cdlab check` on the run through an events track: the
// shipped coursework walkthrough passes; each expectation of such a run can fail, with its
// reason (a broken broad phase switched to, a broad phase never or unlisted in use, a dump no
// entry writes, frames the track never shows); the steps graded are those the run takes, the
// re-simulated ones after stepping back included; the dumps are those `cdlab run --events`
// writes; bad keys are refused by name.
//
// The small scene: two unit-diameter spheres 3.1 m apart closing at 2 m/s along x (no response),
// dt = 0.1 s, one step per frame: they overlap in frames 11..20 and nowhere else.
//
//     a -->   gap 2.1 m   <-- b          c (still)
//    (-1.55)             (1.55)        (0, 2.5, -2)
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <span>
#include <string>

#include "check.h"
#include "cli_run.h"
#include "collision/visibility_oracle.h"
#include "engine/scene.h"
#include "render/image.h"

namespace app {
namespace {

namespace fs = std::filesystem;
using cdlab_test::runCdlab;
using cdlab_test::slurp;

const std::string kClosingSpheres =
    "world: {bounds: {min: [-4, -4, -4], max: [4, 4, 4]}, time_step: 0.1, frames: 25}\n"
    "output: {width: 160, height: 120, fps: 10}\n"
    "camera: {position: [0, 0, 12], look_at: [0, 0, 0]}\n"
    "draw: {volumes: [aabb]}\n"
    "bodies:\n"
    "  - {name: a, shape: sphere, radius: 0.5, position: [-1.55, 0, 0], velocity: [1, 0, 0]}\n"
    "  - {name: b, shape: sphere, radius: 0.5, position: [1.55, 0, 0], velocity: [-1, 0, 0]}\n"
    "  - {name: c, shape: sphere, radius: 0.5, position: [0, 2.5, -2]}\n";

const fs::path kSource = CDLAB_SOURCE_DIR;
const fs::path kWalkthrough = kSource / "scenes" / "events" / "coursework_walkthrough.yaml";

// The two spheres with the track and expectations of `events_yaml` (an events file's text).
engine::Scene withTrack(const std::string& events_yaml) {
    engine::Scene scene = engine::parseScene(kClosingSpheres, "spheres.yaml", ".");
    engine::EventTrack track = engine::parseEventTrack(events_yaml, "track.yaml", scene);
    scene.events = std::move(track.events);
    scene.expect = std::move(track.expect);
    return scene;
}

const CheckRow& row(const std::vector<CheckRow>& rows, const std::string& expectation) {
    for (const CheckRow& r : rows) {
        if (r.expectation == expectation) return r;
    }
    static const CheckRow missing{"(missing)", false, "no such row"};
    ADD_FAILURE() << "no row \"" << expectation << "\"";
    return missing;
}

std::string trackError(const std::string& events_yaml) {
    try {
        withTrack(events_yaml);
    } catch (const engine::SceneError& e) {
        return e.what();
    }
    return "";
}

// A visibility oracle that calls every box fully visible: `cullide` then prunes every body and
// reports no pair at all, a broad phase broken on purpose behind its registry name.
class EverythingVisible final : public collision::VisibilityOracle {
public:
    int resolution() const override { return 64; }
    void fullyVisibleInOrder(std::span<const collision::Aabb>, int,
                             std::span<char> visible) override {
        std::fill(visible.begin(), visible.end(), char(1));
    }
};

TEST(CheckEvents, TheShippedWalkthroughPasses) {
    const fs::path dir = cdlab_test::tempDir("cdlab_check_events_", "walkthrough");
    const engine::Scene scene =
        loadCheckScene(kSource / "scenes" / "coursework.yaml", kWalkthrough, std::nullopt);
    ASSERT_EQ(scene.events.size(), 12u);
    const SceneReport report = gradeScene(scene, 0, std::nullopt, dir);
    ASSERT_EQ(report.outcome, SceneOutcome::Graded);
    for (const CheckRow& r : report.rows) EXPECT_TRUE(r.pass) << r.expectation << ": " << r.reason;
    // One row per broad phase the track uses, each graded while in use.
    for (const char* name : {"sap", "sphere", "hgrid-levels", "obb"}) {
        bool found = false;
        for (const CheckRow& r : report.rows) {
            found = found || r.expectation.rfind(std::string("broad phase ") + name + " equals ", 0) == 0;
        }
        EXPECT_TRUE(found) << name;
    }
    EXPECT_EQ(report.rows.size(), 2u + 4u + 1u + 3u + 2u);
    fs::remove_all(dir);
}

// Bug this guards against: a check that graded the scene without its events, or saw only the
// first visit of each frame. The track pauses at frame 24, where the spheres are apart again,
// switches to the broken cullide there (nothing to miss on that state) and steps back 10
// frames: the session restores frame 16's snapshot and re-simulates 17..23 with cullide, whose
// first step (frame 17, the spheres overlapping) misses the pair.
//
//   frames 0 ........ 11 ==overlap== 20 ... 24  pause, cullide, step -10
//                           16 <- restore; 17 re-simulated: missed (0 a, 1 b)
TEST(CheckEvents, ABrokenBroadPhaseSwitchedToFailsOnTheReSimulatedStep) {
    collision::setVisibilityOracleFactory(
        [] { return std::make_unique<EverythingVisible>(); });
    const engine::Scene scene = withTrack(
        "events:\n"
        "  - {frame: 24, pause: true, broadphase: cullide, step: -10}\n"
        "expect:\n"
        "  broadphases_in_use: [sap, cullide]\n");
    const std::vector<CheckRow> rows = checkScene(scene, 25, fs::temp_directory_path());
    collision::setVisibilityOracleFactory({});
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_TRUE(row(rows, "broad phase sap equals brute on every step it is in use").pass);
    const CheckRow& broken = row(rows, "broad phase cullide equals brute on every step it is in use");
    EXPECT_FALSE(broken.pass);
    EXPECT_EQ(broken.reason.rfind("differs at frame 17, step 17: broad phase 'cullide' reports 0 "
                                  "pairs, reference 'brute' reports 1;  missed (1): (0 a, 1 b)",
                                  0),
              0u)
        << broken.reason;
}

// Each new or adapted row fails with its reason when the run through the track cannot hold it.
TEST(CheckEvents, ExpectationsTheTrackCannotHoldFail) {
    const fs::path dir = cdlab_test::tempDir("cdlab_check_events_", "fail");
    const engine::Scene scene = withTrack(
        "events:\n"
        "  - {frame: 5, pause: true, broadphase: sphere, dump: true}\n"
        "  - {frame: 5, seek: {frame: 22}, play: true}\n"
        "  - {frame: 23, pause: true}\n"
        "expect:\n"
        "  min_bodies: 4\n"
        "  min_moving_rotating: 1\n"
        "  broadphases_in_use: [sap, hgrid]\n"
        "  pause_dumps: [5, 7]\n"
        "  pairs:\n"
        "    - {a: a, b: b, frames: [0, 4], flagged: false}\n"
        "    - {a: a, b: b, frames: [11, 20], colliding: true}\n"
        "    - {a: a, b: b, frames: [22, 24], colliding: false}\n");
    const std::vector<CheckRow> rows = checkScene(scene, 25, dir);
    EXPECT_EQ(row(rows, "at least 4 bodies").reason, "the scene has 3 bodies");
    EXPECT_EQ(row(rows, "at least 1 bodies moving and rotating").reason,
              "0 of 3 bodies both moved and rotated (> 1 degree) in 25 frames");
    EXPECT_TRUE(row(rows, "broad phase sap equals brute on every step it is in use").pass);
    EXPECT_EQ(row(rows, "broad phase hgrid equals brute on every step it is in use").reason,
              "never in use (the run used: sap, sphere)");
    EXPECT_EQ(row(rows, "broad phase sphere in use is listed").reason,
              "in use from frame 5 but not in expect.broadphases_in_use, so not graded");
    EXPECT_TRUE(row(rows, "pause dump at frame 5").pass) << row(rows, "pause dump at frame 5").reason;
    EXPECT_EQ(row(rows, "pause dump at frame 7").reason,
              "frame 7 is never reached through the events");
    EXPECT_TRUE(row(rows, "pair a / b not flagged at every frames 0..4").pass);
    EXPECT_EQ(row(rows, "pair a / b colliding at every frames 11..20").reason,
              "frame 11 is never reached through the events");
    EXPECT_EQ(row(rows, "pair a / b not colliding at every frames 22..24").reason,
              "frame 24 is never reached through the events");
    for (const CheckRow& r : rows) EXPECT_EQ(r.pass, r.reason.empty()) << r.expectation;

    // A listed frame the track reaches but never dumps.
    const engine::Scene no_dump = withTrack(
        "events:\n"
        "  - {frame: 3, dump: true}\n"
        "  - {frame: 5, pause: true, dump: true}\n"
        "  - {frame: 5, play: true}\n"
        "expect:\n"
        "  pause_dumps: [4]\n");
    const std::vector<CheckRow> dump_rows = checkScene(no_dump, 25, dir);
    ASSERT_EQ(dump_rows.size(), 1u);
    EXPECT_EQ(dump_rows[0].reason,
              "no entry of the events track dumps frame 4 (its dumps: frames 3, 5)");
    fs::remove_all(dir);
}

// The dumps check writes are the ones `cdlab run --events` writes (the same view, camera and
// HUD, the same JSON to the byte), and the frames it grades are the ones run shows.
TEST(CheckEvents, DumpsAreThoseRunWritesOfTheSameTrack) {
    const fs::path dir = cdlab_test::tempDir("cdlab_check_events_", "run");
    std::ofstream(dir / "track.yaml")
        << "events:\n"
           "  - {frame: 10, pause: true, show: [obb, labels], wait: 1}\n"
           "  - {frame: 10, camera: {orbit: [30, 10]}, select: ring4, broadphase: hgrid, "
           "dump: true}\n"
           "  - {frame: 10, step: -3, dump: true}\n"
           "  - {frame: 7, play: true}\n"
           "expect:\n"
           "  broadphases_in_use: [sap, hgrid]\n"
           "  pause_dumps: [7, 10]\n";
    const std::string args = "scenes/coursework.yaml --frames 20 --events " +
                             (dir / "track.yaml").string();
    cdlab_test::CliResult r =
        runCdlab("run " + args + " --no-video --no-frames --quiet --out " + (dir / "run").string(),
                 dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = runCdlab("check " + args + " --out " + (dir / "check").string(), dir);
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    for (const std::string stem : {"pause_7", "pause_10"}) {
        SCOPED_TRACE(stem);
        const std::string json = slurp(dir / "run" / (stem + ".json"));
        ASSERT_FALSE(json.empty());
        EXPECT_EQ(slurp(dir / "check" / "0_coursework" / (stem + ".json")), json);
        const render::Image ran = render::readPng(dir / "run" / (stem + ".png"));
        const render::Image checked =
            render::readPng(dir / "check" / "0_coursework" / (stem + ".png"));
        EXPECT_EQ(checked.rgb, ran.rgb);
    }
    fs::remove_all(dir);
}

TEST(CheckEvents, BadKeysAreRefusedByName) {
    const std::string track = "events:\n  - {frame: 5, broadphase: sphere}\n";
    EXPECT_EQ(trackError(track + "expect:\n  broadphases_in_use: [sap, nope]\n")
                  .rfind("track.yaml:4:29: expect.broadphases_in_use[1]: unknown broad phase "
                         "'nope' (expected one of: ",
                         0),
              0u)
        << trackError(track + "expect:\n  broadphases_in_use: [sap, nope]\n");
    EXPECT_EQ(trackError(track + "expect:\n  broadphases_in_use: [sap, sphere, sap]\n"),
              "track.yaml:4:37: expect.broadphases_in_use[2]: 'sap' is listed twice");
    EXPECT_EQ(trackError(track + "expect:\n  broadphases_in_use: []\n"),
              "track.yaml:4:23: expect.broadphases_in_use: empty list: states no expectation");
    EXPECT_EQ(trackError(track + "expect:\n  broadphase_in_use: [sap]\n")
                  .rfind("track.yaml:4:3: expect.broadphase_in_use: unknown key 'broadphase_in_use' "
                         "(expected one "
                         "of: frames, min_bodies, min_moving_rotating, broadphases, "
                         "broadphases_in_use,",
                         0),
              0u);
    EXPECT_EQ(trackError(track + "expect:\n  pause_dumps: [25]\n"),
              "track.yaml:4:17: expect.pause_dumps[0]: frame out of range (the check runs "
              "frames 0..24)");
    EXPECT_EQ(trackError(track + "expected: {min_bodies: 1}\n"),
              "track.yaml:3:1: expected: unknown key 'expected' (expected one of: events, expect)");
    // Colours count a picture, and a track's picture is its view: refused, at their line.
    EXPECT_EQ(trackError(track + "expect:\n  colors:\n    - {frame: 1, present: [green]}\n"),
              "track.yaml:5:7: expect.colors[0]: not graded in a run through an events track "
              "(its picture is the view the track sets: volumes shown, camera, selection); "
              "grade colours in a scene's expect: without events");
    try {
        engine::parseScene(kClosingSpheres +
                               "expect:\n  colors:\n    - {frame: 1, present: [green]}\n"
                               "events:\n  - {frame: 5, pause: true}\n",
                           "inline.yaml", ".");
        ADD_FAILURE() << "a scene with events and colours loaded";
    } catch (const engine::SceneError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("inline.yaml:11:7: expect.colors[0]: not graded", 0),
                  0u)
            << e.what();
    }
}

// --- through the binary ---

TEST(CheckEventsCli, OneCommandGradesTheWalkthroughAndRefusesWhatCannotBeGraded) {
    const fs::path dir = cdlab_test::tempDir("cdlab_check_events_", "cli");
    const std::string walk = "scenes/events/coursework_walkthrough.yaml";
    // The same table in this process and in a child process (-j 1 --timeout grades in one).
    cdlab_test::CliResult r = runCdlab("check scenes/coursework.yaml --events " + walk, dir);
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("scenes/coursework.yaml --events " + walk +
                         "  broad phase hgrid-levels equals brute on every step it is in use"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("1 scene, 12 expectations, 0 failed"), std::string::npos) << r.out;
    const cdlab_test::CliResult child =
        runCdlab("check --timeout 600 scenes/coursework.yaml --events " + walk, dir);
    EXPECT_EQ(child.exit_code, 0) << child.err;
    EXPECT_EQ(child.out, r.out);

    // An events file without expect: gets the scene's, and coursework's colours cannot be
    // graded through a track: bad input, named at their line, before anything runs.
    std::ofstream(dir / "bare.yaml") << "events:\n  - {frame: 5, pause: true}\n";
    r = runCdlab("check scenes/coursework.yaml --events " + (dir / "bare.yaml").string(), dir);
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_NE(r.err.find("scenes/coursework.yaml:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(": expect.colors[0]: not graded in a run through an events track"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.out, "");
    r = runCdlab("check scenes/coursework.yaml --events " + (dir / "none.yaml").string(), dir);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("none.yaml:1:1: events: cannot open the file (no such file)"),
              std::string::npos)
        << r.err;
    fs::remove_all(dir);
}

}  // namespace
}  // namespace app
