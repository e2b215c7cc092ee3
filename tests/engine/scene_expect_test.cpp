// tests/engine/scene_expect_test.cpp -- the `expect:` section of scene files: what it parses to,
// and every bad key or value reported at its exact line:col.
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <string>

#include "engine/mesh_import.h"
#include "engine/scene.h"
#include "scene_error.h"

namespace engine {
namespace {

// Three bodies, 10 frames; tests append an `expect:` section from line 8 on.
const std::string kScene =
    "world: {bounds: {min: [-5, -5, -5], max: [5, 5, 5]}, frames: 10}\n"  // 1
    "bodies:\n"                                                           // 2
    "  - {name: a, shape: sphere, radius: 1, position: [0, 0, 0]}\n"      // 3
    "  - {name: b, shape: sphere, radius: 1, position: [1, 0, 0]}\n"      // 4
    "  - {name: c, shape: sphere, radius: 1, position: [3, 0, 0]}\n"      // 5
    "  - {name: d, shape: sphere, radius: 1, position: [-3, 0, 0]}\n"     // 6
    "expect:\n";                                                          // 7

TEST(SceneExpect, AbsentMeansNotPresent) {
    const Scene s = parseScene(
        "world: {bounds: {min: [-1, -1, -1], max: [1, 1, 1]}}\nbodies:\n"
        "  - {shape: sphere, radius: 0.25, position: [0.5, 0.5, 0.5]}\n",
        "x.yaml", ".");
    EXPECT_FALSE(s.expect.present);
    const Scene one = parseScene(kScene + "  min_bodies: 1\n", "x.yaml", ".");
    EXPECT_TRUE(one.expect.present);
    EXPECT_EQ(one.expect.min_bodies, 1);
}

// An `expect:` that states nothing passed `cdlab check` having checked nothing (a shipped scene
// could grade itself with no grade); now it is an error at the section's key.
TEST(SceneExpect, EmptyExpectationsAreAnError) {
    const std::string what =
        "states no expectation (give at least one of: min_bodies, "
        "min_moving_rotating, broadphases, broadphases_in_use, energy_drift_max, "
        "energy_rise_max, pause_dumps, pairs, colors, tunnelling, toi, rest, self_collision)";
    EXPECT_SCENE_ERROR(kScene, "7:1: expect: ", what);
    EXPECT_SCENE_ERROR(kScene.substr(0, kScene.size() - 1) + " {}\n", "7:1: expect: ", what);
    EXPECT_SCENE_ERROR(kScene.substr(0, kScene.size() - 1) + " ~\n", "7:1: expect: ", what);
    // `frames` sets the run length and expects nothing.
    EXPECT_SCENE_ERROR(kScene + "  frames: 5\n", "7:1: expect: ", what);
    // An empty list states nothing either, even beside other expectations.
    EXPECT_SCENE_ERROR(kScene + "  min_bodies: 1\n  pairs: []\n",
                       "9:10: expect.pairs: ", "empty list: states no expectation");
    for (const char* key : {"broadphases", "pause_dumps", "colors", "tunnelling", "toi", "rest"}) {
        EXPECT_SCENE_ERROR(
            kScene + "  " + key + ": []\n",
            "8:" + std::to_string(std::string(key).size() + 5) + ": expect." + key + ": ",
            "empty list: states no expectation");
    }
    // One colour list may be empty when the other is not.
    EXPECT_EQ(sceneErrorOf(kScene + "  colors:\n    - {frame: 1, present: [red], absent: []}\n"),
              "");
}

TEST(SceneExpect, ParsesEveryKey) {
    const Scene s = parseScene(kScene +
                                   "  frames: 8\n"
                                   "  min_bodies: 4\n"
                                   "  min_moving_rotating: 2\n"
                                   "  broadphases: [sphere, sap]\n"
                                   "  energy_drift_max: 1e-6\n"
                                   "  pause_dumps: [0, 7]\n"
                                   "  pairs:\n"
                                   "    - {a: b, b: a, frames: [2, 5], colliding: true}\n"
                                   "    - {a: a, b: b, frames: 3, when: any, flagged: false}\n"
                                   "  colors:\n"
                                   "    - {frame: 1, present: [red, green], absent: [yellow],"
                                   " min_pixels: 5}\n",
                               "x.yaml", ".");
    const Expectations& e = s.expect;
    ASSERT_TRUE(e.present);
    EXPECT_EQ(e.frames, 8);
    EXPECT_EQ(e.min_bodies, 4);
    EXPECT_EQ(e.min_moving_rotating, 2);
    EXPECT_EQ(e.broad_phases, (std::vector<std::string>{"sphere", "sap"}));
    EXPECT_EQ(e.energy_drift_max, Real(1e-6));
    EXPECT_EQ(e.pause_dumps, (std::vector<int>{0, 7}));
    ASSERT_EQ(e.pairs.size(), 2u);
    EXPECT_EQ(e.pairs[0].a, 1);
    EXPECT_EQ(e.pairs[0].b, 0);
    EXPECT_EQ(e.pairs[0].frames.first, 2);
    EXPECT_EQ(e.pairs[0].frames.last, 5);
    EXPECT_TRUE(e.pairs[0].every);
    EXPECT_EQ(e.pairs[0].colliding, true);
    EXPECT_FALSE(e.pairs[0].flagged.has_value());
    EXPECT_EQ(e.pairs[0].line, 15);
    EXPECT_EQ(e.pairs[1].frames.first, 3);
    EXPECT_EQ(e.pairs[1].frames.last, 3);
    EXPECT_FALSE(e.pairs[1].every);
    EXPECT_EQ(e.pairs[1].flagged, false);
    ASSERT_EQ(e.colors.size(), 1u);
    EXPECT_EQ(e.colors[0].frame, 1);
    EXPECT_EQ(e.colors[0].present,
              (std::vector<BodyState>{BodyState::Colliding, BodyState::Apart}));
    EXPECT_EQ(e.colors[0].absent, (std::vector<BodyState>{BodyState::Flagged}));
    EXPECT_EQ(e.colors[0].min_pixels, 5);
    EXPECT_EQ(e.colors[0].volume, "");
    const Scene one = parseScene(kScene +
                                     "  colors:\n    - {frame: 1, volume: kdop14, "
                                     "absent: [red]}\n",
                                 "x.yaml", ".");
    ASSERT_EQ(one.expect.colors.size(), 1u);
    EXPECT_EQ(one.expect.colors[0].volume, "kdop14");
}

TEST(SceneExpectErrors, ColourVolumeIsADrawableVolume) {
    EXPECT_SCENE_ERROR(kScene + "  colors:\n    - {frame: 1, volume: kdop8, present: [red]}\n",
                       "9:26: expect.colors[0].volume: ",
                       "unknown volume 'kdop8' (expected one of: sphere, aabb, obb, kdop6, "
                       "kdop14, kdop18, kdop26)");
    EXPECT_SCENE_ERROR(kScene + "  colors:\n    - {frame: 1, volume: [aabb], present: [red]}\n",
                       "9:26: expect.colors[0].volume: ", "expected a string");
}

TEST(SceneExpectErrors, UnknownKeysAtEveryLevel) {
    EXPECT_SCENE_ERROR(kScene + "  min_body: 3\n",
                       "8:3: expect.min_body: ", "unknown key 'min_body'");
    EXPECT_SCENE_ERROR(kScene + "  pairs:\n    - {a: a, b: b, frame: 1, colliding: true}\n",
                       "9:20: expect.pairs[0].frame: ", "unknown key 'frame'");
    EXPECT_SCENE_ERROR(kScene + "  colors:\n    - {frame: 1, colour: [red]}\n",
                       "9:18: expect.colors[0].colour: ", "unknown key 'colour'");
    EXPECT_SCENE_ERROR(kScene + "  - 3\n", "8:3: expect: ", "expected a mapping");
}

TEST(SceneExpectErrors, BodyNames) {
    EXPECT_SCENE_ERROR(kScene + "  pairs:\n    - {a: a, b: nobody, frames: 1, flagged: true}\n",
                       "9:17: expect.pairs[0].b: ", "no body is named 'nobody'");
    EXPECT_SCENE_ERROR(kScene + "  pairs:\n    - {a: a, b: a, frames: 1, flagged: true}\n",
                       "9:17: expect.pairs[0].b: ", "must differ from 'a'");
}

TEST(SceneExpectErrors, FramesOutsideTheRun) {
    EXPECT_SCENE_ERROR(kScene + "  pause_dumps: [3, 10]\n", "8:20: expect.pause_dumps[1]: ",
                       "frame out of range (the check runs frames 0..9)");
    // expect.frames shortens the run, wherever it is written.
    EXPECT_SCENE_ERROR(kScene + "  pause_dumps: [5]\n  frames: 4\n",
                       "8:17: expect.pause_dumps[0]: ", "frames 0..3");
    EXPECT_SCENE_ERROR(kScene + "  pairs:\n    - {a: a, b: b, frames: [4, 2], flagged: true}\n",
                       "9:32: expect.pairs[0].frames[1]: ", "must be >= the first frame");
    EXPECT_SCENE_ERROR(kScene + "  pairs:\n    - {a: a, b: b, frames: [1, 2, 3], flagged: true}\n",
                       "9:28: expect.pairs[0].frames: ", "a frame or a range");
    EXPECT_SCENE_ERROR(kScene + "  colors:\n    - {frame: -1, present: [red]}\n",
                       "9:15: expect.colors[0].frame: ", "frame out of range");
    EXPECT_SCENE_ERROR(kScene + "  frames: 0\n", "8:11: expect.frames: ", "must be >= 1");
}

TEST(SceneExpectErrors, ValuesAndContradictions) {
    EXPECT_SCENE_ERROR(kScene + "  broadphases: [sap, bogus]\n",
                       "8:22: expect.broadphases[1]: ", "unknown broad phase 'bogus'");
    EXPECT_SCENE_ERROR(kScene + "  energy_drift_max: -1\n",
                       "8:21: expect.energy_drift_max: ", "must be >= 0");
    EXPECT_SCENE_ERROR(kScene + "  energy_drift_max: .nan\n",
                       "8:21: expect.energy_drift_max: ", "must be finite");
    EXPECT_SCENE_ERROR(kScene + "  min_bodies: -2\n", "8:15: expect.min_bodies: ", "must be >= 0");
    EXPECT_SCENE_ERROR(kScene + "  pairs:\n    - {a: a, b: b, frames: 1}\n",
                       "9:7: expect.pairs[0]: ", "needs 'colliding' or 'flagged'");
    EXPECT_SCENE_ERROR(kScene +
                           "  pairs:\n    - {a: a, b: b, frames: 1, colliding: true, "
                           "flagged: false}\n",
                       "9:57: expect.pairs[0].flagged: ", "can never hold");
    EXPECT_SCENE_ERROR(kScene +
                           "  pairs:\n    - {a: a, b: b, frames: 1, when: always, "
                           "flagged: true}\n",
                       "9:37: expect.pairs[0].when: ", "expected one of: every, any");
    EXPECT_SCENE_ERROR(kScene + "  colors:\n    - {frame: 1, present: [blue]}\n",
                       "9:28: expect.colors[0].present[0]: ", "unknown colour 'blue'");
    EXPECT_SCENE_ERROR(kScene + "  colors:\n    - {frame: 1, present: [red], absent: [red]}\n",
                       "9:7: expect.colors[0]: ", "both present and absent");
    EXPECT_SCENE_ERROR(kScene + "  colors:\n    - {frame: 1}\n",
                       "9:7: expect.colors[0]: ", "needs 'present' or 'absent'");
    EXPECT_SCENE_ERROR(kScene + "  colors:\n    - {frame: 1, present: [red], min_pixels: 0}\n",
                       "9:46: expect.colors[0].min_pixels: ", "must be >= 1");
    EXPECT_SCENE_ERROR(kScene + "  pairs: {a: a}\n", "8:10: expect.pairs: ", "expected a list");
}

TEST(SceneExpectErrors, TunnellingTimeOfImpactAndRest) {
    EXPECT_SCENE_ERROR(kScene + "  energy_rise_max: -0.1\n",
                       "8:20: expect.energy_rise_max: ", "must be >= 0");
    EXPECT_SCENE_ERROR(kScene + "  tunnelling:\n    - {a: a, b: a, passes: false}\n",
                       "9:17: expect.tunnelling[0].b: ", "must differ from 'a'");
    EXPECT_SCENE_ERROR(kScene + "  tunnelling:\n    - {a: a, b: b}\n",
                       "9:7: expect.tunnelling[0].passes: ", "required key is missing");
    EXPECT_SCENE_ERROR(kScene + "  tunnelling:\n    - {a: a, b: b, passes: 2}\n",
                       "9:28: expect.tunnelling[0].passes: ", "expected true or false");
    EXPECT_SCENE_ERROR(kScene + "  toi:\n    - {a: a, b: b, time: 1, tolerance: 0}\n",
                       "9:40: expect.toi[0].tolerance: ", "must be > 0");
    EXPECT_SCENE_ERROR(kScene + "  toi:\n    - {a: a, b: b, time: -1, tolerance: 1}\n",
                       "9:26: expect.toi[0].time: ", "must be >= 0");
    EXPECT_SCENE_ERROR(kScene + "  toi:\n    - {a: a, b: b, time: 1, tolerance: 1, t: 3}\n",
                       "9:43: expect.toi[0].t: ", "unknown key 't'");
    EXPECT_SCENE_ERROR(kScene + "  rest:\n    - {body: b, frames: [0, 9]}\n",
                       "9:7: expect.rest[0]: ", "needs 'max_displacement' or 'max_speed'");
    EXPECT_SCENE_ERROR(kScene + "  rest:\n    - {body: twin, frames: 1, max_speed: 1}\n",
                       "9:14: expect.rest[0].body: ", "no body is named 'twin'");
    EXPECT_SCENE_ERROR(kScene + "  rest:\n    - {body: a, frames: [0, 10], max_speed: 1}\n",
                       "9:29: expect.rest[0].frames[1]: ", "frame out of range");
    EXPECT_SCENE_ERROR(kScene + "  rest:\n    - {body: a, frames: 1, max_speed: -1}\n",
                       "9:39: expect.rest[0].max_speed: ", "must be >= 0");
}

}  // namespace
}  // namespace engine

namespace engine {
namespace {

// Regression (found with the fuzz target): every scale of a mesh file used to be a separate
// assimp import, about half a second each under ASan. Now a file is imported once and scaled;
// the mesh must still be exactly importMesh(file, scale)'s, up to the re-centring translation.
TEST(SceneMeshScale, ScaledAfterImportEqualsImportAtScale) {
    const std::filesystem::path scenes = std::filesystem::path(CDLAB_SOURCE_DIR) / "scenes";
    const Real scales[] = {Real(0.71), Real(0.65), Real(1e-3), Real(1e3), Real(0.62)};
    std::string text = "world: {bounds: {min: [-10, -10, -10], max: [10, 10, 10]}}\nbodies:\n";
    for (const Real s : scales) {
        text += "  - {shape: mesh, file: ../assets/torus.obj, position: [0, 0, 0], scale: " +
                std::to_string(s) + "}\n";
    }
    const Scene scene = parseScene(text, "t.yaml", scenes);
    ASSERT_EQ(scene.bodies.size(), std::size(scales));
    for (std::size_t i = 0; i < std::size(scales); ++i) {
        const Real s = std::stod(std::to_string(scales[i]));  // the value the file states
        const MeshImportOutput direct = importMesh(scenes / "../assets/torus.obj", s);
        ASSERT_TRUE(direct.ok) << direct.error;
        const collision::TriangleMesh& got = *scene.bodies[i].shape.mesh;
        ASSERT_EQ(got.triangles, direct.mesh.triangles) << "scale " << s;
        ASSERT_EQ(got.vertices.size(), direct.mesh.vertices.size());
        const Vec3 offset = direct.mesh.vertices[0] - got.vertices[0];  // the centre of mass
        for (std::size_t v = 0; v < got.vertices.size(); ++v) {
            const Vec3 d = direct.mesh.vertices[v] - got.vertices[v];
            // got = direct - com, rounded once: equal offsets up to one rounding of the size.
            EXPECT_LE((d - offset).norm(), 8 * std::numeric_limits<Real>::epsilon() * 2 * s)
                << "scale " << s << " vertex " << v;
        }
    }
}

}  // namespace
}  // namespace engine
