// tests/engine/deformation_test.cpp -- prescribed deformation of a mesh body: the closed forms
// (bend, twist, wave), the world moving the vertices and refitting the body's hierarchy every
// step (self pairs equal to the brute force on the deformed mesh, volumes containing it), the
// rebuild rule, and the scene keys' errors.
#include "engine/deformation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "collision/bvh/bvh.h"
#include "collision/geometry/convex_hull.h"
#include "collision/narrowphase/narrow_phase.h"
#include "engine/scene.h"
#include "engine/world.h"
#include "scene_error.h"

namespace engine {
namespace {

namespace fs = std::filesystem;
using collision::kPi;

TEST(Deformation, ClosedForms) {
    // Bend at full strength (t = 1 / (2 f)): the x axis becomes the circle of radius 1 / k
    // through the origin centred at (0, 1 / k); arc length pi / k reaches the top.
    const Deformation bend{DeformKind::Bend, 2.0, 0.25, 1};
    const Real full = 2.0;  // 1 / (2 f)
    const Vec3 top = deformPoint(bend, Vec3(kPi / 2, 0, 0.3), full);
    EXPECT_NEAR(top.x(), 0, 1e-12);
    EXPECT_NEAR(top.y(), 1.0, 1e-12);
    EXPECT_EQ(top.z(), 0.3);
    const Vec3 inner = deformPoint(bend, Vec3(0.4, 0.1, 0), full);  // 0.1 towards the centre
    EXPECT_NEAR((inner - Vec3(0, 0.5, 0)).norm(), 0.4, 1e-12);
    // Rest shape at t = 0 (and every period).
    EXPECT_EQ(deformPoint(bend, Vec3(1, 2, 3), 0), Vec3(1, 2, 3));
    // A tiny curvature bends by about x^2 k / 2, without cancellation.
    const Deformation slight{DeformKind::Bend, 1e-9, 0.25, 1};
    const Vec3 p = deformPoint(slight, Vec3(2, 0, 0), full);
    EXPECT_NEAR(p.y(), 2e-9, 1e-20);
    EXPECT_NEAR(p.x(), 2, 1e-15);
    // Twist: the section at x turns by amount x about x.
    const Deformation twist{DeformKind::Twist, kPi / 2, 0.25, 1};
    const Vec3 q = deformPoint(twist, Vec3(1, 1, 0), full);
    EXPECT_NEAR(q.y(), 0, 1e-12);
    EXPECT_NEAR(q.z(), 1, 1e-12);
    // Wave: y + amount sin(2 pi (x / wavelength - f t)).
    const Deformation wave{DeformKind::Wave, 0.1, 0.5, 2};
    EXPECT_NEAR(deformPoint(wave, Vec3(0.5, 1, 0), 0).y(), 1.1, 1e-12);
    EXPECT_NEAR(deformPoint(wave, Vec3(0.5, 1, 0), 0.5).y(), 1.0, 1e-12);
}

Scene deformScene() { return loadScene(fs::path(CDLAB_SOURCE_DIR) / "scenes/deform_self.yaml"); }

TEST(Deformation, WorldRefitsAndSelfPairsFollowTheDeformedMesh) {
    const Scene scene = deformScene();
    World world = makeWorld(scene);
    const Body& strip = world.bodies()[0];
    ASSERT_TRUE(strip.deform.has_value());
    const std::vector<Vec3> rest = strip.shape.mesh->vertices;
    int with_pairs = 0;
    int without_pairs = 0;
    for (int step = 1; step <= 240; ++step) {
        world.step();
        const Body& b = world.bodies()[0];
        EXPECT_GT(world.lastStats().refit_nodes, 0);
        // Every 8th step: the full checks.
        if (step % 8 != 0) continue;
        for (std::size_t k = 0; k < rest.size(); k += 37) {
            EXPECT_EQ(b.shape.mesh->vertices[k], deformPoint(*b.deform, rest[k], world.time()));
        }
        std::string error;
        EXPECT_TRUE(b.shape.bvh->validate(&error)) << "step " << step << ": " << error;
        const std::vector<collision::TrianglePair> brute =
            collision::intersectSelfBruteForce(*b.shape.mesh);
        const std::span<const collision::TrianglePair> got = world.selfPairs(0);
        EXPECT_EQ(std::vector<collision::TrianglePair>(got.begin(), got.end()), brute)
            << "step " << step;
        (brute.empty() ? without_pairs : with_pairs) += 1;
    }
    // The strip curls through itself and back: both outcomes.
    EXPECT_GT(with_pairs, 0);
    EXPECT_GT(without_pairs, 0);
    // The scene file the other bodies share was not touched: a fresh load is at rest.
    EXPECT_EQ(makeWorld(scene).bodies()[0].shape.mesh->vertices, rest);
}

TEST(Deformation, RebuildRuleChangesTheTreeNotTheAnswer) {
    Scene always = deformScene();
    always.world.rebuild_ratio = 0;  // every step: the refitted ratio exceeds 0
    Scene never = deformScene();
    never.world.rebuild_ratio = 1e30;
    World a = makeWorld(always);
    World b = makeWorld(never);
    std::int64_t rebuilds_a = 0;
    std::int64_t rebuilds_b = 0;
    for (int step = 0; step < 80; ++step) {
        a.step();
        b.step();
        rebuilds_a += a.lastStats().rebuilds;
        rebuilds_b += b.lastStats().rebuilds;
        const auto pa = a.selfPairs(0);
        const auto pb = b.selfPairs(0);
        ASSERT_EQ(std::vector<collision::TrianglePair>(pa.begin(), pa.end()),
                  std::vector<collision::TrianglePair>(pb.begin(), pb.end()))
            << "step " << step;
        EXPECT_EQ(a.collidingPairs().size(), b.collidingPairs().size());
    }
    EXPECT_EQ(rebuilds_a, 80);
    EXPECT_EQ(rebuilds_b, 0);
}

// deformSpeedBound bounds the speed of every vertex at every time (central differences over a
// period at random times), and is reached to within a few per cent by some vertex and time (a
// bound far above the true speed would stop continuous collision detection needlessly early).
TEST(Deformation, SpeedBoundHoldsAndIsNearlyReached) {
    const Scene scene = deformScene();
    const std::vector<Vec3>& rest = scene.bodies[0].shape.mesh->vertices;
    for (const Deformation& d :
         {Deformation{DeformKind::Bend, 2.2, 0.25, 1}, Deformation{DeformKind::Twist, 1.5, 0.5, 1},
          Deformation{DeformKind::Wave, 0.3, 2.0, 3}}) {
        SCOPED_TRACE(std::string(deformKindName(d.kind)));
        const Real bound = deformSpeedBound(d, rest);
        ASSERT_GT(bound, 0);
        const Real period = 1 / d.frequency;
        const Real h = 1e-6 * period;
        Real fastest = 0;
        for (int k = 0; k < 400; ++k) {
            const Real t = period * (Real(k) + Real(0.5)) / 400;
            for (const Vec3& v : rest) {
                const Real speed =
                    (deformPoint(d, v, t + h) - deformPoint(d, v, t - h)).norm() / (2 * h);
                EXPECT_LE(speed, bound * (1 + 1e-6)) << "t " << t;
                fastest = std::max(fastest, speed);
            }
        }
        EXPECT_GT(fastest, 0.85 * bound);
    }
}

// A wavy strip rises at 0.3 m/s under a static ball while a long travelling wave lifts its tip
// at up to 3.1 m/s in its own frame, with ccd on. Every step that starts apart keeps the strip's
// true surface (its convex hull, deformed at each sampled time and placed on its sweep, which
// is what the continuous stage stands the mesh for) out of the ball at every sampled time up to
// the step's stop, checked by collide(). Without the deformation's term in the motion bound the
// stage sees only the 2.5 mm a step of rigid motion and lets the rising tip into the ball.
//
//         ( ball )
//   ____/~~ tip rises 26 mm a step
//   strip ^ 0.3 m/s
TEST(Deformation, ContinuousStageIsConservativeForADeformingBody) {
    const std::string text =
        "world:\n"
        "  bounds: {min: [-10, -10, -10], max: [10, 10, 10]}\n"
        "  gravity: [0, 0, 0]\n"
        "  time_step: 0.008333333333333333\n"
        "  ccd: conservative_advancement\n"
        "bodies:\n"
        "  - {name: strip, shape: mesh, file: ../assets/wavy_strip.obj, position: [0, 0, 0],\n"
        "     velocity: [0, 0.3, 0], deform: {kind: wave, amount: 0.5, frequency: 1,\n"
        "     wavelength: 16}}\n"
        "  - {name: ball, shape: sphere, radius: 0.25, position: [1.8, 1.0, 0], static: true}\n";
    const Scene scene = parseScene(text, "test.yaml", fs::path(CDLAB_SOURCE_DIR) / "scenes");
    const std::vector<Vec3> rest = scene.bodies[0].shape.mesh->vertices;
    World world = makeWorld(scene);
    const Deformation deform = *world.bodies()[0].deform;
    const collision::Shape ball = world.bodies()[1].shape;
    const Pose ball_pose = world.bodies()[1].pose();
    const Real dt = world.settings().time_step;

    int samples = 0;
    Real closest = 1;  // smallest gap seen at a sample, m
    bool stopped = false;
    for (int step = 0; step < 240 && !stopped; ++step) {
        const Body& strip = world.bodies()[0];
        ASSERT_EQ(strip.orientation.coeffs(), Quat::Identity().coeffs()) << "step " << step;
        const Vec3 p0 = strip.position;
        const Vec3 v0 = strip.velocity();
        const Real t0 = world.time();
        world.step();
        // Pure translation until the first stop: the stop time from the displacement.
        const Vec3 moved = world.bodies()[0].position - p0;
        const Real tau = moved.dot(v0) / (v0.squaredNorm() * dt);
        stopped = tau < 1 - 1e-12;
        for (int k = 0; k <= 16; ++k) {
            const Real s = tau * Real(k) / 16;
            std::vector<Vec3> vertices;
            for (const Vec3& v : rest) vertices.push_back(deformPoint(deform, v, t0 + s * dt));
            collision::ConvexHullOutput hull = collision::computeConvexHull(vertices);
            ASSERT_TRUE(hull.ok) << hull.error;
            const collision::Shape surface = collision::Shape::convexHull(
                std::make_shared<const collision::ConvexPolytope>(std::move(hull.hull)));
            Pose pose;
            pose.position = p0 + s * dt * v0;
            const collision::CollideOutput c = collision::collide(surface, pose, ball, ball_pose);
            ASSERT_NE(c.state, collision::ContactState::Penetrating)
                << "step " << step << " at " << s << " of the step (stop at " << tau << ")";
            if (c.state == collision::ContactState::Separated)
                closest = std::min(closest, c.distance);
            ++samples;
        }
    }
    // The strip was stopped, having come closer to the ball than its surface may move in a step.
    EXPECT_TRUE(stopped);
    EXPECT_LT(closest, deformSpeedBound(deform, rest) * dt);
    EXPECT_GT(samples, 16 * 20);
}

TEST(Deformation, SceneKeysRejectBadValues) {
    const std::string head =
        "world: {bounds: {min: [-5, -5, -5], max: [5, 5, 5]}}\n"
        "bodies:\n";
    EXPECT_SCENE_ERROR(head +
                           "  - {shape: sphere, radius: 1, position: [0, 0, 0], deform: "
                           "{kind: bend, amount: 1, frequency: 1}}\n",
                       "3:53: bodies[0].deform: ", "applies to mesh bodies only");
    const std::string mesh =
        "  - {shape: mesh, file: ../assets/wavy_strip.obj, position: [0, 0, "
        "0], deform: ";
    EXPECT_SCENE_ERROR(head + mesh + "{kind: melt, amount: 1, frequency: 1}}\n",
                       "3:87: bodies[0].deform.kind: ", "unknown deformation 'melt'");
    EXPECT_SCENE_ERROR(head + mesh + "{kind: bend, amount: 1, frequency: 0}}\n",
                       "3:115: bodies[0].deform.frequency: ", "must be in (0, 1000]");
    EXPECT_SCENE_ERROR(head + mesh + "{kind: bend, amount: 1, frequency: 1, wavelength: 2}}\n",
                       "3:118: bodies[0].deform.wavelength: ", "applies to kind: wave only");
    EXPECT_SCENE_ERROR(head + mesh + "{kind: wave, frequency: 1}}\n",
                       "3:80: bodies[0].deform.amount: ", "required key is missing");
}

}  // namespace
}  // namespace engine
