// tests/engine/ccd_policy_test.cpp -- the engine's continuous stage on the shipped tunnelling
// scenes: with ccd off the fast sphere and the spinning bar pass through their static plate /
// wall, with conservative advancement they never do; the first time of impact matches the
// closed form; elastic resolution keeps the speed; runs are bit-identical; ccd off does no
// CCD work at all. With three bodies: the first of two plates stops a fast sphere, and a body
// stopped early gets no impulse from its later impacts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/scene.h"
#include "engine/world.h"
#include "shipped_scenes.h"

namespace engine {
namespace {

using cdlab_test::kScenes;

World loadWorld(const std::string& file) { return makeWorld(loadScene(kScenes / file)); }

// Largest world x of a capsule body: its segment's end points plus the radius.
Real maxCapsuleX(const Body& b) {
    const Vec3 top = b.pose().apply(Vec3(0, b.shape.half_height, 0));
    const Vec3 bottom = b.pose().apply(Vec3(0, -b.shape.half_height, 0));
    return std::max(top.x(), bottom.x()) + b.shape.radius;
}

TEST(CcdPolicy, ScenesSelectTheMethod) {
    EXPECT_EQ(loadScene(kScenes / "tunnel_sphere.yaml").world.ccd, CcdMethod::Off);
    EXPECT_EQ(loadScene(kScenes / "tunnel_sphere_ccd.yaml").world.ccd,
              CcdMethod::ConservativeAdvancement);
    EXPECT_EQ(loadScene(kScenes / "tunnel_bar.yaml").world.ccd, CcdMethod::Off);
    EXPECT_EQ(loadScene(kScenes / "tunnel_bar_ccd.yaml").world.ccd,
              CcdMethod::ConservativeAdvancement);
    const Scene s = loadScene(kScenes / "tunnel_sphere.yaml");
    ASSERT_EQ(s.bodies.size(), 2u);
    EXPECT_TRUE(s.bodies[0].is_static);
    EXPECT_EQ(s.bodies[0].inv_mass, 0);
    EXPECT_FALSE(s.bodies[1].is_static);
}

TEST(CcdPolicy, FastSphereTunnelsThroughThePlateWithCcdOff) {
    World world = loadWorld("tunnel_sphere.yaml");
    bool passed = false;
    for (int i = 0; i < 90 && !passed; ++i) {
        world.step();
        EXPECT_EQ(world.lastStats().toi_queries, 0);  // the stage never runs
        EXPECT_TRUE(world.toiEvents().empty());
        passed = world.bodies()[1].position.x() - 0.05 > 0.005;
    }
    EXPECT_TRUE(passed);
}

TEST(CcdPolicy, FastSphereNeverPassesThePlateWithConservativeAdvancement) {
    World world = loadWorld("tunnel_sphere_ccd.yaml");
    const Real speed = world.bodies()[1].velocity().norm();
    ASSERT_EQ(speed, 1000);
    int hits = 0;
    bool first = true;
    for (int i = 0; i < 300; ++i) {
        world.step();
        const Body& ball = world.bodies()[1];
        // The sphere's surface never crosses the plate's face at x = -0.005.
        ASSERT_LT(ball.position.x() + 0.05, -0.005) << "step " << i;
        hits += static_cast<int>(world.toiEvents().size());
        if (first && !world.toiEvents().empty()) {
            first = false;
            // From x = -20 at 1000/30 m per step: contact when the centre reaches -0.055; the
            // stage stops 1e-3 * 0.05 m (target gap) to 2e-3 * 0.05 m (plus tolerance) before.
            const ToiEvent& e = world.toiEvents()[0];
            const Real exact = (20 - 0.055) / (1000.0 / 30);
            EXPECT_EQ(i, 0);
            EXPECT_LT(e.t, exact);
            EXPECT_GT(e.t, exact - 2.5e-4 / (1000.0 / 30));
            EXPECT_NEAR(e.pose_b.position.x(), -0.055, 1.5e-4);
            EXPECT_NEAR(e.normal.x(), -1, 1e-12);  // from the plate (a) to the ball (b)
        }
        // Elastic, frictionless: the speed is kept.
        EXPECT_NEAR(ball.velocity().norm(), speed, 1e-9 * speed);
    }
    // Back and forth between the plate and the -x bound: it keeps coming back.
    EXPECT_GE(hits, 5);
    RecordProperty("plate_hits", hits);
}

TEST(CcdPolicy, SpinningBarTunnelsThroughTheWallWithCcdOff) {
    World world = loadWorld("tunnel_bar.yaml");
    bool passed = false;
    for (int i = 0; i < 150 && !passed; ++i) {
        world.step();
        passed = world.bodies()[1].position.x() > 1.0;  // centre a bar's half length past
    }
    EXPECT_TRUE(passed);
}

TEST(CcdPolicy, SpinningBarNeverPassesTheWallWithConservativeAdvancement) {
    World world = loadWorld("tunnel_bar_ccd.yaml");
    int hits = 0;
    for (int i = 0; i < 600; ++i) {
        world.step();
        const Body& bar = world.bodies()[1];
        // No point of the bar ever reaches the wall's face at x = -0.01.
        ASSERT_LT(maxCapsuleX(bar), -0.01) << "step " << i;
        hits += static_cast<int>(world.toiEvents().size());
        for (const ToiEvent& e : world.toiEvents()) EXPECT_FALSE(e.failed);
    }
    EXPECT_GE(hits, 2);
    RecordProperty("wall_hits", hits);
}

// world.ccd_tolerance and world.ccd_target_gap reach the stage: the spinning bar's first stop
// (closed form 0.0721186 s, see tunnel_bar_ccd.yaml) comes earlier with a looser tolerance or a
// larger target gap, never after first contact; the defaults reproduce the scene as shipped.
TEST(CcdPolicy, ToleranceAndTargetGapMoveTheFirstStopEarlier) {
    const Real exact = 0.0721186;  // s, by bisection (6 digits)
    auto firstStop = [](const std::vector<SceneOverride>& overrides) {
        World world = makeWorld(loadScene(kScenes / "tunnel_bar_ccd.yaml", overrides));
        for (int i = 0; i < 10; ++i) {
            world.step();
            if (!world.toiEvents().empty()) {
                EXPECT_FALSE(world.toiEvents()[0].failed);
                return world.settings().time_step * (i + world.toiEvents()[0].t);
            }
        }
        ADD_FAILURE() << "no stop in 10 steps";
        return Real(0);
    };
    const Real shipped = firstStop({});
    EXPECT_EQ(firstStop({{"world.ccd_tolerance", "0.001"}, {"world.ccd_target_gap", "0.001"}}),
              shipped);
    const Real tight = firstStop({{"world.ccd_tolerance", "1e-6"}});
    const Real loose = firstStop({{"world.ccd_tolerance", "0.1"}});
    const Real far = firstStop({{"world.ccd_target_gap", "0.1"}});
    RecordProperty("first_stop_tight", std::to_string(tight));
    RecordProperty("first_stop_shipped", std::to_string(shipped));
    RecordProperty("first_stop_loose", std::to_string(loose));
    RecordProperty("first_stop_far", std::to_string(far));
    // Never later than first contact (5e-7 s: the 6 digits of the closed form).
    EXPECT_LE(tight, exact + 5e-7);
    EXPECT_LE(shipped, tight);
    EXPECT_LT(loose, shipped);
    EXPECT_LT(far, shipped);
    // And earlier by no more than the gap left over the slowest closing speed: every point of
    // the bar moves towards the wall at >= 75 - 30 * 1 = 45 m/s, and the stop leaves at most
    // (0.1 + 0.001) of the bar's bounding radius (1 m), so it is at most 0.101 / 45 s early.
    EXPECT_GE(loose, exact - 0.101 / 45 - 5e-7);
    EXPECT_GE(far, exact - 0.101 / 45 - 5e-7);
}

// More than two bodies: the 5 cm sphere at 1000 m/s (33 m per step) sweeps through two 1 cm
// plates, 0.5 m apart, within one step. The earliest time of impact is the first plate's, so
// the sphere must stop there and bounce back; it must never reach either plate.
//
//      -20 m         x = 0     x = 0.5
//   ball o -->        |         |
//                  plate 1   plate 2
// Both orders of insertion (the first plate added before or after the second) are run, so the
// outcome does not hinge on body ids.
TEST(CcdPolicy, FastSphereStopsAtTheFirstOfTwoPlates) {
    for (const bool near_first : {true, false}) {
        Scene scene = loadScene(kScenes / "tunnel_sphere_ccd.yaml");
        ASSERT_EQ(scene.bodies.size(), 2u);
        Body near_plate = scene.bodies[0];
        Body far_plate = scene.bodies[0];
        far_plate.name = "plate2";
        far_plate.position.x() = 0.5;
        const Body ball = scene.bodies[1];
        scene.bodies = near_first ? std::vector<Body>{near_plate, far_plate, ball}
                                  : std::vector<Body>{far_plate, near_plate, ball};
        const BodyId near_id = near_first ? 0 : 1;
        World world = makeWorld(scene);
        const Real speed = world.bodies()[2].velocity().norm();
        ASSERT_EQ(speed, 1000);
        int hits = 0;
        for (int i = 0; i < 300; ++i) {
            world.step();
            const Body& b = world.bodies()[2];
            // The sphere's surface never crosses the first plate's face at x = -0.005.
            ASSERT_LT(b.position.x() + 0.05, -0.005)
                << "step " << i << " near_first " << near_first;
            if (!world.toiEvents().empty()) {
                // The earliest event of the step is with the first plate.
                const ToiEvent& e = world.toiEvents()[0];
                EXPECT_EQ(e.a, near_id) << "step " << i;
                EXPECT_EQ(e.b, 2) << "step " << i;
                ++hits;
            }
            EXPECT_NEAR(b.velocity().norm(), speed, 1e-9 * speed) << "step " << i;
        }
        EXPECT_GE(hits, 5) << near_first;
    }
}

// A body the stage stopped at an early time of impact is not at its later ones: they must not
// push it. Regression: the impulse loop took an event as "the earliest for one of its bodies"
// when it was the earliest for the *static* body, whose stop time is just its own event's. The
// ball (5 cm, 600 m/s along x and y, 20 m per step each) is stopped at the wall at t = 0.497 of
// the step; its straight sweep also meets the ceiling, which lies past the wall, at t = 0.747,
// 5 m away from where it stopped. That event still got an elastic impulse with a 5 m lever arm:
// -240 rad/s of spin about z and v_y 600 -> 599.952 m/s from a ceiling it never touched.
//
//            ceiling (y = 5, x in [0.5, 20.5])
//     |    ==========
//     |   /
//     |  /  (straight sweep, cut at the wall)
//     | /
//   wall x = 0
//    o ball from (-10, -10)
TEST(CcdPolicy, StoppedBodyGetsNoImpulseFromALaterImpactWithAStaticBody) {
    WorldSettings settings;
    settings.bounds = collision::Aabb{Vec3::Constant(-60), Vec3::Constant(60)};
    settings.time_step = Real(1) / 30;
    settings.ccd = CcdMethod::ConservativeAdvancement;
    MassProperties slab_mass;
    slab_mass.mass = 1;
    Body wall = makeBody("wall", collision::Shape::box(Vec3(0.005, 40, 40)), slab_mass);
    setStatic(wall);
    Body ceiling = makeBody("ceiling", collision::Shape::box(Vec3(10, 0.005, 10)), slab_mass);
    ceiling.position = Vec3(10.5, 5, 0);
    setStatic(ceiling);
    MassProperties ball_mass;
    ball_mass.mass = 4;
    ball_mass.inertia = Mat3::Identity() * (Real(0.4) * 4 * 0.05 * 0.05);
    Body ball = makeBody("ball", collision::Shape::sphere(0.05), ball_mass);
    ball.position = Vec3(-10, -10, 0);
    ball.linear_momentum = ball.mass * Vec3(600, 600, 0);
    World world(settings);
    world.addBody(wall);
    world.addBody(ceiling);
    world.addBody(ball);
    world.detect();
    world.step();
    ASSERT_EQ(world.toiEvents().size(), 2u);
    EXPECT_EQ(world.toiEvents()[0].a, 0);  // the wall first
    EXPECT_EQ(world.toiEvents()[1].a, 1);  // the ceiling later, on the uncut sweep
    const Body& b = world.bodies()[2];
    EXPECT_NEAR(b.position.x(), -0.055, 1e-3);  // stopped at the wall
    // Only the wall's impulse: v_x reversed, v_y and the (zero) spin untouched.
    EXPECT_NEAR(b.velocity().x(), -600, 1e-9 * 600);
    EXPECT_NEAR(b.velocity().y(), 600, 1e-9 * 600);
    EXPECT_LE(b.angularVelocity().norm() * 0.05, 1e-9 * 600);
}

TEST(CcdPolicy, RunsAreBitIdentical) {
    for (const char* file : {"tunnel_sphere_ccd.yaml", "tunnel_bar_ccd.yaml"}) {
        World a = loadWorld(file);
        World b = loadWorld(file);
        for (int i = 0; i < 200; ++i) {
            a.step();
            b.step();
        }
        EXPECT_EQ(a.stateHash(), b.stateHash()) << file;
    }
    // And the stage changes the outcome: the same bar without CCD ends elsewhere.
    World on = loadWorld("tunnel_bar_ccd.yaml");
    World off = loadWorld("tunnel_bar.yaml");
    for (int i = 0; i < 50; ++i) {
        on.step();
        off.step();
    }
    EXPECT_NE(on.stateHash(), off.stateHash());
}

// Sphere pairs with world.ccd_spheres: exact take the closed-form root: scenes/ccd_spheres.yaml
// (two 5 cm bullets head-on at 600 m/s each, first contact at (60 - 0.1) / 1200 s) never lets
// the bullets pass each other, stops them within the target gap of the analytic contact, never
// after it,
// with one iteration per query (the advancement lands on the same root here, pure translation,
// after more distance queries).
TEST(CcdPolicy, ExactSphereRootStopsHeadOnBulletsAtTheAnalyticContact) {
    const Real contact_s = 59.9 / 1200;
    struct Run {
        Real first_toi_s = -1;
        std::int64_t queries = 0;
        std::int64_t iterations = 0;
    };
    auto run = [&](CcdSpheres method) {
        Scene scene = loadScene(kScenes / "ccd_spheres.yaml");
        scene.world.ccd_spheres = method;
        World world = makeWorld(scene);
        Run r;
        for (int i = 0; i < 60; ++i) {
            const Real t0 = world.time();
            world.step();
            const Body& left = world.bodies()[0];
            const Body& right = world.bodies()[1];
            EXPECT_LT(left.position.x() + 0.05, right.position.x() - 0.05) << "step " << i;
            r.queries += world.lastStats().toi_queries;
            r.iterations += world.lastStats().toi_iterations;
            for (const ToiEvent& e : world.toiEvents()) {
                if (r.first_toi_s < 0 && e.a == 0 && e.b == 1) {
                    r.first_toi_s = t0 + e.t * scene.world.time_step;
                }
            }
        }
        return r;
    };
    const Run exact = run(CcdSpheres::Exact);
    const Run advance = run(CcdSpheres::Advancement);
    ASSERT_GT(exact.first_toi_s, 0);
    ASSERT_GT(advance.first_toi_s, 0);
    EXPECT_LE(exact.first_toi_s, contact_s);
    // The target gap, 1e-3 of 5 cm at 1200 m/s of closing: 4.2e-8 s early.
    EXPECT_NEAR(exact.first_toi_s, contact_s - 0.05e-3 / 1200, 1e-12);
    // Pure translation head-on: the advancement's first step lands on the same root (to
    // rounding); it needs more than one distance query to know it.
    EXPECT_NEAR(advance.first_toi_s, exact.first_toi_s, 1e-12);
    EXPECT_EQ(exact.iterations, exact.queries);
    EXPECT_GT(advance.iterations, advance.queries)
        << advance.iterations << " " << advance.queries << " " << exact.queries;
}

TEST(CcdPolicy, SceneErrors) {
    const std::string head = "world:\n  bounds: {min: [0,0,0], max: [1,1,1]}\n";
    try {
        parseScene(head + "  ccd: always\n", "t.yaml", ".");
        FAIL() << "accepted an unknown ccd method";
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "t.yaml:3:8: world.ccd: unknown ccd method 'always' (expected one of: off, "
                  "conservative_advancement)");
    }
    try {
        parseScene(head +
                       "bodies:\n  - shape: sphere\n    radius: 0.1\n    position: [0.5, 0.5, "
                       "0.5]\n    static: true\n    velocity: [1, 0, 0]\n",
                   "t.yaml", ".");
        FAIL() << "accepted a moving static body";
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "t.yaml:8:5: bodies[0].velocity: a static body does not move");
    }
    try {
        parseScene(head + "  ccd_spheres: analytic\n", "t.yaml", ".");
        FAIL() << "accepted an unknown ccd_spheres";
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "t.yaml:3:16: world.ccd_spheres: unknown ccd_spheres 'analytic' (expected one "
                  "of: advancement, exact)");
    }
}

// Mesh-mesh pairs run the continuous stage on their surfaces (timeOfImpactMeshes on the OBB
// trees), not on their convex hulls. tests/data/ring_rod_ccd.yaml:
//
//      ring (axis y, 300 m/s up)   ( O )  -> passes around the bead in its hole
//      bead on the tube (x = 1)    ( o)   -> the ring is stopped at the bead
//
TEST(CcdPolicy, MeshRingPassesAroundABeadInItsHoleButStopsAtOneOnItsTube) {
    const std::filesystem::path file =
        std::filesystem::path(CDLAB_SOURCE_DIR) / "tests" / "data" / "ring_rod_ccd.yaml";
    {
        World world = makeWorld(loadScene(file));
        ASSERT_EQ(world.bodies()[0].shape.type, collision::ShapeType::Mesh);
        world.step();
        EXPECT_GT(world.lastStats().toi_queries, 0);  // the pair was asked
        EXPECT_TRUE(world.toiEvents().empty());
        EXPECT_NEAR(world.bodies()[0].position.y(), 5, 1e-9);  // a whole step: through the hole
    }
    {
        Scene scene = loadScene(file);
        scene.bodies[1].position = Vec3(1, 0, 0);
        World world = makeWorld(scene);
        world.step();
        ASSERT_EQ(world.toiEvents().size(), 1u);
        // Contact when the tube's top (ring y + 0.35) meets the bead's bottom (-0.07), at ring
        // y = -0.42 for the smooth shapes; the faceted meshes (12 segments around the tube) meet
        // up to ~0.015 later. Stopped a target gap short, never past it.
        const Real y = world.bodies()[0].position.y();
        EXPECT_LT(y, -0.42 + 0.015);
        EXPECT_GT(y, -0.42 - 0.01);
        const ToiEvent& e = world.toiEvents()[0];
        EXPECT_NEAR(e.point.x(), 1, 0.05);  // at the bead
        EXPECT_GT(e.normal.y(), 0.9);       // from the ring (a) up to the bead (b)
    }
}

}  // namespace
}  // namespace engine
