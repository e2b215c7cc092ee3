// tests/engine/wide_mesh_bvh_test.cpp -- `world.mesh_bvh: obb4`, the 4-wide OBB tree, in the
// engine: the discrete narrow phase on its wide nodes, mesh-mesh CCD, deforming meshes and the
// drawn levels on the binary OBB tree inside it. Every one must behave exactly as under `obb`.
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "collision/bvh/bvh.h"
#include "collision/debug_draw.h"
#include "engine/scene.h"
#include "engine/world.h"

namespace engine {
namespace {

const std::filesystem::path kSource(CDLAB_SOURCE_DIR);

Scene loadWith(const std::filesystem::path& file, const std::string& mesh_bvh,
               std::vector<SceneOverride> overrides = {}) {
    overrides.push_back({"world.mesh_bvh", mesh_bvh});
    return loadScene(file, overrides);
}

// Everything a step leaves that a trace records, and the contacts drawn from it.
struct StepRecord {
    std::uint64_t state_hash = 0;
    std::vector<collision::ProxyPair> colliding;
    std::vector<std::vector<collision::TrianglePair>> triangle_pairs;
    std::int64_t rebuilds = 0;
    bool operator==(const StepRecord&) const = default;
};

std::vector<StepRecord> runSteps(const Scene& scene, int steps) {
    World world = makeWorld(scene);
    std::vector<StepRecord> out;
    for (int i = 0; i < steps; ++i) {
        world.step();
        StepRecord r;
        r.state_hash = world.stateHash();
        r.colliding.assign(world.collidingPairs().begin(), world.collidingPairs().end());
        for (const collision::PairContacts& c : world.contactDetails()) {
            r.triangle_pairs.push_back(c.triangle_pairs);
        }
        r.rebuilds = world.lastStats().rebuilds;
        out.push_back(std::move(r));
    }
    return out;
}

// scenes/mesh_hierarchy.yaml: two tori drift into each other, a ball drops onto one, a ship
// passes the other. Under obb4 every step gives the same states (bit for bit), confirmed pairs
// and confirmed triangle pairs as under obb: the wide traversal tests the same boxes as the
// binary one, four at a time.
TEST(WideMeshBvh, MeshSceneRunsAsUnderObb) {
    const std::filesystem::path file = kSource / "scenes" / "mesh_hierarchy.yaml";
    const Scene wide = loadWith(file, "obb4");
    ASSERT_FALSE(wide.bodies.empty());
    ASSERT_TRUE(wide.bodies[0].shape.bvh);
    EXPECT_EQ(wide.bodies[0].shape.bvh->volumeName(), collision::kWideObbName);
    constexpr int kSteps = 300;
    const std::vector<StepRecord> a = runSteps(loadWith(file, "obb"), kSteps);
    const std::vector<StepRecord> b = runSteps(wide, kSteps);
    ASSERT_EQ(a.size(), b.size());
    int with_triangles = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i], b[i]) << "step " << i;
        for (const auto& pairs : a[i].triangle_pairs) with_triangles += !pairs.empty();
    }
    EXPECT_GT(with_triangles, 0);  // the meshes did meet
}

// Mesh-mesh CCD runs on the binary OBB tree inside obb4 (collision::obbTreeOf), not on the
// convex hulls. tests/data/ring_rod_ccd.yaml, as in ccd_policy_test:
//
//      ring (axis y, 300 m/s up)   ( O )  -> passes around the bead in its hole
//      bead on the tube (x = 1)    ( o)   -> the ring is stopped at the bead
//
TEST(WideMeshBvh, MeshCcdRunsOnTheSurfacesAsUnderObb) {
    const std::filesystem::path file = kSource / "tests" / "data" / "ring_rod_ccd.yaml";
    for (const std::string bead_x : {"0", "1"}) {
        const std::vector<SceneOverride> at{{"bodies.1.position", "[" + bead_x + ", 0, 0]"}};
        World obb = makeWorld(loadWith(file, "obb", at));
        World wide = makeWorld(loadWith(file, "obb4", at));
        obb.step();
        wide.step();
        EXPECT_EQ(wide.toiEvents().size(), bead_x == "0" ? 0u : 1u) << "bead x " << bead_x;
        ASSERT_EQ(wide.toiEvents().size(), obb.toiEvents().size());
        EXPECT_EQ(wide.stateHash(), obb.stateHash()) << "bead x " << bead_x;
    }
}

// scenes/deform_self.yaml: a strip bends until it curls through itself. Its obb4 tree is refitted
// and rebuilt at the same steps as the obb tree (the volume ratio is the binary tree's), and the
// self pairs and states are the same.
TEST(WideMeshBvh, DeformingMeshRefitsAndRebuildsAsUnderObb) {
    const std::filesystem::path file = kSource / "scenes" / "deform_self.yaml";
    constexpr int kSteps = 160;
    const std::vector<StepRecord> a = runSteps(loadWith(file, "obb"), kSteps);
    const std::vector<StepRecord> b = runSteps(loadWith(file, "obb4"), kSteps);
    std::int64_t rebuilds = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i], b[i]) << "step " << i;
        rebuilds += a[i].rebuilds;
    }
    EXPECT_GT(rebuilds, 0);
}

class RecordingDraw final : public collision::DebugDraw {
public:
    void drawLine(const collision::Vec3& a, const collision::Vec3& b,
                  const collision::Color& color) override {
        lines.push_back({a.x(), a.y(), a.z(), b.x(), b.y(), b.z(), double(color.r),
                         double(color.g), double(color.b)});
    }
    std::vector<std::array<double, 9>> lines;
};

// draw.bvh_depth on an obb4 tree draws the binary OBB tree's level (its boxes and states), the
// same lines as under obb.
TEST(WideMeshBvh, LevelDrawingDrawsTheBinaryLevels) {
    const std::filesystem::path file = kSource / "scenes" / "mesh_hierarchy.yaml";
    ContactDrawStyle style;
    style.node_apart = collision::Color{0, 1, 0};
    style.node_overlapping = collision::Color{1, 1, 0};
    style.node_confirmed = collision::Color{1, 0, 0};
    World obb = makeWorld(loadWith(file, "obb"));
    World wide = makeWorld(loadWith(file, "obb4"));
    for (int i = 0; i < 240; ++i) {
        obb.step();
        wide.step();
    }
    for (const int depth : {0, 3}) {
        RecordingDraw drawn_obb;
        RecordingDraw drawn_wide;
        obb.drawHierarchyLevels(drawn_obb, depth, style);
        wide.drawHierarchyLevels(drawn_wide, depth, style);
        EXPECT_FALSE(drawn_wide.lines.empty()) << "depth " << depth;
        EXPECT_EQ(drawn_wide.lines, drawn_obb.lines) << "depth " << depth;
    }
}

}  // namespace
}  // namespace engine
