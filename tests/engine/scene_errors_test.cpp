// tests/engine/scene_errors_test.cpp -- scene files that do not load: every error class with its
// exact line:col and key path, hostile and truncated YAML, magnitudes double cannot integrate.
#include "engine/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "collision/bvh/bvh.h"
#include "engine/mass_properties.h"
#include "scene_error.h"
#include "scene_text.h"

namespace engine {
namespace {

using namespace scene_text;
namespace fs = std::filesystem;

TEST(SceneErrors, BodyNamesAreUnique) {
    EXPECT_SCENE_ERROR(
        withBody("  - {name: twin, shape: sphere, radius: 1, position: [3, 0, 0]}\n"
                 "  - {name: twin, shape: sphere, radius: 1, position: [-3, 0, 0]}\n"),
        "5:12: bodies[1].name: ",
        "the body name 'twin' is already taken by bodies[0]; body names must be");
    EXPECT_SCENE_ERROR(
        withBody("  - {name: rock_1, shape: sphere, radius: 0.1, position: [0, 0, 0]}\n"
                 "  - {name: rock, shape: sphere, radius: 0.1, repeat: {count: 3, seed: 1,"
                 " region: {min: [-5, -5, -5], max: [5, 5, 5]}}}\n"),
        "5:12: bodies[1].name: ", "(repeat names its bodies <name>_0, <name>_1");
    EXPECT_SCENE_ERROR(
        withBody("  - {shape: sphere, radius: 0.1, position: [0, 0, 0]}\n"
                 "  - {name: sphere0, shape: sphere, radius: 0.1, position: [1, 0, 0]}\n"),
        "5:12: bodies[1].name: ", "already taken by bodies[0]");
    EXPECT_SCENE_ERROR(
        withBody("  - {name: sphere1, shape: sphere, radius: 0.1, position: [0, 0, 0]}\n"
                 "  - {shape: sphere, radius: 0.1, position: [1, 0, 0]}\n"),
        "5:5: bodies[1]: ", "(a body without a name is called <shape><index>)");
}

// Whichever of time_step and steps_per_frame a scene leaves out is chosen so that one frame
// spans 1/fps s of simulated time; a scene that gives both keeps them (slow motion is allowed).

TEST(SceneErrors, UnknownKeysAtEveryLevel) {
    EXPECT_SCENE_ERROR("wrld:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n", "1:1: wrld: ",
                       "unknown key 'wrld' (expected one of: world, broadphase, pair_order, "
                       "output, camera, draw, bodies, chains, expect, events)");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radus: 0.5\n    position: [0, 0, 0]\n"),
                       "5:5: bodies[0].radus: ", "unknown key 'radus' (expected one of: name,");
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  gravty: [0,0,0]\n",
                       "3:3: world.gravty: ", "unknown key 'gravty'");
    EXPECT_SCENE_ERROR(kHeader + "output: {width: 64, heigth: 64}\n", "4:21: output.heigth: ",
                       "unknown key 'heigth' (expected one of: width, height, fps)");
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [0,0,0], max: [1,1,1], mid: [0,0,0]}\n",
                       "2:40: world.bounds.mid: ", "unknown key 'mid'");
}

TEST(SceneErrors, DuplicateKey) {
    EXPECT_SCENE_ERROR(
        withBody("  - shape: sphere\n    radius: 0.5\n    radius: 0.6\n    position: [0, 0, 0]\n"),
        "6:5: bodies[0].radius: ", "duplicate key");
}

TEST(SceneErrors, WrongTypes) {
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: big\n    position: [0, 0, 0]\n"),
                       "5:13: bodies[0].radius: ", "expected a number");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: [1]\n    position: [0, 0, 0]\n"),
                       "5:13: bodies[0].radius: ", "expected a number");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 0.5\n    position: [0, 0]\n"),
                       "6:15: bodies[0].position: ", "expected a list of 3 numbers");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 0.5\n    position: 3\n"),
                       "6:15: bodies[0].position: ", "expected a list of 3 numbers");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 0.5\n    position: [0, x, 0]\n"),
                       "6:19: bodies[0].position[1]: ", "expected a number");
    EXPECT_SCENE_ERROR(kHeader + "draw: {hud: maybe}\n",
                       "4:13: draw.hud: ", "expected true or false");
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  frames: 2.5\n",
                       "3:11: world.frames: ", "expected an integer");
    EXPECT_SCENE_ERROR("world: 3\n", "1:8: world: ", "expected a mapping");
    EXPECT_SCENE_ERROR(kHeader + "  shape: sphere\n", "4:3: bodies: ", "expected a list");
    EXPECT_SCENE_ERROR(withBody("  - 42\n"), "4:5: bodies[0]: ", "expected a mapping");
    EXPECT_SCENE_ERROR(withBody("  - shape: [sphere]\n    radius: 1\n    position: [0, 0, 0]\n"),
                       "4:12: bodies[0].shape: ", "expected a string");
}

TEST(SceneErrors, NonFiniteNumbersRejected) {
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: .nan\n    position: [0, 0, 0]\n"),
                       "5:13: bodies[0].radius: ", "must be finite");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 0.5\n    position: [0, .inf, 0]\n"),
                       "6:19: bodies[0].position[1]: ", "must be finite");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 0.5\n    position: [0, 0, 0]\n"
                                "    velocity: [-.Inf, 0, 0]\n"),
                       "7:16: bodies[0].velocity[0]: ", "must be finite");
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  time_step: .NaN\n",
                       "3:14: world.time_step: ", "must be finite");
    // Overflowing literal: not representable.
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 1e999\n    position: [0, 0, 0]\n"),
                       "5:13: bodies[0].radius: ", "");
}

TEST(SceneErrors, OutOfRangeValues) {
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 0\n    position: [0, 0, 0]\n"),
                       "5:13: bodies[0].radius: ", "must be > 0");
    EXPECT_SCENE_ERROR(withBody("  - shape: capsule\n    radius: 1\n    half_height: -0.1\n"
                                "    position: [0, 0, 0]\n"),
                       "6:18: bodies[0].half_height: ", "must be >= 0");
    EXPECT_SCENE_ERROR(
        withBody("  - shape: box\n    half_extents: [1, -1, 1]\n    position: [0, 0, 0]\n"),
        "5:23: bodies[0].half_extents[1]: ", "must be >= 0");
    EXPECT_SCENE_ERROR(withBody("  - shape: mesh\n    file: ../assets/torus.obj\n    scale: 0\n"
                                "    position: [0, 0, 0]\n"),
                       "6:12: bodies[0].scale: ", "must be > 0");
    EXPECT_SCENE_ERROR(
        withBody("  - shape: sphere\n    radius: 1\n    position: [0, 0, 0]\n    mass: -2\n"),
        "7:11: bodies[0].mass: ", "must be > 0");
    EXPECT_SCENE_ERROR(
        withBody("  - shape: sphere\n    radius: 1\n    position: [0, 0, 0]\n    density: 0\n"),
        "7:14: bodies[0].density: ", "must be > 0");
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  time_step: 0\n",
                       "3:14: world.time_step: ", "must be > 0 and <= 1");
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  time_step: 2\n",
                       "3:14: world.time_step: ", "must be > 0 and <= 1");
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  steps_per_frame: 0\n",
                       "3:20: world.steps_per_frame: ", "must be >= 1");
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  frames: 0\n",
                       "3:11: world.frames: ", "must be >= 1");
    EXPECT_SCENE_ERROR(
        "world:\n  bounds: {min: [0,0,0], max: [1,0,1]}\n",
        "2:31: world.bounds.max: ", "must be greater than min on every axis (axis y)");
    EXPECT_SCENE_ERROR(kHeader + "output: {width: 641}\n", "4:17: output.width: ", "must be even");
    EXPECT_SCENE_ERROR(kHeader + "output: {height: 8}\n",
                       "4:18: output.height: ", "must be in 16..8192");
    EXPECT_SCENE_ERROR(kHeader + "output: {fps: 0}\n", "4:15: output.fps: ", "must be in 1..240");
    EXPECT_SCENE_ERROR(kHeader + "camera: {fov_deg: 180}\n",
                       "4:19: camera.fov_deg: ", "must be > 0 and < 180");
    EXPECT_SCENE_ERROR(kHeader + "camera: {position: [0, 5, 0], look_at: [0, 0, 0]}\n",
                       "4:40: camera.look_at: ", "up must not be parallel to the view direction");
    EXPECT_SCENE_ERROR(kHeader + "camera: {up: [0, 0, 0]}\n",
                       "4:14: camera.up: ", "up must not be zero");
    EXPECT_SCENE_ERROR(kHeader + "draw: {volumes: [sphere, kdop]}\n", "4:26: draw.volumes[1]: ",
                       "unknown volume 'kdop' (expected one of: sphere, aabb, obb, kdop6, "
                       "kdop14, kdop18, kdop26)");
    EXPECT_SCENE_ERROR(kHeader + "draw: {volumes: [kdop7]}\n", "4:18: draw.volumes[0]: ",
                       "unknown volume 'kdop7'");
}

TEST(SceneErrors, DrawBvhDepthAndContactsAreValidated) {
    EXPECT_EQ(sceneErrorOf(kHeader + "draw: {bvh_depth: -2}\n"),
              "test.yaml:4:19: draw.bvh_depth: must be >= 0, or -1 for off");
    EXPECT_EQ(sceneErrorOf(kHeader + "draw: {bvh_depth: 2.5}\n"),
              "test.yaml:4:19: draw.bvh_depth: expected an integer, got '2.5'");
    EXPECT_EQ(sceneErrorOf(kHeader + "draw: {bvh_depth: deep}\n"),
              "test.yaml:4:19: draw.bvh_depth: expected an integer, got 'deep'");
    EXPECT_EQ(sceneErrorOf(kHeader + "draw: {bvh_depth: [3]}\n"),
              "test.yaml:4:19: draw.bvh_depth: expected an integer");
    EXPECT_EQ(sceneErrorOf(kHeader + "draw: {contacts: 1.5}\n"),
              "test.yaml:4:18: draw.contacts: expected true or false, got '1.5'");
    EXPECT_EQ(sceneErrorOf(kHeader + "draw: {contact: true}\n"),
              "test.yaml:4:8: draw.contact: unknown key 'contact' (expected one of: bodies, "
              "volumes, bounds, hud, structure, bvh_depth, contacts, labels)");
}

TEST(SceneErrors, UnknownNamesListTheChoices) {
    const std::string err = sceneErrorOf(kHeader + "broadphase: quadtree\n");
    EXPECT_EQ(err.rfind("test.yaml:4:13: broadphase: unknown broad phase 'quadtree' "
                        "(expected one of: " +
                            collision::broadPhaseNames() + ")",
                        0),
              0u)
        << err;
    EXPECT_SCENE_ERROR(kHeader + "pair_order: unsorted\n", "4:13: pair_order: ",
                       "unknown pair order 'unsorted' (expected one of: sorted, found)");
    EXPECT_SCENE_ERROR(kHeader + "pair_order: [found]\n",
                       "4:13: pair_order: ", "expected a string");
    EXPECT_SCENE_ERROR(withBody("  - shape: cone\n    position: [0, 0, 0]\n"),
                       "4:12: bodies[0].shape: ",
                       "unknown shape 'cone' (expected one of: sphere, box, capsule, hull, mesh)");
}

TEST(SceneErrors, CcdToleranceAndTargetGapAreValidated) {
    const std::string head = "world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n";
    EXPECT_SCENE_ERROR(head + "  ccd_tolerance: 0\n", "3:18: world.ccd_tolerance: ",
                       "must be > 0 and <= 1 (fraction of the smaller bounding radius)");
    EXPECT_SCENE_ERROR(head + "  ccd_tolerance: 1.5\n",
                       "3:18: world.ccd_tolerance: ", "must be > 0 and <= 1");
    EXPECT_SCENE_ERROR(head + "  ccd_tolerance: -1e-3\n",
                       "3:18: world.ccd_tolerance: ", "must be > 0 and <= 1");
    EXPECT_SCENE_ERROR(head + "  ccd_tolerance: .nan\n",
                       "3:18: world.ccd_tolerance: ", "must be finite");
    EXPECT_SCENE_ERROR(head + "  ccd_tolerance: loose\n",
                       "3:18: world.ccd_tolerance: ", "expected a number, got 'loose'");
    EXPECT_SCENE_ERROR(head + "  ccd_target_gap: -0.1\n", "3:19: world.ccd_target_gap: ",
                       "must be in [0, 1] (fraction of the smaller bounding radius)");
    EXPECT_SCENE_ERROR(head + "  ccd_target_gap: 2\n",
                       "3:19: world.ccd_target_gap: ", "must be in [0, 1]");
    EXPECT_SCENE_ERROR(head + "  ccd_target_gap: [1]\n",
                       "3:19: world.ccd_target_gap: ", "expected a number");
}

TEST(SceneErrors, RebuildRatioIsValidated) {
    const std::string head = "world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n";
    EXPECT_SCENE_ERROR(head + "  rebuild_ratio: 1\n", "3:18: world.rebuild_ratio: ",
                       "must be > 1 (multiple of the volume ratio at the last build)");
    EXPECT_SCENE_ERROR(head + "  rebuild_ratio: 0.5\n",
                       "3:18: world.rebuild_ratio: ", "must be > 1");
    EXPECT_SCENE_ERROR(head + "  rebuild_ratio: .inf\n",
                       "3:18: world.rebuild_ratio: ", "must be finite");
    EXPECT_SCENE_ERROR(head + "  rebuild_ratio: often\n",
                       "3:18: world.rebuild_ratio: ", "expected a number, got 'often'");
}

TEST(SceneErrors, UnknownMeshBvh) {
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  mesh_bvh: kdop7\n",
                       "3:13: world.mesh_bvh: ",
                       "unknown bounding volume 'kdop7' (expected one of: sphere, aabb, obb, "
                       "kdop6, kdop14, kdop18, kdop26, rss, lss, obb4)");
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  mesh_bvh: [obb]\n",
                       "3:13: world.mesh_bvh: ", "expected a string");
}

TEST(SceneErrors, KeysThatDoNotApplyToTheShape) {
    EXPECT_SCENE_ERROR(withBody("  - shape: box\n    half_extents: [1, 1, 1]\n    radius: 0.5\n"
                                "    position: [0, 0, 0]\n"),
                       "6:5: bodies[0].radius: ", "does not apply to shape 'box'");
    EXPECT_SCENE_ERROR(
        withBody("  - shape: sphere\n    radius: 1\n    scale: 2\n    position: [0, 0, 0]\n"),
        "6:5: bodies[0].scale: ", "does not apply to shape 'sphere'");
    EXPECT_SCENE_ERROR(
        withBody("  - shape: sphere\n    radius: 1\n    half_height: 2\n    position: [0, 0, 0]\n"),
        "6:5: bodies[0].half_height: ", "does not apply to shape 'sphere'");
}

TEST(SceneErrors, MissingRequiredKeys) {
    // Reported at the mapping that lacks the key.
    EXPECT_SCENE_ERROR("broadphase: sap\n", "1:1: world: ", "required key is missing");
    EXPECT_SCENE_ERROR("world:\n  gravity: [0, 0, 0]\n",
                       "2:3: world.bounds: ", "required key is missing");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 1\n"),
                       "4:5: bodies[0].position: ", "required key is missing");
    EXPECT_SCENE_ERROR(withBody("  - radius: 1\n    position: [0, 0, 0]\n"),
                       "4:5: bodies[0].shape: ", "required key is missing");
    EXPECT_SCENE_ERROR(withBody("  - shape: capsule\n    radius: 1\n    position: [0, 0, 0]\n"),
                       "4:5: bodies[0].half_height: ", "required key is missing");
    EXPECT_SCENE_ERROR(withBody("  - shape: mesh\n    position: [0, 0, 0]\n"),
                       "4:5: bodies[0].file: ", "required key is missing");
}

TEST(SceneErrors, ExclusiveKeys) {
    EXPECT_SCENE_ERROR(
        withBody("  - shape: sphere\n    radius: 1\n    position: [0, 0, 0]\n    mass: 1\n"
                 "    density: 2\n"),
        "8:5: bodies[0].density: ", "give either 'mass' or 'density', not both");
    EXPECT_SCENE_ERROR(
        withBody("  - shape: sphere\n    radius: 1\n    euler_deg: [0, 0, 0]\n"
                 "    position: [0, 0, 0]\n    orientation_wxyz: [1, 0, 0, 0]\n"),
        "8:5: bodies[0].orientation_wxyz: ", "give either 'orientation_wxyz' or 'euler_deg'");
}

TEST(SceneErrors, BadQuaternion) {
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 1\n    position: [0, 0, 0]\n"
                                "    orientation_wxyz: [0, 0, 0, 0]\n"),
                       "7:23: bodies[0].orientation_wxyz: ", "non-zero quaternion");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 1\n    position: [0, 0, 0]\n"
                                "    orientation_wxyz: [1, 0, 0]\n"),
                       "7:23: bodies[0].orientation_wxyz: ", "expected a list of 4 numbers");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 1\n    position: [0, 0, 0]\n"
                                "    orientation_wxyz: [1, 0, .nan, 0]\n"),
                       "7:30: bodies[0].orientation_wxyz[2]: ", "must be finite");
}

TEST(SceneErrors, BodyOutsideBounds) {
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 1\n    position: [0, 7, 0]\n"),
                       "6:15: bodies[0].position: ", "outside the world bounds");
    // Exactly on the boundary is inside.
    EXPECT_EQ(
        sceneErrorOf(withBody("  - shape: sphere\n    radius: 1\n    position: [10, 6, 0]\n")), "");
}

TEST(SceneErrors, MalformedYamlReportsTheParserPosition) {
    const std::string err =
        sceneErrorOf("world:\n  bounds: {min: [0, 0, 0], max: [1, 1, 1]\nbodies:\n");
    EXPECT_EQ(err.rfind("test.yaml:", 0), 0u) << err;
    EXPECT_NE(err.find(": malformed YAML: "), std::string::npos) << err;
    // An unclosed flow sequence: yaml-cpp reports the end of the input, line 3 column 1.
    EXPECT_SCENE_ERROR("world:\n  gravity: [0, 0\n",
                       "3:1: malformed YAML: ", "end of sequence flow not found");
    EXPECT_SCENE_ERROR("world: {bounds: [}\n", "1:", "malformed YAML");
    EXPECT_SCENE_ERROR("\t- x\n", "1:", "");
    EXPECT_SCENE_ERROR("", "1:1: scene: ", "expected a mapping");
    EXPECT_SCENE_ERROR("- 1\n- 2\n", "1:1: scene: ", "expected a mapping");
}

// --- meshes ------------------------------------------------------------------------------------

TEST(SceneErrors, EveryTruncationFailsCleanly) {
    const std::string full = kFullScene;
    int errors = 0;
    int parsed = 0;
    for (std::size_t n = 0; n < full.size(); n += 3) {
        try {
            parse(full.substr(0, n));
            ++parsed;
        } catch (const SceneError& e) {
            ++errors;
            EXPECT_EQ(std::string(e.what()).rfind("test.yaml:", 0), 0u) << e.what();
        }
    }
    EXPECT_GT(errors, 0);
    EXPECT_GT(parsed, 0);
}

TEST(SceneErrors, HostileYamlFailsCleanly) {
    const std::string deep = std::string(5000, '[') + std::string(5000, ']');
    const std::string cases[] = {
        deep,
        "world: *undefined\n",
        "? [a, b]\n: 1\n",
        "world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\nbodies:\n  - !!binary AAAA\n",
        std::string("world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n") +
            std::string("\0\0\xff\xfe", 4),
        // (Bounds of +-1e308 are refused in their own right now: +-1e150 at most.)
        "world:\n  bounds: {min: [-1e150,-1e150,-1e150], max: [1e150,1e150,1e150]}\n"
        "bodies:\n  - shape: sphere\n    radius: 1e300\n    position: [0, 0, 0]\n",
        "world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n"
        "bodies:\n  - shape: sphere\n    radius: 1e-300\n    position: [0, 0, 0]\n",
        "world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  frames: 99999999999999999999\n",
        // A quoted key with a newline: the key path in the message is escaped too (found by
        // the fuzzer in CI).
        "world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  \"fr\\names\": 3\n",
    };
    for (const std::string& text : cases) {
        const std::string err = sceneErrorOf(text);
        EXPECT_EQ(err.rfind("test.yaml:", 0), 0u) << "input: " << text.substr(0, 80);
        // One printable line.
        for (const char c : err) EXPECT_GE(static_cast<unsigned char>(c), 0x20) << err;
    }
    EXPECT_SCENE_ERROR(deep, "1:", "malformed YAML: nesting is too deep");
    EXPECT_SCENE_ERROR("? [a, b]\n: 1\n", "1:3: scene: ", "keys must be plain names");
    EXPECT_SCENE_ERROR(cases[5], "5:13: bodies[0].radius: ", "degenerate mass properties");
    EXPECT_SCENE_ERROR(cases[6], "5:13: bodies[0].radius: ", "degenerate mass properties");
}

// --- the world -----------------------------------------------------------------------------------

TEST(SceneErrors, MagnitudesDoublePrecisionCannotIntegrateAreRefused) {
    const std::string ball = "  - {shape: sphere, radius: 0.5, position: [0, 0, 0], ";
    EXPECT_SCENE_ERROR(withBody(ball + "velocity: [1e308, 0, 0]}\n"), "4:",
                       "bodies[0].velocity: speed 1e+308 m/s is beyond what the world can "
                       "integrate: at most ");
    EXPECT_SCENE_ERROR(withBody(ball + "angular_velocity: [0, 1e308, 0]}\n"),
                       "4:", "bodies[0].angular_velocity: angular speed 1e+308 rad/s is beyond");
    EXPECT_SCENE_ERROR(
        withBody("  - {shape: sphere, radius: 0.5, repeat: {count: 3, speed: 1e300}}\n"),
        "4:", "repeat.speed: speed 1e+300 m/s is beyond");
    EXPECT_SCENE_ERROR(
        withBody("  - {shape: sphere, radius: 0.5, repeat: {count: 3, spin: 1e300}}\n"),
        "4:", "repeat.spin: angular speed 1e+300 rad/s is beyond");
    EXPECT_SCENE_ERROR(
        "world:\n  bounds: {min: [-1, -1, -1], max: [1, 1, 1]}\n"
        "  gravity: [0, -1e308, 0]\nbodies:\n",
        "3:12: world.gravity: ", "too strong for the time step");
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [-1e200, -1, -1], max: [1, 1, 1]}\nbodies:\n",
                       "2:", "world.bounds.min: coordinates must lie within +-1e+150");
    EXPECT_SCENE_ERROR(
        "world:\n  bounds: {min: [-1, -1, -1], max: [1, 1, 1]}\n"
        "  steps_per_frame: 2147483647\nbodies:\n",
        "3:20: world.steps_per_frame: ", "must be <= 100000");
    EXPECT_SCENE_ERROR(
        "world:\n  bounds: {min: [-1, -1, -1], max: [1, 1, 1]}\n"
        "  frames: 2000000000\nbodies:\n",
        "3:11: world.frames: ", "must be <= 1000000");
    // Regression: `scale: 1e300` was reported as "points are coplanar", 1e-300 as "no triangles".
    for (const char* scale : {"1e300", "1e-300"}) {
        EXPECT_SCENE_ERROR(withBody(std::string("  - {shape: hull, file: ../assets/crystal.obj, "
                                                "position: [0, 0, 0], scale: ") +
                                    scale + "}\n"),
                           "4:", "scale: must be in [1e-50, 1e+50]");
    }
    // Regression: a camera at 1e308 was reported as "up must not be parallel".
    EXPECT_SCENE_ERROR(kHeader + "camera: {position: [1e308, 0, 0], look_at: [0, 0, 0]}\n",
                       "4:", "camera.position: coordinates must lie within +-1e+150");
    // Regression: one 10^6-body `repeat` aliased 200 times asked for 2e8 bodies (5.9 GB, then
    // bad_alloc). The total is capped before any body of an entry is made.
    EXPECT_SCENE_ERROR(withBody("  - {shape: sphere, radius: 0.5, position: [0, 0, 0]}\n"
                                "  - &many {shape: sphere, radius: 0.01, "
                                "repeat: {count: 1000000}}\n  - *many\n"),
                       "5:", "1000000 more bodies after 1 would pass the limit of 1000000 bodies");
    // The limits leave every real scene alone: 1e4 m/s in a 20 m box at 1/60 s is fine.
    EXPECT_EQ(
        sceneErrorOf(withBody(ball + "velocity: [1e4, 0, 0], angular_velocity: [0, 0, 1e4]}\n")),
        "");
}

// Regression: values that parsed silently wrong. `frames: 0300` was octal (192 frames) while
// `09` was an error; "0.5" in quotes (a string) was read as a number.

TEST(SceneErrors, OctalAndQuotedNumbersAreRefused) {
    const std::string world = "world:\n  bounds: {min: [-1, -1, -1], max: [1, 1, 1]}\n";
    EXPECT_SCENE_ERROR(world + "  frames: 0300\nbodies:\n", "3:11: world.frames: ",
                       "expected a decimal integer without leading zeros, got '0300'");
    EXPECT_SCENE_ERROR(world + "  frames: 0x10\nbodies:\n",
                       "3:11: world.frames: ", "decimal integer");
    EXPECT_SCENE_ERROR(world + "  frames: \"30\"\nbodies:\n",
                       "3:11: world.frames: ", "expected an integer, got the string \"30\"");
    EXPECT_SCENE_ERROR(world + "  time_step: \"0.5\"\nbodies:\n",
                       "3:14: world.time_step: ", "expected a number, got the string \"0.5\"");
    // What stays valid: plain decimals, a sign, zero itself, and one leading "---".
    EXPECT_EQ(sceneErrorOf("---\n" + world +
                           "  frames: 300\n  steps_per_frame: +2\nbodies:\n  - {shape: sphere, "
                           "radius: 0.25, position: [0.5, 0.5, 0.5]}\n"),
              "");
}

// Regression: 20,000 coincident spheres were accepted and spent 130 s and 11 GB on frame 0 (10^6
// would have run for days). A start whose bodies overlap in more pairs than a step may flag is
// refused at the bodies key; the same count spread out loads.

TEST(SceneErrors, BodiesOverlappingEnMasseAreRefusedUpFront) {
    const std::string head =
        "world:\n  bounds: {min: [-100, -100, -100], max: [100, 100, 100]}\n"
        "bodies:\n  - shape: sphere\n    radius: 1\n";
    EXPECT_SCENE_ERROR(head +
                           "    repeat: {count: 5000, seed: 1, region: {min: [-1, -1, -1], "
                           "max: [1, 1, 1]}, separated: false}\n",
                       "3:1: bodies: ",
                       "overlap in about 1.24975e+07 pairs at the start, more "
                       "than the 10000000 a step may flag");
    EXPECT_EQ(
        sceneErrorOf(head + "    repeat: {count: 5000, seed: 1, region: {min: [-99, -99, -99], "
                            "max: [99, 99, 99]}}\n"),
        "");
}

// Regression: YAML::Load reads the first document only, so everything after a "---" was dropped
// without a word (a scene split in two lost its second half).

TEST(SceneErrors, ASecondDocumentIsRefusedWhereItStarts) {
    const std::string world = "world:\n  bounds: {min: [-1, -1, -1], max: [1, 1, 1]}\nbodies:\n";
    EXPECT_SCENE_ERROR(world + "---\nworld: {}\n", "4:1: scene: ", "a second YAML document");
    EXPECT_SCENE_ERROR(world + "...\n- {shape: sphere, radius: 1}\n",
                       "5:1: scene: ", "a second YAML document");
    // An empty second document is still a second document.
    EXPECT_SCENE_ERROR(world + "---\n", "4:1: scene: ", "a second YAML document");
    // One document with its own end marker, a leading "---" and trailing comments stay valid.
    const std::string one_body =
        world + "  - {shape: sphere, radius: 0.25, position: [0.5, 0.5, 0.5]}\n";
    EXPECT_EQ(sceneErrorOf("---\n" + one_body + "...\n"), "");
    EXPECT_EQ(sceneErrorOf(one_body + "# the end\n"), "");
}

// Regression: a one-triangle mesh was refused with "cannot build the convex hull ... needs at
// least 4 points", which names a step of ours instead of what is wrong with the file.

}  // namespace
}  // namespace engine
