// tests/app/demo_session_test.cpp -- a demo session driven by the command vocabulary: stepping
// back and seeking give the first visit's state bit for bit, refused commands change nothing,
// layers and the broad phase switch as asked, the camera moves as stated; and `cdlab run` with
// an events track writes the frames, dumps and video frames the track asks for, the same twice.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.h"
#include "demo/demo_session.h"
#include "engine/scene.h"
#include "render/camera_moves.h"

namespace {

namespace fs = std::filesystem;
using cdlab_test::runCdlab;
using cdlab_test::slurp;

engine::Scene coursework() {
    return engine::loadScene(fs::path(CDLAB_SOURCE_DIR) / "scenes" / "coursework.yaml");
}

engine::DemoCommands command(const engine::Scene& scene, const std::string& text) {
    return engine::parseDemoCommands(text, "test", scene);
}

TEST(DemoSession, SteppingBackAndSeekingGiveTheFirstVisitBitForBit) {
    const engine::Scene scene = coursework();
    app::DemoSession session(scene, false);
    std::vector<std::uint64_t> hashes{session.world().stateHash()};
    while (session.frame() < 40) {
        ASSERT_TRUE(session.advance());
        hashes.push_back(session.world().stateHash());
    }
    std::vector<int> reached;
    const auto note = [&] { reached.push_back(session.frame()); };
    ASSERT_EQ(session.apply(command(scene, "{step: -3}"), note), "");
    EXPECT_EQ(reached, (std::vector<int>{39, 38, 37}));
    EXPECT_EQ(session.world().stateHash(), hashes[37]);
    for (const int f : {5, 0, 17, 40, 23, 9}) {
        ASSERT_EQ(session.apply(command(scene, "{seek: {frame: " + std::to_string(f) + "}}")), "");
        EXPECT_EQ(session.frame(), f);
        EXPECT_EQ(session.world().stateHash(), hashes[std::size_t(f)]) << "frame " << f;
        EXPECT_EQ(session.world().stepCount(), std::int64_t(f) * scene.steps_per_frame);
    }
    ASSERT_EQ(session.apply(command(scene, "{step: 4}"), note), "");
    EXPECT_EQ(session.world().stateHash(), hashes[13]);
}

TEST(DemoSession, RefusedCommandsChangeNothing) {
    const engine::Scene scene = coursework();
    app::DemoSession session(scene, false);
    for (int i = 0; i < 3; ++i) session.advance();
    const std::uint64_t hash = session.world().stateHash();
    const std::string problem =
        session.apply(command(scene, "{step: -5, show: [obb], broadphase: hgrid, pause: true}"));
    EXPECT_EQ(problem, "step -5 from frame 3 leaves the run's frames 0.." +
                           std::to_string(scene.frames - 1));
    EXPECT_EQ(session.frame(), 3);
    EXPECT_EQ(session.world().stateHash(), hash);
    EXPECT_FALSE(session.view().draw.obb);
    EXPECT_EQ(session.world().broadPhase().name(), scene.world.broad_phase);
    EXPECT_TRUE(session.playing());
}

TEST(DemoSession, LayersAndBroadPhaseSwitchAsAsked) {
    engine::Scene scene = coursework();
    scene.draw.volumes_given = false;  // the volumes follow the broad phase
    app::DemoSession session(scene, false);
    ASSERT_EQ(session.world().broadPhase().name(), "sap");
    EXPECT_TRUE(session.view().draw.aabb);
    EXPECT_FALSE(session.view().draw.sphere);
    ASSERT_EQ(session.apply(command(scene, "{broadphase: sphere}")), "");
    EXPECT_EQ(session.world().broadPhase().name(), "sphere");
    EXPECT_TRUE(session.view().draw.sphere);
    EXPECT_FALSE(session.view().draw.aabb);
    ASSERT_EQ(session.apply(command(scene, "{show: [obb, labels, structure, hierarchy], "
                                           "hide: [hud, bounds], select: ring4}")),
              "");
    const render::FrameOptions o = session.frameOptions();
    EXPECT_TRUE(o.draw.obb && o.draw.labels && o.draw_structure);
    EXPECT_EQ(o.draw.bvh_depth, 2);
    EXPECT_FALSE(o.draw.hud || o.draw.bounds);
    ASSERT_TRUE(o.selected.has_value());
    EXPECT_EQ(scene.bodies[std::size_t(*o.selected)].name, "ring4");
    // Chosen volumes stay when the broad phase changes again.
    ASSERT_EQ(session.apply(command(scene, "{broadphase: obb}")), "");
    EXPECT_TRUE(session.view().draw.sphere && session.view().draw.obb);
    ASSERT_EQ(session.apply(command(scene, "{select: none, pause: true}")), "");
    EXPECT_FALSE(session.frameOptions().selected.has_value());
    EXPECT_FALSE(session.playing());
}

// Switching the broad phase redraws the volume it tests and nothing else: labels, contacts and
// the hierarchy shown before stay (they were once reset to the scene's with the volumes).
TEST(DemoSession, ABroadPhaseSwitchKeepsTheLayersShown) {
    engine::Scene scene = coursework();
    scene.draw.volumes_given = false;
    app::DemoSession session(scene, false);
    ASSERT_EQ(session.apply(command(scene, "{show: [labels, contacts, hierarchy], hide: [hud]}")),
              "");
    ASSERT_EQ(session.apply(command(scene, "{broadphase: sphere}")), "");
    EXPECT_TRUE(session.view().draw.sphere);
    EXPECT_FALSE(session.view().draw.aabb);
    for (const engine::DemoLayer l : {engine::DemoLayer::Labels, engine::DemoLayer::Contacts,
                                      engine::DemoLayer::Hierarchy}) {
        EXPECT_TRUE(session.shows(l)) << engine::demoLayerName(l);
    }
    EXPECT_FALSE(session.shows(engine::DemoLayer::Hud));
}

// A switch takes effect on the frame it is made: the pairs and states shown at once are the new
// broad phase's on the current state (those of a session that ran it from the start), at a frame
// where the two broad phases' volumes flag different pairs; and again after stepping back.
TEST(DemoSession, ASwitchedBroadPhaseDecidesTheFrameItIsMadeOn) {
    const engine::Scene scene = coursework();
    engine::Scene spheres = scene;
    spheres.world.broad_phase = "sphere";
    app::DemoSession session(scene, false), reference(spheres, false);
    const auto pairsOf = [](const engine::World& w) {
        const auto p = w.flaggedPairs();
        return std::vector<collision::ProxyPair>(p.begin(), p.end());
    };
    while (pairsOf(session.world()) == pairsOf(reference.world())) {
        ASSERT_TRUE(session.advance() && reference.advance()) << "sap and sphere never differ";
    }
    ASSERT_EQ(session.apply(command(scene, "{broadphase: sphere}")), "");
    EXPECT_EQ(pairsOf(session.world()), pairsOf(reference.world())) << "frame " << session.frame();
    EXPECT_TRUE(std::equal(session.world().states().begin(), session.world().states().end(),
                           reference.world().states().begin()));
    const int frame = session.frame();
    ASSERT_EQ(session.apply(command(scene, "{step: -1}")), "");
    reference.goTo(frame - 1);
    EXPECT_EQ(pairsOf(session.world()), pairsOf(reference.world()));
}

TEST(DemoSession, SnapshotsStayBoundedOnLongRuns) {
    engine::Scene scene = engine::parseScene(
        "world: {bounds: {min: [-5, -5, -5], max: [5, 5, 5]}, frames: 2000, gravity: [0, 0, 0]}\n"
        "bodies:\n  - {shape: sphere, radius: 0.5, position: [0, 0, 0], velocity: [1, 0.5, 0]}\n",
        "long.yaml", ".");
    app::DemoSession session(scene, false);
    std::vector<std::uint64_t> hashes{session.world().stateHash()};
    while (session.advance()) hashes.push_back(session.world().stateHash());
    EXPECT_EQ(session.frame(), 1999);
    EXPECT_LE(int(session.snapshots()), app::DemoSession::kMaxSnapshots);
    EXPECT_GT(session.snapshotInterval(), 8);
    session.goTo(1234);
    EXPECT_EQ(session.world().stateHash(), hashes[1234]);
}

TEST(DemoSession, CameraMovesDoWhatTheySay) {
    engine::CameraSettings cam;
    cam.position = {0, 8, 24};
    cam.look_at = {0, 0, 0};
    const double d = cam.position.norm();
    const engine::CameraSettings zoomed = render::zoomCamera(cam, 2);
    EXPECT_NEAR(zoomed.position.norm(), d / 2, 1e-12);
    const engine::CameraSettings panned = render::panCamera(cam, 1, 0);
    EXPECT_NEAR((panned.position - cam.position).x(), 1, 1e-12);
    EXPECT_NEAR((panned.look_at - cam.look_at).x(), 1, 1e-12);
    // A quarter turn to the right puts the eye on +x at the same height and distance.
    const engine::CameraSettings turned = render::orbitCamera(cam, 90, 0);
    EXPECT_NEAR(turned.position.x(), 24, 1e-9);
    EXPECT_NEAR(turned.position.y(), 8, 1e-9);
    EXPECT_NEAR(turned.position.z(), 0, 1e-9);
    // Raising the eye stops a degree short of the pole.
    const engine::CameraSettings top = render::orbitCamera(cam, 0, 170);
    const double from_up = std::acos(top.position.normalized().y()) * 180 / M_PI;
    EXPECT_NEAR(from_up, 1, 1e-9);
    EXPECT_NEAR(top.position.norm(), d, 1e-9);
    const engine::CameraSettings followed = render::lookAtPoint(cam, {1, 2, 3});
    EXPECT_EQ(followed.look_at, engine::Vec3(1, 2, 3));
    EXPECT_EQ(followed.position, engine::Vec3(1, 10, 27));
}

TEST(DemoSession, SelectionLineNamesThePairs) {
    const engine::Scene scene = coursework();
    app::DemoSession session(scene, false);
    const std::string line = app::selectionLine(session.world(), 0);
    EXPECT_EQ(line.rfind("selected ball0 (sphere)", 0), 0u) << line;
}

// The track the end-to-end tests follow, on a 40-frame coursework run.
const std::string kTrack =
    "events:\n"
    "  - {frame: 10, pause: true, show: [obb, labels], wait: 1}\n"
    "  - {frame: 10, camera: {orbit: [30, 10]}, select: ring4, broadphase: hgrid, dump: true}\n"
    "  - {frame: 10, step: -3, wait: 0.5}\n"
    "  - {frame: 7, play: true, speed: 0.5}\n"
    "  - {frame: 12, seek: {frame: 30}, speed: 1}\n";

TEST(RunEvents, TheTrackGivesItsFramesDumpsAndVideoTheSameTwice) {
    const fs::path dir = cdlab_test::tempDir("cdlab_events_", "track");
    std::ofstream(dir / "track.yaml") << kTrack;
    std::vector<std::string> traces;
    for (const std::string run : {"a", "b"}) {
        const auto r = runCdlab("run scenes/coursework.yaml --frames 40 --no-hud-timing --events " +
                                    (dir / "track.yaml").string() + " --out " +
                                    (dir / run).string() + " --trace " +
                                    (dir / run / "trace.jsonl").string() + " --quiet",
                                dir);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_NE(r.out.find("5 events, ending on hgrid"), std::string::npos) << r.out;
        EXPECT_TRUE(fs::exists(dir / run / "pause_10.png"));
        const auto summary = nlohmann::json::parse(slurp(dir / run / "summary.json"));
        EXPECT_EQ(summary["events"], 5);
        EXPECT_EQ(summary["final_broadphase"], "hgrid");
        traces.push_back(slurp(dir / run / "trace.jsonl"));
        if (cdlab_test::haveFfprobe()) {
            // Frames 0..10 (11), 1 s + 0.5 s held at 30 fps (45), frames 9, 8, 7 stepped back
            // (3), 8..12 at half speed (10), the seek's frame 30 and 31..39 (10).
            EXPECT_EQ(cdlab_test::probeVideo(dir / run / "coursework.mp4", dir)["nb_read_frames"],
                      "79");
        }
    }
    EXPECT_EQ(traces[0], traces[1]);
    EXPECT_EQ(slurp(dir / "a" / "pause_10.png"), slurp(dir / "b" / "pause_10.png"));
    EXPECT_EQ(slurp(dir / "a" / "frame_00035.png"), slurp(dir / "b" / "frame_00035.png"));
    // Frame 7 and 8 shown twice (played, then reached by stepping back and playing on): the
    // same state both times; the trace holds a line per frame shown.
    std::vector<std::string> lines;
    std::istringstream in(traces[0]);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    ASSERT_EQ(lines.size(), std::size_t(11 + 3 + 5 + 10));
    EXPECT_EQ(lines[7], lines[13]);  // frame 7: first visit; after the steps 9, 8, 7
    EXPECT_EQ(lines[8], lines[12]);
    EXPECT_EQ(nlohmann::json::parse(lines[19])["frame"], 30);
}

TEST(RunEvents, BadEventsFilesAreRefusedByName) {
    const fs::path dir = cdlab_test::tempDir("cdlab_events_", "bad");
    std::ofstream(dir / "bad.yaml") << "events:\n  - {frame: 10, show: [obbb]}\n";
    auto r = runCdlab("run scenes/coursework.yaml --no-video --events " + (dir / "bad.yaml").string() +
                          " --out " + (dir / "out").string(),
                      dir);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find((dir / "bad.yaml").string() + ":2:24: events[0].show[0]: unknown layer 'obbb'"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "out" / "summary.json"));
    r = runCdlab("run scenes/coursework.yaml --no-video --events " + (dir / "none.yaml").string(), dir);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("none.yaml:1:1: events: cannot open the file (no such file)"),
              std::string::npos)
        << r.err;
    // A track valid for the scene's frames but not for --frames.
    std::ofstream(dir / "late.yaml") << "events:\n  - {frame: 50, dump: true}\n";
    r = runCdlab("run scenes/coursework.yaml --no-video --frames 20 --events " +
                     (dir / "late.yaml").string(),
                 dir);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("frame out of range (the run has frames 0..19)"), std::string::npos) << r.err;
}

}  // namespace

namespace {

TEST(RunEvents, TheShippedWalkthroughLoadsAgainstTheCoursework) {
    const engine::Scene scene = coursework();
    const std::vector<engine::DemoEvent> events = engine::loadEvents(
        fs::path(CDLAB_SOURCE_DIR) / "scenes" / "events" / "coursework_walkthrough.yaml", scene);
    EXPECT_EQ(events.size(), 12u);
    EXPECT_EQ(events.back().frame, 90);
}

}  // namespace
