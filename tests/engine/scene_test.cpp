// tests/engine/scene_test.cpp -- scene files that load: a full round trip, defaults, settings
// reaching the World, orientation conventions, mass vs density, repeat placement, makeWorld.
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
using collision::kPi;

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

TEST(SceneDraw, VolumesAcceptKdopsBesideTheBodyVolumes) {
    const Scene s = parse(kValid + "draw: {volumes: [kdop26, aabb, kdop6]}\n");
    EXPECT_TRUE(s.draw.volumes_given);
    EXPECT_FALSE(s.draw.sphere);
    EXPECT_TRUE(s.draw.aabb);
    EXPECT_EQ(s.draw.kdop, (std::array<bool, 4>{true, false, false, true}));
    EXPECT_EQ(parse(kValid).draw.kdop, (std::array<bool, 4>{}));
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

TEST(Scene, RebuildRatioReachesTheWorld) {
    EXPECT_EQ(parse(kValid).world.rebuild_ratio, Real(1.5));
    const Scene s = parse(
        "world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n  rebuild_ratio: 2.25\nbodies:\n"
        "  - {shape: sphere, radius: 0.25, position: [0.5, 0.5, 0.5]}\n");
    EXPECT_EQ(s.world.rebuild_ratio, Real(2.25));
    EXPECT_EQ(makeWorld(s).settings().rebuild_ratio, Real(2.25));
}

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

}  // namespace
}  // namespace engine
