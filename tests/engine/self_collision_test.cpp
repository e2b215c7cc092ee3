// tests/engine/self_collision_test.cpp -- `self_collision: true` on a mesh body: the world lists
// the body's own intersecting triangle pairs each step (the brute-force loop's list), counts
// them in its step stats, and the scene keys reject misuse at their line:col.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "collision/bvh/bvh.h"
#include "engine/scene.h"
#include "engine/world.h"
#include "scene_error.h"

namespace engine {
namespace {

namespace fs = std::filesystem;

TEST(SelfCollision, ShippedSceneListsTheBruteForcePairsEveryStep) {
    const Scene scene = loadScene(fs::path(CDLAB_SOURCE_DIR) / "scenes/self_collision.yaml");
    World world = makeWorld(scene);
    ASSERT_EQ(world.bodies().size(), 2u);
    const std::vector<collision::TrianglePair> ribbon =
        collision::intersectSelfBruteForce(*world.bodies()[0].shape.mesh);
    ASSERT_FALSE(ribbon.empty());
    for (int step = 0; step < 5; ++step) {
        // Rigid motion leaves the pairs of the body's own (local-frame) triangles unchanged.
        const std::span<const collision::TrianglePair> got = world.selfPairs(0);
        EXPECT_EQ(std::vector<collision::TrianglePair>(got.begin(), got.end()), ribbon);
        EXPECT_TRUE(world.selfPairs(1).empty());  // a closed torus: neighbours share vertices
        EXPECT_EQ(world.lastStats().self_pairs, static_cast<std::int64_t>(ribbon.size()));
        world.step();
    }
}

TEST(SelfCollision, OffByDefault) {
    Scene scene = loadScene(fs::path(CDLAB_SOURCE_DIR) / "scenes/self_collision.yaml");
    for (Body& b : scene.bodies) b.self_collision = false;
    World world = makeWorld(scene);
    world.step();
    EXPECT_TRUE(world.selfPairs(0).empty());
    EXPECT_EQ(world.lastStats().self_pairs, 0);
}

TEST(SelfCollision, SceneKeysRejectMisuse) {
    const std::string world =
        "world: {bounds: {min: [-5, -5, -5], max: [5, 5, 5]}, frames: 10}\n"  // 1
        "bodies:\n";                                                          // 2
    const std::string sphere =
        "  - {name: s, shape: sphere, radius: 1, position: [0, 0, 0], self_collision: true}\n";
    EXPECT_SCENE_ERROR(world + sphere,
                       "3:78: bodies[0].self_collision: ", "applies to mesh bodies only");
    const std::string ring =
        "  - {name: r, shape: mesh, file: ../assets/torus.obj, position: [0, 0, 0]}\n"  // 3
        "expect:\n"                                                                     // 4
        "  self_collision:\n";                                                          // 5
    EXPECT_SCENE_ERROR(
        world + ring + "    - {body: r, frames: [0, 9], max_pairs: 0}\n",
        "6:14: expect.self_collision[0].body: ", "does not have 'self_collision: true'");
    const std::string self_ring =
        "  - {name: r, shape: mesh, file: ../assets/torus.obj, position: [0, 0, 0], "
        "self_collision: true}\n"
        "expect:\n"
        "  self_collision:\n";
    EXPECT_SCENE_ERROR(world + self_ring + "    - {body: r, frames: [0, 9]}\n",
                       "6:7: expect.self_collision[0]: ", "needs 'min_pairs' or 'max_pairs'");
    EXPECT_SCENE_ERROR(
        world + self_ring + "    - {body: r, frames: 1, min_pairs: 3, max_pairs: 2}\n",
        "6:53: expect.self_collision[0].max_pairs: ", "must be >= 'min_pairs'");
    const Scene ok =
        parseScene(world + self_ring + "    - {body: r, frames: [0, 9], min_pairs: 0}\n",
                   "test.yaml", fs::path(CDLAB_SOURCE_DIR) / "scenes");
    ASSERT_EQ(ok.expect.self_collision.size(), 1u);
    EXPECT_TRUE(ok.bodies[0].self_collision);
    EXPECT_EQ(ok.expect.self_collision[0].min_pairs, 0);
}

}  // namespace
}  // namespace engine
