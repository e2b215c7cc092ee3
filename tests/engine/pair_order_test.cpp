// The world in the broad phase's own pair order (WorldSettings::pair_order, scene key
// `pair_order`): the same flagged and confirmed pairs as in sorted order, frame by frame, the
// same motion, and the same lists in the same order when run twice.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "collision/debug_draw.h"
#include "engine/scene.h"
#include "engine/world.h"
#include "scene_text.h"
#include "shipped_scenes.h"

namespace engine {
namespace {

using collision::PairOrder;
using collision::ProxyPair;

using cdlab_test::kScenes;

std::vector<ProxyPair> sortedCopy(std::span<const ProxyPair> pairs) {
    std::vector<ProxyPair> out(pairs.begin(), pairs.end());
    std::sort(out.begin(), out.end());
    return out;
}

bool sameList(std::span<const ProxyPair> a, std::span<const ProxyPair> b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end());
}

TEST(PairOrder, SceneKeyChoosesTheOrderAndSortedIsTheDefault) {
    EXPECT_EQ(scene_text::parse(scene_text::kValid).world.pair_order, PairOrder::Sorted);
    const std::string text = scene_text::kHeader +
                             "  - {shape: sphere, radius: 0.25, position: [0.5, 0.5, 0.5]}\n" +
                             "pair_order: found\n";
    EXPECT_EQ(scene_text::parse(text).world.pair_order, PairOrder::Found);
}

// scenes/crowd.yaml (1,500 bodies, hgrid), its first frames in sorted order, in found order, and
// in found order again from a world that started on sap and was switched to hgrid
// (setBroadPhase keeps the order). Found order is unsorted on some frame, or the test is moot.
TEST(PairOrder, CrowdFlagsAndConfirmsTheSamePairsAndMovesTheSame) {
    Scene scene = loadScene(kScenes / "crowd.yaml");
    ASSERT_EQ(scene.world.broad_phase, "hgrid");
    World sorted = makeWorld(scene);
    scene.world.pair_order = PairOrder::Found;
    World found = makeWorld(scene);
    scene.world.broad_phase = "sap";
    World again = makeWorld(scene);
    again.setBroadPhase("hgrid");
    again.detect();
    int unsorted_frames = 0;
    std::size_t colliding = 0;
    for (int frame = 0; frame < 12; ++frame) {
        if (frame > 0) {
            for (int s = 0; s < scene.steps_per_frame; ++s) {
                sorted.step();
                found.step();
                again.step();
            }
        }
        SCOPED_TRACE("frame " + std::to_string(frame));
        ASSERT_EQ(found.stateHash(), sorted.stateHash());
        ASSERT_EQ(again.stateHash(), found.stateHash());
        ASSERT_TRUE(std::ranges::equal(found.states(), sorted.states()));
        ASSERT_EQ(sortedCopy(found.flaggedPairs()), sortedCopy(sorted.flaggedPairs()));
        ASSERT_EQ(sortedCopy(found.collidingPairs()), sortedCopy(sorted.collidingPairs()));
        ASSERT_TRUE(std::ranges::is_sorted(sorted.flaggedPairs()));
        // Deterministic: the same lists in the same order.
        ASSERT_TRUE(sameList(again.flaggedPairs(), found.flaggedPairs()));
        ASSERT_TRUE(sameList(again.collidingPairs(), found.collidingPairs()));
        unsorted_frames += !std::ranges::is_sorted(found.flaggedPairs());
        colliding += found.collidingPairs().size();
    }
    EXPECT_GT(unsorted_frames, 0);
    EXPECT_GT(colliding, 0u);
}

class LineRecorder final : public collision::DebugDraw {
public:
    void drawLine(const collision::Vec3& a, const collision::Vec3& b,
                  const collision::Color& color) override {
        lines.push_back({a.x(), a.y(), a.z(), b.x(), b.y(), b.z(), double(color.r), double(color.g),
                         double(color.b)});
    }
    std::vector<std::array<double, 9>> lines;
};

// Four tori in a row along x, each cutting through its neighbours, numbered from +x down, so
// hgrid's sweep (by min x) meets (2, 3) first and (0, 1) last:
//
//     x:  -2.4   -0.8    0.8    2.4
//   body:   3      2      1      0
//
// The hierarchy levels mark a pair's nodes red by finding it among the confirmed pairs; in found
// order those are unsorted, and the picture must still be the sorted order's.
TEST(PairOrder, HierarchyLevelsFindConfirmedPairsInFoundOrder) {
    std::string text =
        "world:\n"
        "  bounds: {min: [-6, -4, -4], max: [6, 4, 4]}\n"
        "broadphase: hgrid\n"
        "bodies:\n";
    for (const char* x : {"2.4", "0.8", "-0.8", "-2.4"}) {
        text += std::string("  - {shape: mesh, file: ../assets/torus.obj, position: [") + x +
                ", 0, 0]}\n";
    }
    Scene scene = scene_text::parse(text);
    World sorted = makeWorld(scene);
    scene.world.pair_order = PairOrder::Found;
    World found = makeWorld(scene);
    sorted.detect();
    found.detect();
    const std::vector<ProxyPair> all = {{0, 1}, {1, 2}, {2, 3}};
    ASSERT_EQ(sortedCopy(sorted.collidingPairs()), all);
    ASSERT_EQ(sortedCopy(found.collidingPairs()), all);
    ASSERT_FALSE(std::ranges::is_sorted(found.collidingPairs()));
    ContactDrawStyle style;
    style.node_apart = collision::Color{0, 1, 0};
    style.node_overlapping = collision::Color{1, 1, 0};
    style.node_confirmed = collision::Color{1, 0, 0};
    for (const int depth : {2, 4}) {
        LineRecorder a, b;
        sorted.drawHierarchyLevels(a, depth, style);
        found.drawHierarchyLevels(b, depth, style);
        const auto red = std::ranges::count_if(a.lines, [](const auto& l) { return l[7] == 0; });
        EXPECT_GT(red, 0) << "depth " << depth;  // confirmed nodes drawn
        EXPECT_EQ(b.lines, a.lines) << "depth " << depth;
    }
}

}  // namespace
}  // namespace engine
