// tests/render/volume_colors_test.cpp -- every drawn volume takes the colour of its own overlap
// test, and a run draws the volume its broad phase tests unless the scene chose.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "engine/scene.h"
#include "engine/volume_overlaps.h"
#include "engine/world.h"
#include "engine/world_draw.h"
#include "pixel_checks.h"
#include "render/renderer.h"

namespace {

using namespace cdlab_test;
namespace fs = std::filesystem;

// D and E sit diagonally: their AABBs overlap (x in [-0.8, -0.4], y in [-0.2, 0.2]) but their
// spheres do not (centres 1.70 apart, radii 0.8 + 0.8). F is alone.
//
//        y
//        |     [ ( E ) ]
//   [ ( D ) ]                 ( F )
//   -----+------------------------- x      camera at (0, 0, 9) looking at the origin
engine::World makeDiagonalPairWorld(const std::string& broad_phase) {
    engine::WorldSettings settings;
    settings.bounds = collision::Aabb{Vec3::Constant(-20), Vec3::Constant(20)};
    settings.broad_phase = broad_phase;
    engine::World world(settings);
    world.addBody(sphereBody("d", 0.8, Vec3(-1.2, -0.6, 0)));
    world.addBody(sphereBody("e", 0.8, Vec3(0, 0.6, 0)));
    world.addBody(sphereBody("f", 0.8, Vec3(2.8, 0, 0)));
    world.detect();
    return world;
}

// Two parallel rods turned 45 degrees about z, side by side: their AABBs overlap, their OBBs
// (the rods themselves) are 0.85 apart across, more than the 0.3 of their two half widths.
//
//        y        /  /
//        |       /  /        rods along (1, 1), the second shifted by (0.6, -0.6)
//   -----+------/--/------ x
engine::World makeParallelRodsWorld(const std::string& broad_phase) {
    engine::WorldSettings settings;
    settings.bounds = collision::Aabb{Vec3::Constant(-20), Vec3::Constant(20)};
    settings.broad_phase = broad_phase;
    engine::World world(settings);
    const Quat turn(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitZ()));
    const collision::Shape rod = collision::Shape::box(Vec3(1, 0.15, 0.15));
    world.addBody(makeShapeBody("rod1", rod, Vec3(-0.3, 0.3, 0), turn));
    world.addBody(makeShapeBody("rod2", rod, Vec3(0.3, -0.3, 0), turn));
    world.detect();
    return world;
}

render::FrameOptions volumesOnly(bool sphere, bool aabb, bool obb) {
    render::FrameOptions options = plainOptions();
    options.draw.bodies = false;
    options.draw.sphere = sphere;
    options.draw.aabb = aabb;
    options.draw.obb = obb;
    return options;
}

const Rgb kGreen = toRgb(engine::stateColor(engine::BodyState::Apart));
const Rgb kYellow = toRgb(engine::stateColor(engine::BodyState::Flagged));
const Rgb kRed = toRgb(engine::stateColor(engine::BodyState::Colliding));

}  // namespace

// The broad phase (sap) flags D and E by their AABBs: the AABBs, the volume it tests, are
// yellow; F's is green. Outline points on the boxes' front faces, away from where they cross.
TEST(VolumeColors, FlaggedButNotTouchingAabbsAreYellow) {
    const engine::World world = makeDiagonalPairWorld("sap");
    ASSERT_EQ(world.states()[0], engine::BodyState::Flagged);
    ASSERT_EQ(world.states()[1], engine::BodyState::Flagged);
    ASSERT_EQ(world.states()[2], engine::BodyState::Apart);
    render::Renderer renderer(kWidth, kHeight);
    const engine::CameraSettings cam = headOnCamera();
    const render::Image image = renderer.render(world, cam, volumesOnly(false, true, false));
    for (const Vec3& p :
         {Vec3(-2.0, -0.9, 0.8), Vec3(-1.5, -1.4, 0.8), Vec3(0.8, 0.9, 0.8), Vec3(0.3, 1.4, 0.8)}) {
        const PixelPos px = project(cam, kWidth, kHeight, p);
        EXPECT_TRUE(colorNear(image, px, kYellow)) << "no yellow near " << px.x << "," << px.y;
        EXPECT_FALSE(colorNear(image, px, kGreen)) << "green near " << px.x << "," << px.y;
        EXPECT_FALSE(colorNear(image, px, kRed)) << "red near " << px.x << "," << px.y;
    }
    const PixelPos f_edge = project(cam, kWidth, kHeight, Vec3(3.6, 0.3, 0.8));
    EXPECT_TRUE(colorNear(image, f_edge, kGreen));
    EXPECT_FALSE(colorNear(image, f_edge, kYellow));
}

// The pause picture once drew D's and E's spheres yellow
// because their AABBs were flagged. Drawn together, each volume takes its own test's colour:
// the spheres (apart as spheres) green, the AABBs and OBBs (overlapping) yellow.
TEST(VolumeColors, SphereStaysGreenWhenOnlyTheAabbsOverlap) {
    const engine::World world = makeDiagonalPairWorld("sap");
    constexpr int kW = 320;
    constexpr int kH = 240;
    render::Renderer renderer(kW, kH);
    // Looking straight at D, so its box's front and back faces frame its sphere concentrically
    // and the sphere's outline at 45 degrees lies 5 or more pixels from every box edge.
    engine::CameraSettings cam = headOnCamera();
    cam.position = Vec3(-1.2, -0.6, 9);
    cam.look_at = Vec3(-1.2, -0.6, 0);
    for (const bool with_boxes : {false, true}) {
        SCOPED_TRACE(with_boxes ? "spheres, AABBs and OBBs" : "spheres only");
        const render::Image image =
            renderer.render(world, cam, volumesOnly(true, with_boxes, with_boxes));
        // D's outline at 45 degrees, except towards E.
        const Real r = Real(0.8) * std::sqrt(Real(0.5));
        for (const Vec3& p : {Vec3(-1.2 - r, -0.6 - r, 0), Vec3(-1.2 - r, -0.6 + r, 0),
                              Vec3(-1.2 + r, -0.6 - r, 0)}) {
            const PixelPos px = project(cam, kW, kH, p);
            EXPECT_TRUE(colorNear(image, px, kGreen, 1)) << "no green near " << px.x << "," << px.y;
            EXPECT_FALSE(colorNear(image, px, kYellow, 1)) << "yellow near " << px.x << "," << px.y;
        }
        if (with_boxes) {
            const PixelPos corner = project(cam, kW, kH, Vec3(-2.0, -1.4, 0.8));
            EXPECT_TRUE(colorNear(image, corner, kYellow)) << "the AABBs overlap: yellow";
        }
    }
}

// --broadphase obb on a scene without draw.volumes: the OBBs are drawn, green, since they do not
// overlap, and nothing is yellow, though the AABBs overlap. An AABB-based broad phase draws the
// AABBs, yellow. A scene that chose AABBs keeps them, yellow by their own test even under the
// OBB broad phase (they were green: coloured by the OBB test).
TEST(VolumeColors, ObbBroadPhaseDrawsObbsAndNoYellowWhenOnlyTheAabbsOverlap) {
    constexpr int kW = 320;
    constexpr int kH = 240;
    render::Renderer renderer(kW, kH);
    const engine::CameraSettings cam = headOnCamera();
    engine::DrawSettings scene_default = plainOptions().draw;  // draw.volumes not given
    scene_default.bodies = false;
    ASSERT_FALSE(scene_default.volumes_given);

    const engine::World obb_world = makeParallelRodsWorld("obb");
    ASSERT_EQ(obb_world.flaggedPairs().size(), 0u);
    render::FrameOptions options;
    options.draw = engine::drawSettingsFor(scene_default, obb_world);
    EXPECT_TRUE(options.draw.obb);
    EXPECT_FALSE(options.draw.aabb);
    EXPECT_FALSE(options.draw.sphere);
    const render::Image obb_image = renderer.render(obb_world, cam, options);
    EXPECT_EQ(countColor(obb_image, kYellow), 0);
    // A point of rod1's long upper front edge, 0.7 from its middle: on its OBB, clear of its and
    // rod2's bounding spheres' circles, so green there is an OBB line.
    const Real c = std::sqrt(Real(0.5));
    const Vec3 edge_point = Vec3(-0.3, 0.3, 0.15) + Vec3(0.7 * c - 0.15 * c, 0.7 * c + 0.15 * c, 0);
    EXPECT_TRUE(colorNear(obb_image, project(cam, kW, kH, edge_point), kGreen, 1));

    const engine::World sap_world = makeParallelRodsWorld("sap");
    ASSERT_EQ(sap_world.flaggedPairs().size(), 1u);
    options.draw = engine::drawSettingsFor(scene_default, sap_world);
    EXPECT_TRUE(options.draw.aabb);
    EXPECT_FALSE(options.draw.obb);
    EXPECT_GT(countColor(renderer.render(sap_world, cam, options), kYellow), 20);

    engine::DrawSettings chose_aabb = scene_default;
    chose_aabb.sphere = false;
    chose_aabb.aabb = true;
    chose_aabb.volumes_given = true;
    options.draw = engine::drawSettingsFor(chose_aabb, obb_world);
    EXPECT_TRUE(options.draw.aabb);
    EXPECT_FALSE(options.draw.obb);
    EXPECT_GT(countColor(renderer.render(obb_world, cam, options), kYellow), 20);
}

// The default volume follows the registry's volume column for every broad phase; a scene's
// draw.volumes is kept as it is.
TEST(VolumeColors, DefaultVolumeIsTheOneEachBroadPhaseTests) {
    engine::World world = makeDiagonalPairWorld("sap");
    for (const collision::BroadPhaseEntry& e : collision::broadPhaseRegistry()) {
        if (e.needs_render_context) continue;  // no oracle installed in render_tests
        SCOPED_TRACE(std::string(e.name));
        world.setBroadPhase(std::string(e.name));
        const engine::DrawSettings d = engine::drawSettingsFor(engine::DrawSettings{}, world);
        EXPECT_EQ(d.sphere, e.volume == collision::VolumeKind::Sphere);
        EXPECT_EQ(d.aabb, e.volume == collision::VolumeKind::Aabb);
        EXPECT_EQ(d.obb, e.volume == collision::VolumeKind::Obb);
        engine::DrawSettings chosen;
        chosen.sphere = chosen.aabb = chosen.obb = true;
        chosen.volumes_given = true;
        const engine::DrawSettings kept = engine::drawSettingsFor(chosen, world);
        EXPECT_TRUE(kept.sphere && kept.aabb && kept.obb);
    }
    EXPECT_FALSE(engine::loadScene(fs::path(CDLAB_SOURCE_DIR) / "scenes" / "bounce.yaml")
                     .draw.sphere);  // volumes: [] is a choice too
}

// The per-kind overlaps equal brute force over the volumes with the collision library's own
// tests, whichever broad phase the world runs (its own pairs serve the kind it tests), and the
// states follow from the pairs and the confirmed pairs. The coursework scene after 2 s has pairs
// of every kind and kinds that disagree.
TEST(VolumeOverlaps, EqualBruteForceForEveryKindUnderEveryBroadPhase) {
    const engine::Scene scene =
        engine::loadScene(fs::path(CDLAB_SOURCE_DIR) / "scenes" / "coursework.yaml");
    engine::World world = engine::makeWorld(scene);
    for (int s = 0; s < 240; ++s) world.step();
    const auto volumes = world.volumes();
    std::vector<collision::ProxyPair> brute[3];
    for (std::size_t i = 0; i < volumes.size(); ++i) {
        for (std::size_t j = i + 1; j < volumes.size(); ++j) {
            const collision::ProxyPair p{collision::ProxyId(i), collision::ProxyId(j)};
            if (volumes[i].sphere.overlaps(volumes[j].sphere)) brute[0].push_back(p);
            if (volumes[i].aabb.overlaps(volumes[j].aabb)) brute[1].push_back(p);
            if (volumes[i].obb.overlaps(volumes[j].obb)) brute[2].push_back(p);
        }
    }
    for (const auto& pairs : brute) ASSERT_FALSE(pairs.empty());
    EXPECT_NE(brute[0], brute[1]);
    EXPECT_NE(brute[1], brute[2]);
    ASSERT_FALSE(world.collidingPairs().empty());

    for (const std::string bp : {"sap", "sphere", "obb", "hgrid", "brute"}) {
        SCOPED_TRACE(bp);
        world.setBroadPhase(bp);
        world.detect();
        for (const engine::VolumeKind kind : engine::kVolumeKinds) {
            SCOPED_TRACE(std::string(engine::volumeKindName(kind)));
            const engine::VolumeOverlaps o = engine::volumeOverlaps(world, kind);
            EXPECT_EQ(o.pairs, brute[int(kind)]);
            ASSERT_EQ(o.states.size(), volumes.size());
            std::vector<engine::BodyState> expected(volumes.size(), engine::BodyState::Apart);
            for (const collision::ProxyPair& p : brute[int(kind)]) {
                expected[p.a] = expected[p.b] = engine::BodyState::Flagged;
            }
            for (const collision::ProxyPair& p : world.collidingPairs()) {
                expected[p.a] = expected[p.b] = engine::BodyState::Colliding;
            }
            EXPECT_EQ(o.states, expected);
            if (engine::broadPhaseVolume(world) == kind) {
                EXPECT_EQ(o.states, std::vector<engine::BodyState>(world.states().begin(),
                                                                   world.states().end()));
            }
        }
    }
}

namespace {

// The diagonal pair again: D and E's 6-DOPs (their AABBs) overlap; the face-diagonal slab
// (1, 1, 0) of the 18- and 26-DOPs separates them (D's reaches -0.67, E's starts at -0.53).
TEST(KdopOverlaps, TighterKdopsLeaveTheDiagonalPairApart) {
    const engine::World world = makeDiagonalPairWorld("sap");
    using engine::BodyState;
    const std::vector<BodyState> boxes = {BodyState::Flagged, BodyState::Flagged, BodyState::Apart};
    const std::vector<BodyState> apart(3, BodyState::Apart);
    EXPECT_EQ(engine::kdopOverlaps(world, engine::worldKdops(world, 6)).states, boxes);
    EXPECT_EQ(engine::kdopOverlaps(world, engine::worldKdops(world, 14)).states, boxes);
    EXPECT_EQ(engine::kdopOverlaps(world, engine::worldKdops(world, 18)).states, apart);
    EXPECT_EQ(engine::kdopOverlaps(world, engine::worldKdops(world, 26)).states, apart);
}

TEST(KdopOverlaps, SweepFindsExactlyTheBruteForcePairs) {
    engine::WorldSettings settings;
    settings.bounds = collision::Aabb{Vec3::Constant(-20), Vec3::Constant(20)};
    engine::World world(settings);
    std::uint64_t seed = 12345;
    auto next = [&seed] {
        seed = seed * 6364136223846793005ull + 1442695040888963407ull;
        return Real(seed >> 11) / Real(1ull << 53);
    };
    for (int i = 0; i < 60; ++i) {
        const Vec3 at(8 * next() - 4, 8 * next() - 4, 8 * next() - 4);
        std::string name = "s";
        name += std::to_string(i);
        world.addBody(sphereBody(name, 0.3 + 0.4 * next(), at));
    }
    world.detect();
    for (const int k : {6, 14, 18, 26}) {
        const std::vector<collision::WorldKdop> kdops = engine::worldKdops(world, k);
        std::vector<collision::ProxyPair> brute;
        for (std::size_t a = 0; a < kdops.size(); ++a) {
            for (std::size_t b = a + 1; b < kdops.size(); ++b) {
                if (kdops[a].overlaps(kdops[b])) {
                    brute.push_back({collision::ProxyId(a), collision::ProxyId(b)});
                }
            }
        }
        EXPECT_EQ(engine::kdopOverlaps(world, kdops).pairs, brute) << "k=" << k;
        EXPECT_FALSE(brute.empty()) << "k=" << k;
    }
}

}  // namespace

// The 14-DOP is drawn as its polytope, not as the box of its three axis slabs: F's 14-DOP (a
// cube of side 1.6 with each corner cut by a cube-diagonal slab) has an edge across the front
// face's top right corner, from (0.8, -0.21, 0.8) to (-0.21, 0.8, 0.8) about F's centre. A point
// 0.3 along it (clear of the box's far edges in perspective) is green with kdop14 drawn, and
// nothing is drawn there with kdop6 (the box).
TEST(KdopDrawing, FourteenDopCornerCutsAreDrawn) {
    const engine::World world = makeDiagonalPairWorld("sap");
    render::Renderer renderer(kWidth, kHeight);
    const engine::CameraSettings cam = headOnCamera();
    const Real cut = Real(0.8) * std::sqrt(Real(3)) - Real(1.6);  // -0.21
    const Vec3 on_edge = Vec3(2.8, 0, 0) + 0.7 * Vec3(0.8, cut, 0.8) + 0.3 * Vec3(cut, 0.8, 0.8);
    const PixelPos px = project(cam, kWidth, kHeight, on_edge);
    render::FrameOptions options = volumesOnly(false, false, false);
    options.draw.kdop[1] = true;  // kdop14
    ASSERT_EQ(engine::kDrawnKdops[1], 14);
    EXPECT_TRUE(colorNear(renderer.render(world, cam, options), px, kGreen, 1))
        << px.x << "," << px.y;
    options.draw.kdop = {};
    options.draw.kdop[0] = true;  // kdop6: the box, no line there
    EXPECT_FALSE(colorNear(renderer.render(world, cam, options), px, kGreen, 1))
        << px.x << "," << px.y;
}

// The legend names every volume drawn, each k-DOP by its k.
TEST(KdopDrawing, LegendNamesEachKDrawn) {
    engine::DrawSettings draw;
    draw.sphere = true;
    draw.aabb = false;
    draw.obb = false;
    draw.kdop = {true, true, false, true};
    EXPECT_EQ(engine::drawnVolumeNames(draw),
              (std::vector<std::string>{"sphere", "6-DOP", "14-DOP", "26-DOP"}));
    draw.sphere = false;
    draw.obb = true;
    draw.kdop = {false, false, true, false};
    EXPECT_EQ(engine::drawnVolumeNames(draw), (std::vector<std::string>{"OBB", "18-DOP"}));

    // In the frame: the legend block (bottom left, clear of the bodies' volumes) is there with
    // the HUD, and its text differs between a frame drawing the 14-DOPs and one drawing the
    // 26-DOPs.
    const engine::World world = makeDiagonalPairWorld("sap");
    render::Renderer renderer(640, 480);
    render::FrameOptions options = volumesOnly(false, false, false);
    options.draw.hud = true;
    options.draw.kdop = {false, true, false, false};
    const render::Image fourteen = renderer.render(world, headOnCamera(), options);
    options.draw.kdop = {false, false, false, true};
    const render::Image twenty_six = renderer.render(world, headOnCamera(), options);
    options.draw.hud = false;
    const render::Image no_legend = renderer.render(world, headOnCamera(), options);
    int legend = 0;
    int text = 0;
    for (int y = 480 - 48; y < 480; ++y) {
        for (int x = 0; x < 320; ++x) {
            legend += pixelAt(twenty_six, x, y) != pixelAt(no_legend, x, y);
            text += pixelAt(fourteen, x, y) != pixelAt(twenty_six, x, y);
        }
    }
    EXPECT_GT(legend, 500);
    EXPECT_GT(text, 10);
}
