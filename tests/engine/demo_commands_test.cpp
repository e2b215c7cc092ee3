// tests/engine/demo_commands_test.cpp -- the demo command vocabulary as the scene loader reads
// it: a scene's events track, a separate events file, one live command; every bad command refused
// at its key with the choices, and tracks whose entries a run could never reach refused whole.
#include <gtest/gtest.h>

#include "engine/demo_commands.h"
#include "scene_error.h"
#include "scene_text.h"

namespace engine {
namespace {

using scene_text::kValid;

// kValid names its body "sphere0"; 120 frames at 1/30 s (2 steps of 1/60 s).
const std::string kDemoScene = kValid + "  - {name: ball, shape: sphere, radius: 0.25, position: [3, 0, 0]}\n";

std::string withDemoEvents(const std::string& events) { return kDemoScene + "events:\n" + events; }

TEST(DemoCommands, EveryCommandIsReadAndAtTimesBecomeFrames) {
    const Scene scene = scene_text::parse(withDemoEvents(
        "  - {frame: 3, pause: true, show: [obb, labels], hide: sphere, wait: 1.5}\n"
        "  - {frame: 3, broadphase: hgrid, select: ball, dump: true}\n"
        "  - {frame: 3, camera: {orbit: [30, -10], zoom: 2, pan: [1, 0.5], follow: ball}}\n"
        "  - {frame: 3, step: -2, speed: 0.5}\n"
        "  - {frame: 1, play: true}\n"
        "  - {at: 0.5, seek: {time: 0.2}, camera: {reset: true, follow: none}, select: none}\n"));
    ASSERT_EQ(scene.events.size(), 6u);
    const DemoCommands& a = scene.events[0].commands;
    EXPECT_EQ(scene.events[0].frame, 3);
    EXPECT_EQ(scene.events[0].line, 7);
    EXPECT_EQ(a.playing, std::optional<bool>(false));
    EXPECT_EQ(a.show, (std::vector<DemoLayer>{DemoLayer::Obb, DemoLayer::Labels}));
    EXPECT_EQ(a.hide, (std::vector<DemoLayer>{DemoLayer::Sphere}));
    EXPECT_EQ(a.wait_s, 1.5);
    const DemoCommands& b = scene.events[1].commands;
    EXPECT_EQ(b.broad_phase, std::optional<std::string>("hgrid"));
    EXPECT_EQ(b.select, std::optional<std::optional<BodyId>>(BodyId(1)));
    EXPECT_TRUE(b.dump);
    const CameraCommand& cam = *scene.events[2].commands.camera;
    EXPECT_EQ((*cam.orbit)[0], 30);
    EXPECT_EQ((*cam.orbit)[1], -10);
    EXPECT_EQ(*cam.zoom, 2);
    EXPECT_EQ((*cam.pan)[1], 0.5);
    EXPECT_EQ(*cam.follow, std::optional<BodyId>(1));
    EXPECT_EQ(scene.events[3].commands.step, -2);
    EXPECT_EQ(scene.events[3].commands.speed, 0.5);
    // 0.5 s is frame 15 and 0.2 s frame 6 (1/30 s a frame).
    EXPECT_EQ(scene.events[5].frame, 15);
    EXPECT_EQ(scene.events[5].commands.seek, 6);
    EXPECT_TRUE(scene.events[5].commands.camera->reset);
    EXPECT_EQ(*scene.events[5].commands.camera->follow, std::nullopt);
    ASSERT_TRUE(scene.events[5].commands.select.has_value());  // `select: none`: clear
    EXPECT_FALSE(scene.events[5].commands.select->has_value());
}

TEST(DemoCommands, BadCommandsAreErrorsAtTheirKey) {
    // Line 7 holds the first event.
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, shwo: [obb]}\n"), "7:16: events[0].shwo: ",
                       "unknown key 'shwo' (expected one of: frame, at, play, pause");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, show: [obbs]}\n"), "7:23: events[0].show[0]: ",
                       "unknown layer 'obbs' (expected one of: sphere, aabb, obb, kdop6");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, show: [obb, obb]}\n"), "7:28: events[0].show[1]: ",
                       "'obb' is listed twice");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, show: obb, hide: [obb]}\n"), "7:5: events[0]: ",
                       "'obb' is both shown and hidden");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, broadphase: sapp}\n"), "7:28: events[0].broadphase: ",
                       "unknown broad phase 'sapp' (expected one of: ");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, select: nobody}\n"), "7:24: events[0].select: ",
                       "no body is named 'nobody'");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, camera: {follow: nobody}}\n"),
                       "7:33: events[0].camera.follow: ", "no body is named 'nobody'");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, camera: {zoom: 0}}\n"), "7:31: events[0].camera.zoom: ",
                       "must be from 0.01 to 100");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, camera: {orbit: [1, .nan]}}\n"),
                       "7:36: events[0].camera.orbit[1]: ", "must be finite");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, camera: {}}\n"), "7:24: events[0].camera: ",
                       "no camera move");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, speed: 100}\n"), "7:23: events[0].speed: ",
                       "must be from 1/16 to 16");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, wait: -1}\n"), "7:22: events[0].wait: ", "must be > 0");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, pause: false}\n"), "7:23: events[0].pause: ",
                       "write 'pause: true' (the opposite is 'play: true')");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, play: true, pause: true}\n"),
                       "7:28: events[0].pause: ", "play and pause in one command");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, step: 0}\n"), "7:22: events[0].step: ", "must not be 0");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 1, seek: {frame: 1, time: 0}}\n"), "7:22: events[0].seek: ",
                       "exactly one of 'frame' or 'time'");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 120, dump: true}\n"), "7:13: events[0].frame: ",
                       "frame out of range (the run has frames 0..119)");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {at: 4.5, dump: true}\n"), "7:10: events[0].at: ",
                       "time out of range");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {dump: true}\n"), "7:5: events[0]: ",
                       "needs exactly one of 'frame' (a frame) or 'at' (seconds)");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 2}\n"), "7:5: events[0]: ", "no command");
    EXPECT_SCENE_ERROR(withDemoEvents("  []\n"), "7:3: events: ", "empty list");
    EXPECT_SCENE_ERROR(kDemoScene + "events: {frame: 1}\n", "6:9: events: ", "expected a list of events");
}

TEST(DemoCommands, EntriesARunCanNeverReachAreRefused) {
    // Left behind by playing on.
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 9, dump: true}\n  - {frame: 4, dump: true}\n"),
                       "8:5: events[1]: ", "frame 4 is never reached");
    // Ahead of a pause that nothing ends.
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 9, pause: true}\n  - {frame: 12, dump: true}\n"),
                       "8:5: events[1]: ", "the run is paused at frame 9");
    // Reached after a seek back, or at a step's target while paused.
    EXPECT_NO_THROW(scene_text::parse(
        withDemoEvents("  - {frame: 9, seek: {frame: 2}}\n  - {frame: 4, pause: true, step: 3}\n"
                   "  - {frame: 7, play: true}\n")));
    // Steps that leave the run.
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 2, step: -3}\n"), "7:5: events[0]: ",
                       "step -3 from frame 2 leaves the run's frames 0..119");
    EXPECT_SCENE_ERROR(withDemoEvents("  - {frame: 110, step: 10}\n"), "7:5: events[0]: ",
                       "step 10 from frame 110 leaves");
}

TEST(DemoCommands, EventsFilesAndLiveCommandsAreReadAgainstTheScene) {
    const Scene scene = scene_text::parse(kDemoScene);
    const std::vector<DemoEvent> events =
        parseEvents("events:\n  - {frame: 5, pause: true, show: [aabb]}\n", "demo.yaml", scene);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].frame, 5);
    auto errorOf = [&](auto&& parse) -> std::string {
        try {
            parse();
        } catch (const SceneError& e) {
            return e.what();
        }
        return "";
    };
    EXPECT_EQ(errorOf([&] { parseEvents("event: []\n", "demo.yaml", scene); }),
              "demo.yaml:1:1: event: unknown key 'event' (expected one of: events, expect)");
    EXPECT_EQ(errorOf([&] { parseEvents("events: [{frame: 1, dump: true}]\n---\n", "demo.yaml", scene); })
                  .rfind("demo.yaml:2:1: scene: a second YAML document", 0),
              0u);
    EXPECT_NE(errorOf([&] { parseEvents("events: [{frame: 1", "demo.yaml", scene); })
                  .find("malformed YAML"),
              std::string::npos);
    // One command as JSON, as a live session receives it; wait belongs to tracks only.
    const DemoCommands c = parseDemoCommands(R"({"step": -1, "show": ["obb"], "select": "ball"})",
                                             "request", scene);
    EXPECT_EQ(c.step, -1);
    EXPECT_EQ(c.select, std::optional<std::optional<BodyId>>(BodyId(1)));
    EXPECT_EQ(errorOf([&] { parseDemoCommands(R"({"wait": 1})", "request", scene); }),
              "request:1:2: command.wait: unknown key 'wait' (expected one of: play, pause, step, "
              "seek, show, hide, broadphase, select, camera, dump, speed)");
    EXPECT_EQ(errorOf([&] { parseDemoCommands("{}", "request", scene); }).rfind("request:1:1: command: no command", 0), 0u);
    EXPECT_EQ(errorOf([&] { parseDemoCommands("[1, 2]", "request", scene); })
                  .rfind("request:1:1: command: expected a mapping", 0),
              0u);
}

// A track written out (a live session's log) reads back to the same commands: every command,
// numbers to the last bit, a body whose name needs quoting.
TEST(DemoCommands, ATrackWrittenOutReadsBackTheSame) {
    const Scene scene = scene_text::parse(
        kDemoScene + "  - {name: 'odd: [name]', shape: sphere, radius: 0.25, position: [0, 3, 0]}\n" +
        "events:\n"
        "  - {frame: 3, pause: true, show: [obb, labels], hide: sphere, wait: 1.5}\n"
        "  - {frame: 3, broadphase: hgrid, select: 'odd: [name]', dump: true}\n"
        "  - {frame: 3, camera: {orbit: [0.1, -10.3], zoom: 1.1, pan: [1e-7, 0.5], follow: ball}}\n"
        "  - {frame: 3, step: -2, speed: 0.3}\n"
        "  - {frame: 1, play: true}\n"
        "  - {at: 0.5, seek: {time: 0.2}, camera: {reset: true, follow: none}, select: none}\n");
    const std::string text = eventsYaml(scene.events, scene);
    const std::vector<DemoEvent> back = parseEvents(text, "log.yaml", scene);
    ASSERT_EQ(back.size(), scene.events.size()) << text;
    EXPECT_EQ(eventsYaml(back, scene), text);
    for (std::size_t i = 0; i < back.size(); ++i) {
        SCOPED_TRACE(i);
        const DemoCommands& a = scene.events[i].commands;
        const DemoCommands& b = back[i].commands;
        EXPECT_EQ(back[i].frame, scene.events[i].frame);
        EXPECT_EQ(b.broad_phase, a.broad_phase);
        EXPECT_EQ(b.show, a.show);
        EXPECT_EQ(b.hide, a.hide);
        EXPECT_EQ(b.select, a.select);
        EXPECT_EQ(b.speed, a.speed);
        EXPECT_EQ(b.playing, a.playing);
        EXPECT_EQ(b.step, a.step);
        EXPECT_EQ(b.seek, a.seek);
        EXPECT_EQ(b.dump, a.dump);
        EXPECT_EQ(b.wait_s, a.wait_s);
        ASSERT_EQ(b.camera.has_value(), a.camera.has_value());
        if (!a.camera) continue;
        EXPECT_EQ(b.camera->reset, a.camera->reset);
        EXPECT_EQ(b.camera->orbit, a.camera->orbit);
        EXPECT_EQ(b.camera->zoom, a.camera->zoom);
        EXPECT_EQ(b.camera->pan, a.camera->pan);
        EXPECT_EQ(b.camera->follow, a.camera->follow);
    }
    EXPECT_EQ(back[1].commands.select, std::optional<std::optional<BodyId>>(BodyId(2)));
}

TEST(DemoCommands, LayerNamesRoundTrip) {
    for (int i = 0; i <= int(DemoLayer::Hud); ++i) {
        EXPECT_EQ(findDemoLayer(demoLayerName(DemoLayer(i))), DemoLayer(i));
    }
    EXPECT_EQ(findDemoLayer("OBB"), std::nullopt);
}

}  // namespace
}  // namespace engine
