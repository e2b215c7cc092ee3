// tests/engine/deformation_test.cpp -- prescribed deformation of a mesh body: the closed forms
// (bend, twist, wave), the world moving the vertices and refitting the body's hierarchy every
// step (self pairs equal to the brute force on the deformed mesh, volumes containing it), the
// rebuild rule, and the scene keys' errors.
#include "engine/deformation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "collision/bvh/bvh.h"
#include "engine/scene.h"
#include "engine/world.h"
#include "scene_error.h"

namespace engine {
namespace {

namespace fs = std::filesystem;
constexpr Real kPi = std::numbers::pi_v<Real>;

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
