// tests/app/pause_picture_test.cpp -- end to end: `cdlab run` draws the volume its broad phase
// tests, the pause picture and dump judge every volume by its own overlap test, and
// --pause-hold holds the pause picture in the video.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_run.h"
#include "engine/world_draw.h"
#include "render/image.h"
#include "render/pixel_checks.h"

namespace {

namespace fs = std::filesystem;
using cdlab_test::CliResult;
using cdlab_test::runCdlab;
using cdlab_test::slurp;
using namespace cdlab_test;

using cdlab_test::kTiny;

fs::path pauseDir(const std::string& name) { return cdlab_test::tempDir("cdlab_pause_", name); }

// A scene without draw.volumes (so a run draws its broad phase's volume), no HUD and no bounds,
// seen head-on by a camera at (cx, cy, 9) looking along -z.
std::string sceneText(double cx, double cy, const std::string& bodies) {
    return "world:\n  bounds: {min: [-20, -20, -20], max: [20, 20, 20]}\n  time_step: 0.01\n"
           "  frames: 3\nbroadphase: sap\noutput: {width: 320, height: 240, fps: 10}\n"
           "camera: {position: [" +
           std::to_string(cx) + ", " + std::to_string(cy) + ", 9], look_at: [" +
           std::to_string(cx) + ", " + std::to_string(cy) +
           ", 0], up: [0, 1, 0], fov_deg: 45}\n"
           "draw: {hud: false, bounds: false, bodies: false}\nbodies:\n" +
           bodies;
}

// D and E diagonal: AABBs (and the spheres' cube OBBs) overlap, spheres do not; F alone.
const std::string kDiagonalBodies =
    "  - {name: d, shape: sphere, radius: 0.8, position: [-1.2, -0.6, 0]}\n"
    "  - {name: e, shape: sphere, radius: 0.8, position: [0, 0.6, 0]}\n"
    "  - {name: f, shape: sphere, radius: 0.8, position: [2.8, 0, 0]}\n";

// Two parallel rods turned 45 degrees about z, side by side: AABBs overlap, OBBs do not.
const std::string kRodBodies =
    "  - {name: rod1, shape: box, half_extents: [1, 0.15, 0.15], euler_deg: [0, 0, 45], "
    "position: [-0.3, 0.3, 0]}\n"
    "  - {name: rod2, shape: box, half_extents: [1, 0.15, 0.15], euler_deg: [0, 0, 45], "
    "position: [0.3, -0.3, 0]}\n";

fs::path writeScene(const fs::path& dir, const std::string& name, const std::string& text) {
    const fs::path file = dir / name;
    std::ofstream(file) << text;
    return file;
}

engine::CameraSettings cameraAt(double cx, double cy) {
    engine::CameraSettings cam = headOnCamera();
    cam.position = Vec3(cx, cy, 9);
    cam.look_at = Vec3(cx, cy, 0);
    return cam;
}

const Rgb kGreen = toRgb(engine::stateColor(engine::BodyState::Apart));
const Rgb kYellow = toRgb(engine::stateColor(engine::BodyState::Flagged));

}  // namespace

// Each volume is coloured by its own test: D's sphere stays green though its AABB is flagged,
// and the dump lists each volume's own state, as the picture shows it.
TEST(PausePicture, EachVolumeTakesItsOwnTestsStateInPictureAndDump) {
    const fs::path work = pauseDir("own");
    const fs::path scene =
        writeScene(work, "diagonal.yaml", sceneText(-1.2, -0.6, kDiagonalBodies));
    const fs::path out = work / "out";
    const CliResult r =
        runCdlab("run " + scene.string() + " --no-video --pause-at 1 --out " + out.string(), work);
    ASSERT_EQ(r.exit_code, 0) << r.err;

    const nlohmann::json dump = nlohmann::json::parse(slurp(out / "pause_1.json"));
    EXPECT_EQ(dump["broadphase_volume"], "aabb");
    const nlohmann::json& d = dump["bodies"][0];
    EXPECT_EQ(d["state"], "flagged");  // by the broad phase, on AABBs
    EXPECT_EQ(d["volume_states"]["sphere"], "apart");
    EXPECT_EQ(d["volume_states"]["aabb"], "overlapping");
    EXPECT_EQ(d["volume_states"]["obb"], "overlapping");
    EXPECT_EQ(dump["bodies"][2]["volume_states"]["aabb"], "apart");
    EXPECT_EQ(dump["overlapping_pairs"]["sphere"], nlohmann::json::array());
    EXPECT_EQ(dump["overlapping_pairs"]["aabb"], nlohmann::json::array({{0, 1}}));
    EXPECT_EQ(dump["overlapping_pairs"]["obb"], nlohmann::json::array({{0, 1}}));
    EXPECT_FALSE(dump.contains("kdop_slab_directions"));  // no k-DOP drawn, none dumped

    // The camera looks straight at D: its sphere's outline at 45 degrees lies clear of its
    // box's edges (render/volume_colors_test.cpp), green; the box corner is yellow.
    const render::Image pause = render::readPng(out / "pause_1.png");
    const engine::CameraSettings cam = cameraAt(-1.2, -0.6);
    const Real k = Real(0.8) * std::sqrt(Real(0.5));
    for (const Vec3& p : {Vec3(-1.2 - k, -0.6 - k, 0), Vec3(-1.2 - k, -0.6 + k, 0)}) {
        const PixelPos px = project(cam, pause.width, pause.height, p);
        EXPECT_TRUE(colorNear(pause, px, kGreen, 1)) << px.x << "," << px.y;
        EXPECT_FALSE(colorNear(pause, px, kYellow, 1)) << px.x << "," << px.y;
    }
    const PixelPos corner = project(cam, pause.width, pause.height, Vec3(-2.0, -1.4, 0.8));
    EXPECT_TRUE(colorNear(pause, corner, kYellow));

    // The frames of the run (no draw.volumes, broad phase sap) draw the AABBs, yellow.
    const render::Image frame = render::readPng(out / "frame_00001.png");
    EXPECT_TRUE(colorNear(frame, corner, kYellow));
    fs::remove_all(work);
}

// A scene that chose its volumes gets them, and only them, in the pause picture too: with
// draw.volumes [aabb] the green sphere outline of the test above is gone, the yellow box corner
// stays; the dump still lists every volume's state.
TEST(PausePicture, ChosenVolumesAreTheOnesThePausePictureDraws) {
    const fs::path work = pauseDir("chosen");
    const fs::path scene =
        writeScene(work, "diagonal.yaml", sceneText(-1.2, -0.6, kDiagonalBodies));
    const fs::path out = work / "out";
    const CliResult r = runCdlab("run " + scene.string() +
                                     " --no-video --pause-at 1 --set 'draw.volumes=[aabb]' --out " +
                                     out.string(),
                                 work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const render::Image pause = render::readPng(out / "pause_1.png");
    const engine::CameraSettings cam = cameraAt(-1.2, -0.6);
    const Real k = Real(0.8) * std::sqrt(Real(0.5));
    for (const Vec3& p : {Vec3(-1.2 - k, -0.6 - k, 0), Vec3(-1.2 - k, -0.6 + k, 0)}) {
        const PixelPos px = project(cam, pause.width, pause.height, p);
        EXPECT_FALSE(colorNear(pause, px, kGreen, 1)) << "a sphere drawn at " << px.x << "," << px.y;
    }
    EXPECT_TRUE(colorNear(pause, project(cam, pause.width, pause.height, Vec3(-2.0, -1.4, 0.8)),
                          kYellow));
    const nlohmann::json dump = nlohmann::json::parse(slurp(out / "pause_1.json"));
    EXPECT_EQ(dump["bodies"][0]["volume_states"]["sphere"], "apart");
    fs::remove_all(work);
}

// k-DOPs drawn (draw.volumes) are dumped too, each by its own slab test: D and E sit on the
// diagonal (1, 1, 0), so their 6-DOPs (boxes) and 14-DOPs (axes and cube diagonals) overlap
// while the 26-DOPs' (1, 1, 0) slab separates them. Each slab interval is a sphere's
// [d.c - r |d|, d.c + r |d|] along the dumped direction d; k-DOPs not drawn are not dumped.
TEST(PausePicture, DrawnKdopsAreDumpedWithTheirSlabsAndStates) {
    const fs::path work = pauseDir("kdop");
    std::string text = sceneText(-1.2, -0.6, kDiagonalBodies);
    const std::string draw = "draw: {hud: false, bounds: false, bodies: false}";
    ASSERT_NE(text.find(draw), std::string::npos);
    text.replace(text.find(draw), draw.size(),
                 "draw: {hud: false, bounds: false, bodies: false, volumes: [kdop6, kdop14, "
                 "kdop26]}");
    const fs::path scene = writeScene(work, "kdops.yaml", text);
    const fs::path out = work / "out";
    const CliResult r =
        runCdlab("run " + scene.string() + " --no-video --pause-at 0 --out " + out.string(), work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json dump = nlohmann::json::parse(slurp(out / "pause_0.json"));

    const Vec3 centres[3] = {Vec3(-1.2, -0.6, 0), Vec3(0, 0.6, 0), Vec3(2.8, 0, 0)};
    for (const int k : {6, 14, 26}) {
        const std::string name = "kdop" + std::to_string(k);
        SCOPED_TRACE(name);
        const nlohmann::json& directions = dump["kdop_slab_directions"][name];
        ASSERT_EQ(directions.size(), std::size_t(k / 2));
        for (std::size_t b = 0; b < 3; ++b) {
            const nlohmann::json& kdop = dump["bodies"][b][name];
            EXPECT_EQ(kdop["k"], k);
            ASSERT_EQ(kdop["min"].size(), std::size_t(k / 2));
            ASSERT_EQ(kdop["max"].size(), std::size_t(k / 2));
            for (std::size_t i = 0; i < directions.size(); ++i) {
                const Vec3 d(directions[i][0].get<double>(), directions[i][1].get<double>(),
                             directions[i][2].get<double>());
                EXPECT_NEAR(kdop["min"][i].get<double>(), d.dot(centres[b]) - 0.8 * d.norm(),
                            1e-12);
                EXPECT_NEAR(kdop["max"][i].get<double>(), d.dot(centres[b]) + 0.8 * d.norm(),
                            1e-12);
            }
        }
        EXPECT_EQ(dump["bodies"][2]["volume_states"][name], "apart");
    }
    const nlohmann::json& d = dump["bodies"][0];
    EXPECT_EQ(d["volume_states"]["kdop6"], "overlapping");
    EXPECT_EQ(d["volume_states"]["kdop14"], "overlapping");
    EXPECT_EQ(d["volume_states"]["kdop26"], "apart");
    EXPECT_EQ(dump["overlapping_pairs"]["kdop6"], nlohmann::json::array({{0, 1}}));
    EXPECT_EQ(dump["overlapping_pairs"]["kdop14"], nlohmann::json::array({{0, 1}}));
    EXPECT_EQ(dump["overlapping_pairs"]["kdop26"], nlohmann::json::array());
    EXPECT_FALSE(d.contains("kdop18"));
    EXPECT_FALSE(d["volume_states"].contains("kdop18"));
    EXPECT_FALSE(dump["overlapping_pairs"].contains("kdop18"));
    // The volumes every pause dump has are still there.
    EXPECT_EQ(d["volume_states"]["aabb"], "overlapping");
    EXPECT_EQ(d["volume_states"]["sphere"], "apart");
    fs::remove_all(work);
}

// --broadphase obb / sphere: the frames show the volume that broad phase tests, coloured by it.
// The rods' AABBs and bounding spheres overlap, their OBBs do not: with obb nothing is yellow and
// the OBB lines are green; with sphere the spheres and with sap the AABBs are yellow.
TEST(PausePicture, FramesDrawTheVolumeTheBroadPhaseTests) {
    const fs::path work = pauseDir("default");
    const fs::path scene = writeScene(work, "rods.yaml", sceneText(0, 0, kRodBodies));
    const engine::CameraSettings cam = cameraAt(0, 0);
    // A point of rod1's long upper front edge, 0.7 from its middle: on its OBB, clear of its and
    // rod2's bounding spheres' circles.
    const Real c = std::sqrt(Real(0.5));
    const Vec3 edge_point = Vec3(-0.3, 0.3, 0.15) + Vec3(0.7 * c - 0.15 * c, 0.7 * c + 0.15 * c, 0);
    for (const std::string bp : {"obb", "sphere", "sap"}) {
        SCOPED_TRACE(bp);
        const fs::path out = work / bp;
        const CliResult r = runCdlab("run " + scene.string() +
                                         " --no-video --frames 1 --pause-at 0 "
                                         "--broadphase " +
                                         bp + " --out " + out.string(),
                                     work);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const nlohmann::json dump = nlohmann::json::parse(slurp(out / "pause_0.json"));
        ASSERT_EQ(dump["overlapping_pairs"]["aabb"], nlohmann::json::array({{0, 1}}));
        ASSERT_EQ(dump["overlapping_pairs"]["obb"], nlohmann::json::array());
        const render::Image frame = render::readPng(out / "frame_00000.png");
        const PixelPos px = project(cam, frame.width, frame.height, edge_point);
        if (bp == "obb") {
            EXPECT_EQ(countColor(frame, kYellow), 0);
            EXPECT_TRUE(colorNear(frame, px, kGreen, 1)) << "no green OBB edge";
        } else if (bp == "sphere") {
            // The rods' bounding spheres overlap: yellow circles, and no OBB edge.
            EXPECT_FALSE(colorNear(frame, px, kGreen, 1)) << "an OBB edge, not a sphere";
            EXPECT_GT(countColor(frame, kYellow), 50);
        } else {
            EXPECT_GT(countColor(frame, kYellow), 50);
        }
    }
    fs::remove_all(work);
}

// --pause-hold: the pause picture stays in the video for SECONDS x fps more frames (tiny.yaml:
// 6 frames at 10 fps); the PNG frames are not repeated; 0 holds nothing.
TEST(PausePicture, PauseHoldAddsHoldTimesFpsVideoFrames) {
    if (!haveFfprobe()) GTEST_SKIP() << "ffprobe not on PATH (Debian package ffmpeg)";
    const fs::path work = pauseDir("hold");
    struct Case {
        std::string flags;
        int video_frames;
    };
    for (const Case& c : {Case{"--pause-at 2", 6 + 20}, Case{"--pause-at 2 --pause-hold 0", 6},
                          Case{"--pause-at 2 --pause-at 4 --pause-hold 0.5", 6 + 2 * 5},
                          Case{"--pause-hold 3", 6}}) {
        SCOPED_TRACE(c.flags);
        const fs::path out = work / "out";
        const CliResult r =
            runCdlab("run " + kTiny + " " + c.flags + " --out " + out.string(), work);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const auto probe = probeVideo(out / "tiny.mp4", work);
        ASSERT_EQ(probe.count("error"), 0u) << probe.at("error");
        EXPECT_EQ(probe.count("nb_read_frames") ? probe.at("nb_read_frames") : "?",
                  std::to_string(c.video_frames));
        EXPECT_TRUE(fs::exists(out / "frame_00005.png"));
        EXPECT_FALSE(fs::exists(out / "frame_00006.png"));
    }
    fs::remove_all(work);
}

TEST(PausePicture, BadPauseHoldIsAClearErrorExit2) {
    const fs::path work = pauseDir("badhold");
    for (const std::string v : {"-1", "nan", "inf", "-inf", "1e9", "abc"}) {
        SCOPED_TRACE(v);
        const CliResult r = runCdlab("run " + kTiny + " --no-video --pause-at 1 --pause-hold " + v +
                                         " --out " + (work / "o").string(),
                                     work);
        EXPECT_EQ(r.exit_code, 2);
        EXPECT_NE(r.err.find("--pause-hold"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(work / "o"));
    }
    fs::remove_all(work);
}

// A mesh body's dump names its hierarchy's volume (world.mesh_bvh), the wide tree included;
// other bodies have none.
TEST(PausePicture, DumpNamesEachMeshBodysHierarchy) {
    const fs::path work = pauseDir("mesh_bvh");
    const std::string torus = std::string(CDLAB_SOURCE_DIR) + "/assets/torus.obj";
    const fs::path scene = writeScene(
        work, "meshes.yaml",
        sceneText(0, 0,
                  "  - {name: ring, shape: mesh, file: " + torus + ", position: [-0.5, 0, 0]}\n"
                  "  - {name: ball, shape: sphere, radius: 0.5, position: [2.5, 0, 0]}\n"));
    const fs::path out = work / "out";
    const CliResult r = runCdlab("run " + scene.string() +
                                     " --set world.mesh_bvh=obb4 --no-video --pause-at 1 --out " +
                                     out.string(),
                                 work);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json dump = nlohmann::json::parse(slurp(out / "pause_1.json"));
    EXPECT_EQ(dump["bodies"][0]["mesh_bvh"], "obb4");
    EXPECT_FALSE(dump["bodies"][1].contains("mesh_bvh"));
    fs::remove_all(work);
}
