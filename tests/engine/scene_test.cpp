// tests/engine/scene_test.cpp -- scene files: a full round trip, defaults, every error class with
// its exact line:col, orientation conventions, mesh paths, mass vs density, makeWorld.
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

namespace engine {
namespace {

namespace fs = std::filesystem;
constexpr Real kPi = std::numbers::pi_v<Real>;

const fs::path kSourceDir = CDLAB_SOURCE_DIR;
// Mesh paths in the test scenes are relative to this folder, like a file in scenes/.
const fs::path kScenesDir = kSourceDir / "scenes";

Scene parse(const std::string& text) { return parseScene(text, "test.yaml", kScenesDir); }

// A minimal valid scene; the error tests append one body or replace a line.
const std::string kHeader =
    "world:\n"                                             // 1
    "  bounds: {min: [-10, -6, -10], max: [10, 6, 10]}\n"  // 2
    "bodies:\n";                                           // 3

std::string withBody(const std::string& body_lines) { return kHeader + body_lines; }

// kHeader with one body: the smallest scene that loads.
const std::string kValid =
    kHeader + "  - {shape: sphere, radius: 0.25, position: [0.5, 0.5, 0.5]}\n";

const char* const kFullScene = R"(world:
  bounds: {min: [-10, -6, -10], max: [10, 6, 10]}
  gravity: [0, -9.81, 0]
  time_step: 0.01
  steps_per_frame: 2
  frames: 240
broadphase: brute
output: {width: 640, height: 360, fps: 25}
camera: {position: [1, 8, 24], look_at: [0, 1, 0], up: [0, 1, 0], fov_deg: 50}
draw:
  bodies: false
  volumes: [aabb, obb]
  bounds: false
  hud: false
  structure: true
bodies:
  - name: ball
    shape: sphere
    radius: 0.5
    position: [0, 1, 0]
    velocity: [1, 0, 0]
    angular_velocity: [0, 2, 0]
    mass: 2.0
  - name: crate
    shape: box
    half_extents: [0.5, 0.3, 0.2]
    position: [2, 0, 0]
    orientation_wxyz: [2, 0, 0, 0]
    density: 500
  - shape: capsule
    radius: 0.25
    half_height: 0.6
    position: [-2, 0, 0]
    euler_deg: [0, 30, 0]
  - name: gem
    shape: hull
    file: ../assets/crystal.obj
    scale: 2
    position: [0, 0, 3]
  - name: ring
    shape: mesh
    file: ../assets/torus.obj
    scale: 0.5
    position: [0, 0, -3]
    density: 800
)";

TEST(Scene, FullSceneRoundTrip) {
    const Scene s = parse(kFullScene);
    EXPECT_EQ(s.name, "test");
    EXPECT_EQ(s.world.bounds.min, Vec3(-10, -6, -10));
    EXPECT_EQ(s.world.bounds.max, Vec3(10, 6, 10));
    EXPECT_EQ(s.world.gravity, Vec3(0, -9.81, 0));
    EXPECT_EQ(s.world.time_step, 0.01);
    EXPECT_EQ(s.world.broad_phase, "brute");
    EXPECT_EQ(s.steps_per_frame, 2);
    EXPECT_EQ(s.frames, 240);
    EXPECT_EQ(s.output.width, 640);
    EXPECT_EQ(s.output.height, 360);
    EXPECT_EQ(s.output.fps, 25);
    EXPECT_EQ(s.camera.position, Vec3(1, 8, 24));
    EXPECT_EQ(s.camera.look_at, Vec3(0, 1, 0));
    EXPECT_EQ(s.camera.up, Vec3(0, 1, 0));
    EXPECT_EQ(s.camera.fov_deg, 50);
    EXPECT_FALSE(s.draw.bodies);
    EXPECT_FALSE(s.draw.sphere);
    EXPECT_TRUE(s.draw.aabb);
    EXPECT_TRUE(s.draw.obb);
    EXPECT_TRUE(s.draw.volumes_given);  // the scene chose: no broad-phase default
    EXPECT_FALSE(s.draw.bounds);
    EXPECT_FALSE(s.draw.hud);
    EXPECT_TRUE(s.draw.structure);
    ASSERT_EQ(s.bodies.size(), 5u);

    const Body& ball = s.bodies[0];
    EXPECT_EQ(ball.name, "ball");
    EXPECT_EQ(ball.shape.type, collision::ShapeType::Sphere);
    EXPECT_EQ(ball.shape.radius, 0.5);
    EXPECT_EQ(ball.position, Vec3(0, 1, 0));
    EXPECT_EQ(ball.mass, 2.0);
    EXPECT_LE((ball.velocity() - Vec3(1, 0, 0)).norm(), 1e-15);
    EXPECT_LE((ball.angularVelocity() - Vec3(0, 2, 0)).norm(), 1e-12);
    // Solid sphere: I = 2/5 m r^2.
    EXPECT_NEAR(ball.inertia_body(0, 0), 0.4 * 2 * 0.25, 1e-15);

    const Body& crate = s.bodies[1];
    EXPECT_EQ(crate.shape.type, collision::ShapeType::Box);
    EXPECT_EQ(crate.shape.half_extents, Vec3(0.5, 0.3, 0.2));
    EXPECT_NEAR(crate.mass, 500 * 1.0 * 0.6 * 0.4, 1e-12);
    // [2, 0, 0, 0] is normalised to the identity.
    EXPECT_EQ(crate.orientation.coeffs(), Quat::Identity().coeffs());

    const Body& pill = s.bodies[2];
    EXPECT_EQ(pill.name, "capsule2");  // default name: shape + index
    EXPECT_EQ(pill.shape.half_height, 0.6);
    EXPECT_NEAR(pill.mass, 1000 * (kPi * 0.0625 * 1.2 + 4.0 / 3 * kPi * 0.015625), 1e-9);
    EXPECT_NEAR(
        pill.orientation.angularDistance(Quat(Eigen::AngleAxis<Real>(kPi / 6, Vec3::UnitY()))), 0,
        1e-12);

    const Body& gem = s.bodies[3];
    EXPECT_EQ(gem.shape.type, collision::ShapeType::ConvexHull);
    ASSERT_TRUE(gem.shape.hull);
    EXPECT_EQ(gem.position, Vec3(0, 0, 3));

    const Body& ring = s.bodies[4];
    EXPECT_EQ(ring.shape.type, collision::ShapeType::Mesh);
    ASSERT_TRUE(ring.shape.mesh && ring.shape.hull);
    EXPECT_EQ(ring.shape.mesh->triangles.size(), 768u);
    // Torus at scale 0.5: outer radius (1 + 0.35) / 2.
    Real max_r = 0;
    for (const Vec3& v : ring.shape.mesh->vertices) max_r = std::max(max_r, v.norm());
    EXPECT_NEAR(max_r, 0.675, 1e-3);
    EXPECT_NEAR(ring.mass, 800 * shapeVolume(ring.shape), 1e-9);
}

TEST(Scene, Defaults) {
    const Scene s =
        parse(withBody("  - shape: sphere\n    radius: 0.5\n    position: [0, 0, 0]\n"));
    EXPECT_EQ(s.world.gravity, Vec3::Zero());
    // No time_step or steps_per_frame: two steps of 1/60 s per frame at 30 fps, so the video
    // plays at the speed of the simulation.
    EXPECT_EQ(s.world.time_step, Real(1) / 60);
    EXPECT_EQ(s.world.broad_phase, "sap");
    EXPECT_EQ(s.steps_per_frame, 2);
    EXPECT_EQ(videoTimeScale(s), 1);
    EXPECT_EQ(s.frames, 120);
    EXPECT_EQ(s.output.width, 960);
    EXPECT_EQ(s.output.height, 540);
    EXPECT_EQ(s.output.fps, 30);
    EXPECT_EQ(s.camera.position, Vec3(0, 8, 24));
    EXPECT_EQ(s.camera.look_at, Vec3::Zero());
    EXPECT_EQ(s.camera.up, Vec3::UnitY());
    EXPECT_EQ(s.camera.fov_deg, 45);
    EXPECT_TRUE(s.draw.bodies);
    EXPECT_TRUE(s.draw.sphere);
    EXPECT_FALSE(s.draw.aabb);
    EXPECT_FALSE(s.draw.obb);
    EXPECT_FALSE(s.draw.volumes_given);  // a run draws its broad phase's volume
    EXPECT_TRUE(s.draw.bounds);
    EXPECT_TRUE(s.draw.hud);
    EXPECT_FALSE(s.draw.structure);
    EXPECT_EQ(s.draw.bvh_depth, -1);
    EXPECT_FALSE(s.draw.contacts);
    ASSERT_EQ(s.bodies.size(), 1u);
    const Body& b = s.bodies[0];
    EXPECT_EQ(b.name, "sphere0");
    EXPECT_NEAR(b.mass, 1000 * 4.0 / 3 * kPi * 0.125, 1e-9);  // density 1000
    EXPECT_EQ(b.orientation.coeffs(), Quat::Identity().coeffs());
    EXPECT_EQ(b.linear_momentum, Vec3::Zero());
    EXPECT_EQ(b.angular_momentum, Vec3::Zero());
    // No bodies, or an empty list: an error, not a run that shows nothing.
    EXPECT_SCENE_ERROR(kHeader, "3:1: bodies: ", "a scene needs at least one body");
    EXPECT_SCENE_ERROR("world:\n  bounds: {min: [-1, -1, -1], max: [1, 1, 1]}\nbodies: []\n",
                       "3:1: bodies: ", "a scene needs at least one body");
}

// Expectations, traces and pause dumps name bodies, so two bodies may not share a name, whether
// written, generated by repeat (<name>_k) or given by default (<shape><index>).
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
TEST(Scene, DefaultTimingMakesVideoTimeSimulatedTime) {
    const std::string body = "bodies:\n  - {shape: sphere, radius: 0.5, position: [0, 0, 0]}\n";
    const auto scene = [&](const std::string& world_lines, const std::string& output) {
        return parse("world:\n  bounds: {min: [-9, -9, -9], max: [9, 9, 9]}\n" + world_lines +
                     output + body);
    };
    const Scene fps24 = scene("", "output: {fps: 24}\n");
    EXPECT_EQ(fps24.steps_per_frame, 3);  // ceil(60 / 24): steps no longer than 1/60 s
    EXPECT_EQ(fps24.world.time_step, Real(1) / 72);
    const Scene fps120 = scene("", "output: {fps: 120}\n");
    EXPECT_EQ(fps120.steps_per_frame, 1);
    EXPECT_EQ(fps120.world.time_step, Real(1) / 120);
    const Scene steps_only = scene("  steps_per_frame: 4\n", "");
    EXPECT_EQ(steps_only.world.time_step, Real(1) / 120);
    const Scene dt_only = scene("  time_step: 0.005\n", "");
    EXPECT_EQ(dt_only.steps_per_frame, 7);  // round(6.67): the nearest whole number of steps
    const Scene coarse = scene("  time_step: 0.5\n", "");
    EXPECT_EQ(coarse.steps_per_frame, 1);
    const Scene both = scene("  time_step: 0.001\n  steps_per_frame: 2\n", "");
    EXPECT_EQ(both.world.time_step, 0.001);
    EXPECT_EQ(both.steps_per_frame, 2);
    EXPECT_NEAR(videoTimeScale(both), 0.06, 1e-15);
    for (const Scene* s : {&fps24, &fps120, &steps_only}) {
        EXPECT_NEAR(videoTimeScale(*s), 1, 1e-15);
    }
    // The key order in the file does not matter: output may come after world or before it.
    const Scene output_first = parse(
        "output: {fps: 24}\nworld:\n  bounds: {min: [-9, -9, -9], "
        "max: [9, 9, 9]}\n" +
        body);
    EXPECT_EQ(output_first.steps_per_frame, 3);
}

// draw.bvh_depth: the hierarchy level to draw (-1: off, as when absent); draw.contacts.
TEST(Scene, DrawBvhDepthAndContacts) {
    const Scene on = parse(kValid + "draw: {bvh_depth: 4, contacts: true}\n");
    EXPECT_EQ(on.draw.bvh_depth, 4);
    EXPECT_TRUE(on.draw.contacts);
    const Scene root = parse(kValid + "draw: {bvh_depth: 0, contacts: false}\n");
    EXPECT_EQ(root.draw.bvh_depth, 0);
    EXPECT_FALSE(root.draw.contacts);
    EXPECT_EQ(parse(kValid + "draw: {bvh_depth: -1}\n").draw.bvh_depth, -1);
    // The other draw keys keep their defaults.
    EXPECT_TRUE(on.draw.sphere);
    EXPECT_FALSE(on.draw.structure);
}

// --- errors: every class, with its exact position ----------------------------------------------

TEST(SceneErrors, UnknownKeysAtEveryLevel) {
    EXPECT_SCENE_ERROR("wrld:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n", "1:1: wrld: ",
                       "unknown key 'wrld' (expected one of: world, broadphase, output, camera, "
                       "draw, bodies, chains, expect)");
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

TEST(SceneDraw, VolumesAcceptKdopsBesideTheBodyVolumes) {
    const Scene s = parse(kValid + "draw: {volumes: [kdop26, aabb, kdop6]}\n");
    EXPECT_TRUE(s.draw.volumes_given);
    EXPECT_FALSE(s.draw.sphere);
    EXPECT_TRUE(s.draw.aabb);
    EXPECT_EQ(s.draw.kdop, (std::array<bool, 4>{true, false, false, true}));
    EXPECT_EQ(parse(kValid).draw.kdop, (std::array<bool, 4>{}));
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
              "volumes, bounds, hud, structure, bvh_depth, contacts)");
}

TEST(SceneErrors, UnknownNamesListTheChoices) {
    const std::string err = sceneErrorOf(kHeader + "broadphase: quadtree\n");
    EXPECT_EQ(err.rfind("test.yaml:4:13: broadphase: unknown broad phase 'quadtree' "
                        "(expected one of: " +
                            collision::broadPhaseNames() + ")",
                        0),
              0u)
        << err;
    EXPECT_SCENE_ERROR(withBody("  - shape: cone\n    position: [0, 0, 0]\n"),
                       "4:12: bodies[0].shape: ",
                       "unknown shape 'cone' (expected one of: sphere, box, capsule, hull, mesh)");
}

TEST(Scene, MeshBvhIsChosenByTheWorld) {
    const std::string body =
        "  - shape: mesh\n    file: ../assets/torus.obj\n"
        "    position: [0, 0, 0]\n";
    // Default: every mesh body carries the default hierarchy, built once and shared.
    const Scene d = parse(withBody(body + body));
    ASSERT_EQ(d.bodies.size(), 2u);
    ASSERT_TRUE(d.bodies[0].shape.bvh);
    EXPECT_EQ(d.bodies[0].shape.bvh->volumeName(), collision::kDefaultMeshBvh);
    EXPECT_EQ(d.bodies[0].shape.bvh.get(), d.bodies[1].shape.bvh.get());
    EXPECT_EQ(d.world.mesh_bvh, collision::kDefaultMeshBvh);
    // The two coincident tori collide, found through the hierarchy: its counters reach StepStats.
    const World w = makeWorld(d);
    EXPECT_EQ(w.collidingPairs().size(), 1u);
    EXPECT_GT(w.lastStats().bv_tests, 0);
    EXPECT_GT(w.lastStats().triangle_tests, 0);
    // Every volume type by name.
    for (const std::string_view name : collision::bvhVolumeNames()) {
        const Scene s = parse(
            "world:\n  bounds: {min: [-10, -6, -10], max: [10, 6, 10]}\n"
            "  mesh_bvh: " +
            std::string(name) + "\nbodies:\n" + body);
        ASSERT_EQ(s.bodies.size(), 1u);
        ASSERT_TRUE(s.bodies[0].shape.bvh);
        EXPECT_EQ(s.bodies[0].shape.bvh->volumeName(), name);
        EXPECT_EQ(s.bodies[0].shape.bvh->triangleCount(),
                  static_cast<std::int32_t>(s.bodies[0].shape.mesh->triangles.size()));
        EXPECT_TRUE(s.bodies[0].shape.bvh->validate());
    }
}

TEST(Scene, CcdToleranceAndTargetGapReachTheWorld) {
    // Defaults: the constants the continuous stage had before the keys existed, so scenes that
    // do not set them keep their results.
    const Scene d = parse(kValid);
    EXPECT_EQ(d.world.ccd_tolerance, collision::kToiRelativeTolerance);
    EXPECT_EQ(d.world.ccd_target_gap, Real(1e-3));
    const Scene s = parse(
        "world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n"
        "  ccd: conservative_advancement\n  ccd_tolerance: 0.05\n"
        "  ccd_target_gap: 0\nbodies:\n  - {shape: sphere, radius: 0.25, position: [0.5, 0.5, "
        "0.5]}\n");
    EXPECT_EQ(s.world.ccd_tolerance, Real(0.05));
    EXPECT_EQ(s.world.ccd_target_gap, Real(0));
    const World w = makeWorld(s);
    EXPECT_EQ(w.settings().ccd_tolerance, Real(0.05));
    EXPECT_EQ(w.settings().ccd_target_gap, Real(0));
    // The upper ends of the ranges are accepted.
    EXPECT_EQ(
        sceneErrorOf("world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  ccd_tolerance: 1\n"
                     "  ccd_target_gap: 1\nbodies:\n  - {shape: sphere, radius: 0.25, position: "
                     "[0.5, 0.5, 0.5]}\n"),
        "");
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

TEST(Scene, RebuildRatioReachesTheWorld) {
    EXPECT_EQ(parse(kValid).world.rebuild_ratio, Real(1.5));
    const Scene s = parse(
        "world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  rebuild_ratio: 2.25\nbodies:\n"
        "  - {shape: sphere, radius: 0.25, position: [0.5, 0.5, 0.5]}\n");
    EXPECT_EQ(s.world.rebuild_ratio, Real(2.25));
    EXPECT_EQ(makeWorld(s).settings().rebuild_ratio, Real(2.25));
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
                       "kdop6, kdop14, kdop18, kdop26, rss, lss)");
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

class SceneMeshes : public ::testing::Test {
protected:
    void SetUp() override {
        const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() / ("cdlab_scene_" + std::string(info->name()));
        fs::remove_all(dir_);
        fs::create_directories(dir_ / "meshes");
    }
    void TearDown() override { fs::remove_all(dir_); }
    void write(const fs::path& rel, const std::string& text) {
        std::ofstream(dir_ / rel, std::ios::binary) << text;
    }
    fs::path dir_;
};

// A unit cube centred at (5, 0, 0): its file origin is not its centre of mass.
const char* const kOffsetCubeObj =
    "v 4.5 -0.5 -0.5\nv 5.5 -0.5 -0.5\nv 5.5 0.5 -0.5\nv 4.5 0.5 -0.5\n"
    "v 4.5 -0.5 0.5\nv 5.5 -0.5 0.5\nv 5.5 0.5 0.5\nv 4.5 0.5 0.5\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";

TEST_F(SceneMeshes, MeshPathIsRelativeToTheSceneFile) {
    write("meshes/cube.obj", kOffsetCubeObj);
    write("scene.yaml", kHeader +
                            "  - shape: mesh\n    file: meshes/cube.obj\n"
                            "    position: [1, 2, 3]\n    density: 10\n");
    const Scene s = loadScene(dir_ / "scene.yaml");
    EXPECT_EQ(s.name, "scene");
    ASSERT_EQ(s.bodies.size(), 1u);
    const Body& b = s.bodies[0];
    EXPECT_NEAR(b.mass, 10.0, 1e-12);
    // Re-centred: the local origin is the centre of mass, and `position` is where it goes.
    EXPECT_EQ(b.position, Vec3(1, 2, 3));
    for (const Vec3& v : b.shape.mesh->vertices) EXPECT_NEAR(v.cwiseAbs().maxCoeff(), 0.5, 1e-12);
    for (const Vec3& v : b.shape.hull->vertices) EXPECT_NEAR(v.cwiseAbs().maxCoeff(), 0.5, 1e-12);
    const MassPropertiesOutput local = computeMassProperties(b.shape, 1);
    ASSERT_TRUE(local.ok) << local.error;
    EXPECT_LE(local.props.center_of_mass.norm(), 1e-12);
    // A cube's inertia: m/6 s^2.
    EXPECT_NEAR(b.inertia_body(0, 0), 10.0 / 6, 1e-12);
    EXPECT_NEAR(b.inertia_body(0, 1), 0, 1e-12);

    // The same file through parseScene with the project's scenes/ folder as the base.
    const Scene t =
        parse(withBody("  - shape: hull\n    file: ../assets/spaceship.obj\n"
                       "    position: [0, 0, 0]\n"));
    ASSERT_EQ(t.bodies.size(), 1u);
    EXPECT_GT(t.bodies[0].shape.hull->vertices.size(), 8u);
}

TEST_F(SceneMeshes, ImportedOnceAndShared) {
    std::string text = kHeader;
    for (int i = 0; i < 4; ++i) {
        text += "  - shape: mesh\n    file: ../assets/torus.obj\n    position: [" +
                std::to_string(i) + ", 0, 0]\n";
    }
    text += "  - shape: mesh\n    file: ../scenes/../assets/torus.obj\n    position: [0, 1, 0]\n";
    text +=
        "  - shape: mesh\n    file: ../assets/torus.obj\n    scale: 2\n    position: [0, 2, 0]\n";
    text += "  - shape: hull\n    file: ../assets/torus.obj\n    position: [0, 3, 0]\n";
    const Scene s = parse(text);
    ASSERT_EQ(s.bodies.size(), 7u);
    for (int i = 1; i < 5; ++i) {
        EXPECT_EQ(s.bodies[i].shape.mesh.get(), s.bodies[0].shape.mesh.get());
        EXPECT_EQ(s.bodies[i].shape.hull.get(), s.bodies[0].shape.hull.get());
    }
    EXPECT_NE(s.bodies[5].shape.mesh.get(), s.bodies[0].shape.mesh.get());  // other scale
    EXPECT_NE(s.bodies[6].shape.hull.get(), s.bodies[0].shape.hull.get());  // hull: own COM
    // The hull fills the hole: ~1.5 times the torus's mass at the same density.
    EXPECT_GT(s.bodies[6].mass, 1.3 * s.bodies[0].mass);
}

TEST_F(SceneMeshes, MeshErrorsAreReportedAtTheFileKey) {
    EXPECT_SCENE_ERROR(withBody("  - shape: mesh\n    position: [0, 0, 0]\n"
                                "    file: ../assets/missing.obj\n"),
                       "6:5: bodies[0].file: ", "no such file");
    write("meshes/garbage.obj", std::string(200, '\x07') + "\x01\x02\x03");
    write("meshes/flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    write("meshes/open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
    write("meshes/lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n");
    auto error = [&](const std::string& shape, const std::string& file) {
        return sceneErrorOf(withBody("  - shape: " + shape + "\n    file: meshes/" + file +
                                     "\n    position: [0, 0, 0]\n"),
                            dir_);
    };
    const std::string garbage = error("mesh", "garbage.obj");
    EXPECT_EQ(garbage.rfind("test.yaml:5:5: bodies[0].file: ", 0), 0u) << garbage;
    const std::string flat = error("hull", "flat.obj");
    EXPECT_EQ(flat.rfind("test.yaml:5:5: bodies[0].file: ", 0), 0u) << flat;
    EXPECT_NE(flat.find("has no volume: its points lie in one plane"), std::string::npos) << flat;
    // The open tetrahedron loads as a mesh (its hull gives the mass) and as a hull.
    EXPECT_EQ(error("mesh", "open.obj"), "");
    EXPECT_EQ(error("hull", "open.obj"), "");
    // A flat mesh has no hull, which contact response needs: the message says what to use.
    const std::string flat_mesh = error("mesh", "flat.obj");
    EXPECT_EQ(flat_mesh.rfind("test.yaml:5:5: bodies[0].file: ", 0), 0u) << flat_mesh;
    EXPECT_NE(flat_mesh.find("use 'shape: box' with a zero half extent and 'mass'"),
              std::string::npos)
        << flat_mesh;
    const std::string lines = error("mesh", "lines.obj");
    EXPECT_EQ(lines.rfind("test.yaml:5:5: bodies[0].file: ", 0), 0u) << lines;
}

// The offset unit cube without its +y face (f 4 8 7 3): an open box, 4 boundary edges.
std::string openCubeObj() {
    std::string text = kOffsetCubeObj;
    const std::string top = "f 4 8 7 3\n";
    text.erase(text.find(top), top.size());
    return text;
}

// Issue "Meshes from the real world": `shape: mesh` refused every mesh that is not closed
// ("mesh is not closed", exit 2), although collision only uses its triangles. An open box
//        +  +   <- no lid
//        |  |
//        +--+
// now loads; its mass properties are its convex hull's, i.e. the closed cube's, and a note says so.
TEST_F(SceneMeshes, OpenMeshLoadsWithItsHullsMassPropertiesAndANote) {
    write("meshes/cube.obj", kOffsetCubeObj);
    write("meshes/open_cube.obj", openCubeObj());
    const auto scene = [&](const std::string& file) {
        write("s.yaml", kHeader + "  - name: lidless\n    shape: mesh\n    file: meshes/" + file +
                            "\n    position: [1, 2, 3]\n    density: 10\n");
        return loadScene(dir_ / "s.yaml");
    };
    const Scene closed = scene("cube.obj");
    const Scene open = scene("open_cube.obj");
    EXPECT_TRUE(closed.notes.empty());
    ASSERT_EQ(open.notes.size(), 1u);
    EXPECT_EQ(open.notes[0], (dir_ / "s.yaml").string() +
                                 ":6:5: bodies[0] (lidless): mesh 'meshes/open_cube.obj' is open "
                                 "(4 boundary edges); mass properties from its convex hull "
                                 "(collision: its triangles, surface contact only)");
    const Body& o = open.bodies.at(0);
    const Body& c = closed.bodies.at(0);
    EXPECT_EQ(o.shape.mesh->triangles.size(), 10u);  // the surface as it is
    // Hull = the closed cube: mass and inertia equal to rounding (1e-12 relative).
    EXPECT_NEAR(o.mass, c.mass, 1e-12 * c.mass);
    EXPECT_LE((o.inertia_body - c.inertia_body).norm(), 1e-12 * c.inertia_body.norm());
    EXPECT_NEAR(o.inertia_body(0, 0), 10.0 / 6, 1e-12);
    // Re-centred on the hull's centre of mass, as the closed cube on its own.
    for (const Vec3& v : o.shape.mesh->vertices) EXPECT_NEAR(v.cwiseAbs().maxCoeff(), 0.5, 1e-12);
    // It simulates: a World is made and steps.
    World world = makeWorld(open);
    world.step();
    EXPECT_TRUE(world.bodies()[0].position.allFinite());
}

TEST_F(SceneMeshes, MassAndInertiaOverrideTheHull) {
    write("meshes/open_cube.obj", openCubeObj());
    const std::string mesh =
        "  - name: lidless\n    shape: mesh\n    file: meshes/open_cube.obj\n"
        "    position: [0, 0, 0]\n";
    const Scene diag = parseScene(withBody(mesh + "    mass: 3\n    inertia: [0.5, 0.6, 0.7]\n"),
                                  "test.yaml", dir_);
    const Body& d = diag.bodies.at(0);
    EXPECT_EQ(d.mass, 3);
    EXPECT_EQ(d.inertia_body, Mat3(Vec3(0.5, 0.6, 0.7).asDiagonal()));
    ASSERT_EQ(diag.notes.size(), 1u);
    EXPECT_NE(diag.notes[0].find("is open (4 boundary edges); centre of mass from its convex "
                                 "hull, mass and inertia as given"),
              std::string::npos)
        << diag.notes[0];
    const Scene full = parseScene(
        withBody(mesh + "    mass: 3\n    inertia: [[1, 0.1, 0], [0.1, 1, 0], [0, 0, 1.5]]\n"),
        "test.yaml", dir_);
    Mat3 want;
    want << 1, 0.1, 0, 0.1, 1, 0, 0, 0, 1.5;
    EXPECT_EQ(full.bodies.at(0).inertia_body, want);
    // Mass alone: the hull's inertia per kilogram, scaled (cube: m/6).
    const Scene mass = parseScene(withBody(mesh + "    mass: 3\n"), "test.yaml", dir_);
    EXPECT_NEAR(mass.bodies.at(0).inertia_body(1, 1), 3.0 / 6, 1e-12);
    // Any shape takes an inertia with its mass.
    const Body ball = parse(withBody("  - shape: sphere\n    radius: 1\n    position: [0, 0, 0]\n"
                                     "    mass: 2\n    inertia: [1, 1, 1]\n"))
                          .bodies.at(0);
    EXPECT_EQ(ball.inertia_body, Mat3::Identity());
}

TEST_F(SceneMeshes, InvalidInertiaIsAnErrorAtItsKey) {
    write("meshes/open_cube.obj", openCubeObj());
    const auto error = [&](const std::string& lines) {
        return sceneErrorOf(withBody("  - shape: mesh\n    file: meshes/open_cube.obj\n"
                                     "    position: [0, 0, 0]\n" +
                                     lines),
                            dir_);
    };
    const auto expect = [](const std::string& err, const std::string& prefix,
                           const std::string& fragment) {
        EXPECT_EQ(err.rfind(prefix, 0), 0u) << err;
        EXPECT_NE(err.find(fragment), std::string::npos) << err;
    };
    expect(error("    mass: 3\n    inertia: [1, 1, 3]\n"), "test.yaml:8:14: bodies[0].inertia: ",
           "violates the triangle inequality of principal moments");
    expect(error("    mass: 3\n    inertia: [1, -1, 1]\n"),
           "test.yaml:8:14: bodies[0].inertia: ", "must be positive definite");
    expect(error("    mass: 3\n    inertia: [1, 0, 1]\n"),
           "test.yaml:8:14: bodies[0].inertia: ", "must be positive definite");
    expect(error("    mass: 3\n    inertia: [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]\n"),
           "test.yaml:8:14: bodies[0].inertia: ", "must be symmetric");
    expect(error("    mass: 3\n    inertia: [1, 2]\n"),
           "test.yaml:8:14: bodies[0].inertia: ", "expected [ix, iy, iz]");
    expect(error("    mass: 3\n    inertia: [[1, 0, 0], [0, 1, 0]]\n"),
           "test.yaml:8:14: bodies[0].inertia: ", "expected [ix, iy, iz]");
    expect(error("    mass: 3\n    inertia: [1, x, 1]\n"),
           "test.yaml:8:18: bodies[0].inertia[1]: ", "");
    expect(error("    inertia: [1, 1, 1]\n"), "test.yaml:7:5: bodies[0].inertia: ", "needs 'mass'");
    expect(error("    density: 5\n    inertia: [1, 1, 1]\n"),
           "test.yaml:8:5: bodies[0].inertia: ", "needs 'mass'");
}

// A closed mesh whose own volume is unusable (inward oriented) stays an error, naming the ways
// out; with mass and inertia given it loads (centre of mass from its hull).
TEST_F(SceneMeshes, ClosedMeshWithoutUsableVolumeNamesTheWaysOut) {
    std::string inward;
    std::istringstream in(kOffsetCubeObj);
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("f ", 0) == 0) {
            std::istringstream f(line.substr(2));
            std::vector<std::string> idx;
            for (std::string t; f >> t;) idx.push_back(t);
            line = "f";
            for (auto it = idx.rbegin(); it != idx.rend(); ++it) line += " " + *it;
        }
        inward += line + "\n";
    }
    write("meshes/inward.obj", inward);
    const std::string mesh =
        "  - shape: mesh\n    file: meshes/inward.obj\n    position: [0, 0, 0]\n";
    const std::string err = sceneErrorOf(withBody(mesh), dir_);
    EXPECT_EQ(err.rfind("test.yaml:5:5: bodies[0].file: ", 0), 0u) << err;
    EXPECT_NE(err.find("inward"), std::string::npos) << err;
    EXPECT_NE(err.find("use 'shape: hull'"), std::string::npos) << err;
    EXPECT_NE(err.find("give 'mass' and 'inertia'"), std::string::npos) << err;
    EXPECT_NE(
        sceneErrorOf(withBody(mesh + "    mass: 2\n"), dir_).find("give 'mass' and 'inertia'"),
        std::string::npos);
    const Scene s =
        parseScene(withBody(mesh + "    mass: 2\n    inertia: [1, 1, 1]\n"), "test.yaml", dir_);
    EXPECT_EQ(s.bodies.at(0).mass, 2);
    ASSERT_EQ(s.notes.size(), 1u);
    EXPECT_NE(s.notes[0].find("gives no volume"), std::string::npos) << s.notes[0];
}

// What an import changed is noted once per file, at the first body that uses it.
TEST_F(SceneMeshes, ImportChangesAreNotedOncePerFile) {
    // A tetrahedron and a sliver whose fifth vertex is 1e-9 from the second: one in float.
    write("meshes/near.obj",
          "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1.000000001 0 0\n"
          "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 2 5 4\n");
    const std::string body =
        "  - shape: mesh\n    file: meshes/near.obj\n    position: [0, 0, 0]\n";
    const Scene s = parseScene(withBody(body + body), "test.yaml", dir_);
    ASSERT_EQ(s.bodies.size(), 2u);
    ASSERT_EQ(s.notes.size(), 1u);
    EXPECT_EQ(s.notes[0].rfind("test.yaml:5:5: bodies[0].file: 'meshes/near.obj': import changed "
                               "the geometry: dropped 1 of 5 triangles as degenerate",
                               0),
              0u)
        << s.notes[0];
    EXPECT_NE(s.notes[0].find("merged 1 vertices"), std::string::npos) << s.notes[0];
    // The shipped meshes import without a change.
    EXPECT_TRUE(parse(withBody("  - shape: mesh\n    file: ../assets/torus.obj\n"
                               "    position: [0, 0, 0]\n"))
                    .notes.empty());
}

TEST_F(SceneMeshes, LoadSceneFileErrors) {
    try {
        loadScene(dir_ / "absent.yaml");
        FAIL() << "no error";
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()), (dir_ / "absent.yaml").string() +
                                             ":1:1: scene: cannot open the file (no such file)");
    }
    write("bad.yaml", "world:\n  bounds: {min: [0, 0, 0], max: [1, 1, 1]}\n  frames: -1\n");
    try {
        loadScene(dir_ / "bad.yaml");
        FAIL() << "no error";
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()),
                  (dir_ / "bad.yaml").string() + ":3:11: world.frames: must be >= 1");
    }
    // Regression: a 50 MB list of bodies took 4.8 GB in yaml-cpp's nodes. Past 16 MiB the file
    // is refused before it is parsed (a comment line fills this one).
    write("huge.yaml", "# " + std::string((std::size_t(16) << 20) + 1, 'x') + "\n");
    try {
        loadScene(dir_ / "huge.yaml");
        FAIL() << "no error";
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()), (dir_ / "huge.yaml").string() +
                                             ":1:1: scene: the file has 16777220 bytes, more than "
                                             "the limit of 16777216 (16 MiB); describe large "
                                             "populations with repeat:");
    }
}

// --- conventions -------------------------------------------------------------------------------

TEST(Scene, EulerMatchesQuaternion) {
    auto orientationOf = [](const std::string& key_line) {
        const Scene s =
            parse(withBody("  - shape: box\n    half_extents: [1, 2, 3]\n"
                           "    position: [0, 0, 0]\n" +
                           key_line));
        return s.bodies.at(0).orientation;
    };
    // A single axis: 30 degrees about y = (cos 15, 0, sin 15, 0).
    const Quat a = orientationOf("    euler_deg: [0, 30, 0]\n");
    const Real c = std::cos(kPi / 12);
    const Real s = std::sin(kPi / 12);
    const Quat b = orientationOf("    orientation_wxyz: [" + std::to_string(c) + ", 0, " +
                                 std::to_string(s) + ", 0]\n");
    EXPECT_LE(a.angularDistance(b), 1e-6);
    // Intrinsic X then Y: R = Rx(90) Ry(90) sends x to y and z to x (extrinsic order would send
    // x to -z).
    const Quat xy = orientationOf("    euler_deg: [90, 90, 0]\n");
    EXPECT_LE((xy * Vec3::UnitX() - Vec3::UnitY()).norm(), 1e-12);
    EXPECT_LE((xy * Vec3::UnitZ() - Vec3::UnitX()).norm(), 1e-12);
    // General angles against the product of the three axis rotations.
    const Quat g = orientationOf("    euler_deg: [10, -20, 35]\n");
    const Quat expected = Quat(Eigen::AngleAxis<Real>(10 * kPi / 180, Vec3::UnitX())) *
                          Quat(Eigen::AngleAxis<Real>(-20 * kPi / 180, Vec3::UnitY())) *
                          Quat(Eigen::AngleAxis<Real>(35 * kPi / 180, Vec3::UnitZ()));
    EXPECT_LE(g.angularDistance(expected), 1e-12);
    const Quat q =
        orientationOf("    orientation_wxyz: [" + std::to_string(expected.w()) + ", " +
                      std::to_string(expected.x()) + ", " + std::to_string(expected.y()) + ", " +
                      std::to_string(expected.z()) + "]\n");
    EXPECT_LE(g.angularDistance(q), 1e-5);
    EXPECT_NEAR(q.norm(), 1, 1e-15);
}

TEST(Scene, AngularVelocityIsWorldFrame) {
    const Scene s =
        parse(withBody("  - shape: box\n    half_extents: [1, 0.2, 0.5]\n"
                       "    position: [0, 0, 0]\n    euler_deg: [20, 40, 60]\n"
                       "    angular_velocity: [0.3, -1, 2]\n"));
    const Body& b = s.bodies.at(0);
    EXPECT_LE((b.angularVelocity() - Vec3(0.3, -1, 2)).norm(), 1e-12);
}

TEST(Scene, MassVersusDensity) {
    const std::string base =
        "  - shape: capsule\n    radius: 0.3\n    half_height: 0.5\n"
        "    position: [0, 0, 0]\n";
    const Scene by_density = parse(withBody(base + "    density: 250\n"));
    const Scene by_mass = parse(withBody(base + "    mass: 3\n"));
    const Body& d = by_density.bodies.at(0);
    const Body& m = by_mass.bodies.at(0);
    const Real volume = shapeVolume(d.shape);
    EXPECT_NEAR(d.mass, 250 * volume, 1e-12);
    EXPECT_EQ(m.mass, 3);
    // Same shape: inertia per kilogram is the same.
    EXPECT_LE((d.inertia_body / d.mass - m.inertia_body / m.mass).norm(), 1e-12);

    // Meshes too.
    const std::string mesh =
        "  - shape: mesh\n    file: ../assets/crystal.obj\n"
        "    position: [0, 0, 0]\n";
    const Body md = parse(withBody(mesh + "    density: 2\n")).bodies.at(0);
    const Body mm = parse(withBody(mesh + "    mass: 7\n")).bodies.at(0);
    EXPECT_NEAR(md.mass, 2 * shapeVolume(md.shape), 1e-12);
    EXPECT_EQ(mm.mass, 7);
    EXPECT_LE((md.inertia_body / md.mass - mm.inertia_body / mm.mass).norm(), 1e-12);
}

TEST(Scene, ZeroSizeBoxNeedsAMass) {
    const std::string plate =
        "  - shape: box\n    half_extents: [1, 0, 0.5]\n"
        "    position: [0, 0, 0]\n";
    EXPECT_SCENE_ERROR(withBody(plate), "5:19: bodies[0].half_extents: ", "needs 'mass'");
    const Body b = parse(withBody(plate + "    mass: 2\n")).bodies.at(0);
    EXPECT_EQ(b.mass, 2);
    // Thin plate: I_yy = m/3 (a^2 + c^2); the others are invertible.
    EXPECT_NEAR(b.inertia_body(1, 1), 2.0 / 3 * 1.25, 1e-12);
    EXPECT_TRUE(b.inv_inertia_body.allFinite());
    const Body point = parse(withBody("  - shape: box\n    half_extents: [0, 0, 0]\n"
                                      "    position: [0, 0, 0]\n    mass: 1\n"))
                           .bodies.at(0);
    EXPECT_TRUE(point.inv_inertia_body.allFinite());
}

// --- robustness --------------------------------------------------------------------------------

// Every prefix of a valid scene either parses or throws SceneError: never anything else.
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

TEST(Scene, MakeWorldAddsBodiesInOrderAndDetects) {
    const Scene s =
        parse(withBody("  - name: a\n    shape: sphere\n    radius: 0.5\n"
                       "    position: [0, 0, 0]\n"
                       "  - name: b\n    shape: sphere\n    radius: 0.5\n"
                       "    position: [0.8, 0, 0]\n"
                       "  - name: c\n    shape: box\n    half_extents: [0.5, 0.5, 0.5]\n"
                       "    position: [5, 0, 0]\n"));
    const World w = makeWorld(s);
    ASSERT_EQ(w.bodies().size(), 3u);
    EXPECT_EQ(w.bodies()[0].name, "a");
    EXPECT_EQ(w.bodies()[2].name, "c");
    EXPECT_EQ(w.settings().broad_phase, "sap");
    ASSERT_EQ(w.flaggedPairs().size(), 1u);
    EXPECT_EQ(w.flaggedPairs()[0], (collision::ProxyPair{0, 1}));
}

TEST(SceneRepeat, GeneratesDeterministicBodiesInsideTheRegion) {
    const std::string body =
        "  - name: crate\n"
        "    shape: box\n"
        "    half_extents: [0.2, 0.1, 0.3]\n"
        "    density: 500\n"
        "    repeat: {count: 300, seed: 7, region: {min: [-5, -2, -5], max: [5, 2, 5]},\n"
        "             speed: 3, spin: 2}\n"
        "  - shape: sphere\n"
        "    radius: 0.5\n"
        "    position: [0, 0, 0]\n";
    const Scene a = parse(withBody(body));
    const Scene b = parse(withBody(body));
    ASSERT_EQ(a.bodies.size(), 301u);
    EXPECT_EQ(a.bodies[0].name, "crate_0");
    EXPECT_EQ(a.bodies[299].name, "crate_299");
    EXPECT_EQ(a.bodies[300].name, "sphere1");
    Real max_speed = 0;
    Real max_spin = 0;
    int distinct_orientations = 0;
    for (std::size_t i = 0; i < 300; ++i) {
        const Body& x = a.bodies[i];
        EXPECT_EQ(x.position, b.bodies[i].position);  // same seed, same bodies, bit for bit
        EXPECT_EQ(x.linear_momentum, b.bodies[i].linear_momentum);
        EXPECT_TRUE(x.position.x() >= -5 && x.position.x() <= 5 && x.position.y() >= -2 &&
                    x.position.y() <= 2 && x.position.z() >= -5 && x.position.z() <= 5);
        EXPECT_NEAR(x.mass, 500 * 0.4 * 0.2 * 0.6, 1e-9);
        EXPECT_NEAR(x.orientation.norm(), 1.0, 1e-12);
        max_speed = std::max(max_speed, x.velocity().norm());
        max_spin = std::max(max_spin, x.angularVelocity().norm());
        distinct_orientations += !x.orientation.isApprox(a.bodies[0].orientation);
    }
    EXPECT_LE(max_speed, 3 + 1e-9);
    EXPECT_GT(max_speed, 2.5);  // the speeds really spread over [0, 3]
    EXPECT_LE(max_spin, 2 + 1e-9);
    EXPECT_GT(max_spin, 1.5);
    EXPECT_GT(distinct_orientations, 290);
    // Another seed, other bodies.
    std::string other = body;
    other.replace(other.find("seed: 7"), 7, "seed: 8");
    EXPECT_NE(parse(withBody(other)).bodies[0].position, a.bodies[0].position);
}

// Regression: repeat placed 40 crates in a small box with 5 pairs already colliding at frame 0
// (crowd.yaml started with 98). By default each body is placed apart from every body before it,
// its own entry's and earlier entries' (a static floor here); separated: false keeps the plain
// draw, overlaps and all.
TEST(SceneRepeat, BodiesStartApartUnlessAskedOtherwise) {
    const std::string body =
        "  - {name: floor, shape: box, half_extents: [4, 0.5, 4], position: [0, -1.5, 0], "
        "static: true}\n"
        "  - name: crate\n"
        "    shape: box\n"
        "    half_extents: [0.4, 0.3, 0.2]\n"
        "    repeat: {count: 40, seed: 3, region: {min: [-3, -2, -3], max: [3, 2, 3]}SEP}\n";
    const auto sceneWith = [&](const std::string& sep) {
        std::string text = body;
        text.replace(text.find("SEP"), 3, sep);
        return parse(withBody(text));
    };
    // Crates by their bounding spheres, each crate and the floor by their OBBs.
    const auto overlaps = [](const Scene& s) {
        int n = 0;
        for (std::size_t i = 0; i < s.bodies.size(); ++i) {
            for (std::size_t j = i + 1; j < s.bodies.size(); ++j) {
                const Body& a = s.bodies[i];
                const Body& b = s.bodies[j];
                const collision::Pose pa{a.position, a.orientation};
                const collision::Pose pb{b.position, b.orientation};
                if (i == 0) {
                    n += collision::transformObb(a.local_bounds.obb, pa)
                             .overlaps(collision::transformObb(b.local_bounds.obb, pb));
                    continue;
                }
                const auto sa = collision::transformSphere(a.local_bounds.sphere, pa);
                const auto sb = collision::transformSphere(b.local_bounds.sphere, pb);
                n += (sa.center - sb.center).norm() <= sa.radius + sb.radius;
            }
        }
        return n;
    };
    const Scene apart = sceneWith("");
    const Scene drawn = sceneWith(", separated: false");
    ASSERT_EQ(apart.bodies.size(), 41u);
    EXPECT_EQ(overlaps(apart), 0);
    EXPECT_GT(overlaps(drawn), 0);
    EXPECT_EQ(makeWorld(apart).collidingPairs().size(), 0u);
    // The same seed without separation: the draw this scene is a test of really overlaps.
    EXPECT_GT(makeWorld(drawn).collidingPairs().size(), 0u);
    EXPECT_EQ(sceneWith(", separated: true").bodies[7].position, apart.bodies[7].position);
    EXPECT_EQ(sceneWith("").bodies[20].position, apart.bodies[20].position);  // deterministic
    // Asking for more than random placement can keep apart fails at the repeat key at once, and
    // a crowded region that runs out of tries says what to change.
    EXPECT_SCENE_ERROR(
        withBody("  - shape: sphere\n    radius: 0.5\n"
                 "    repeat: {count: 900, region: {min: [-2, -2, -2], max: [2, 2, 2]}}\n"),
        "6:13: bodies[0].repeat: ", "randomly placed spheres stay apart only below");
    EXPECT_SCENE_ERROR(
        withBody("  - shape: sphere\n    radius: 0.5\n"
                 "    repeat: {count: 10, region: {min: [0, 0, 0], max: [0, 0, 0]}}\n"),
        "6:13: bodies[0].repeat: ", "or set separated: false");
}

TEST(SceneRepeat, ErrorsNameTheKey) {
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 0.5\n    position: [0, 0, 0]\n"
                                "    repeat: {count: 3}\n"),
                       "6:5: bodies[0].position: ", "does not apply with 'repeat'");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 0.5\n    repeat: {count: 0}\n"),
                       "6:21: bodies[0].repeat.count: ", "must be in 1..1000000");
    EXPECT_SCENE_ERROR(
        withBody("  - shape: sphere\n    radius: 0.5\n"
                 "    repeat: {count: 2, region: {min: [0, 0, 0], max: [99, 1, 1]}}\n"),
        "6:32: bodies[0].repeat.region: ", "inside the world bounds");
    EXPECT_SCENE_ERROR(withBody("  - shape: sphere\n    radius: 0.5\n    repeat: {cont: 2}\n"),
                       "6:14: bodies[0].repeat.cont: ", "unknown key 'cont'");
}

// Regression: finite but absurd magnitudes passed the loader and became NaN in the first step
// (velocity, angular velocity or gravity of 1e308), and steps_per_frame 2147483647 never finished
// a frame. Each is refused at its line and column with the limit it broke.
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
TEST_F(SceneMeshes, AFlatMeshIsRefusedAsHavingNoVolume) {
    write("tri.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    write("square.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
    auto errorIn = [&](const std::string& file, const char* shape) -> std::string {
        write("scene.yaml",
              "world:\n  bounds: {min: [-5, -5, -5], max: [5, 5, 5]}\nbodies:\n"
              "  - {shape: " +
                  std::string(shape) + ", file: " + file + ", position: [0, 0, 0]}\n");
        try {
            loadScene(dir_ / "scene.yaml");
        } catch (const SceneError& e) {
            return e.what();
        }
        return "";
    };
    for (const char* shape : {"hull", "mesh"}) {
        SCOPED_TRACE(shape);
        std::string err = errorIn("tri.off", shape);
        EXPECT_NE(err.find(":4:"), std::string::npos) << err;
        EXPECT_NE(err.find(": bodies[0].file: "), std::string::npos) << err;
        EXPECT_NE(err.find("has no volume: its points lie in one plane (3 vertices, 1 triangle)"),
                  std::string::npos)
            << err;
        err = errorIn("square.off", shape);
        EXPECT_NE(err.find("has no volume: its points lie in one plane (4 vertices, 2 triangles)"),
                  std::string::npos)
            << err;
    }
}

}  // namespace
}  // namespace engine
