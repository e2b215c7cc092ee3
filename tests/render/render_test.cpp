// tests/render/render_test.cpp -- render checks: pixel colours at projected points (not whole-image
// goldens), determinism, PNG round trip, output error paths, the ffmpeg pipe, the HUD.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "../collision/test_meshes.h"
#include "collision/bvh/bvh_level.h"
#include "collision/debug_draw.h"
#include "collision/geometry/convex_hull.h"
#include "collision/geometry/shape.h"
#include "collision/narrowphase/narrow_phase.h"
#include "engine/body.h"
#include "engine/scene.h"
#include "engine/world.h"
#include "engine/world_draw.h"
#include "render/image.h"
#include "render/renderer.h"
#include "pixel_checks.h"
#include "test_dir.h"

namespace {

namespace fs = std::filesystem;
using engine::Mat3;
using engine::Quat;
using engine::Real;
using engine::Vec3;
using namespace cdlab_test;

// A fresh directory per test.
class RenderDir : public cdlab_test::TempDir {
public:
    RenderDir() : cdlab_test::TempDir("cdlab_render_") {}
};

render::Image renderThreeSpheres(render::Renderer& renderer,
                                 const render::FrameOptions& options = plainOptions()) {
    const engine::World world = makeThreeSphereWorld();
    return renderer.render(world, headOnCamera(), options);
}

// ---------------------------------------------------------------------------------------------

TEST(RenderScene, TestWorldHasOneCollidingPairAndOneLoneSphere) {
    const engine::World world = makeThreeSphereWorld();
    ASSERT_EQ(world.states().size(), 3u);
    EXPECT_EQ(world.states()[0], engine::BodyState::Colliding);
    EXPECT_EQ(world.states()[1], engine::BodyState::Colliding);
    EXPECT_EQ(world.states()[2], engine::BodyState::Apart);
}

TEST(Renderer, ImageHasRequestedSize) {
    render::Renderer renderer(kWidth, kHeight);
    const render::Image image = renderThreeSpheres(renderer);
    EXPECT_EQ(image.width, kWidth);
    EXPECT_EQ(image.height, kHeight);
    EXPECT_EQ(image.rgb.size(), std::size_t(kWidth) * kHeight * 3);
}

TEST(Renderer, SphereOutlinesTakeTheirStateColour) {
    render::Renderer renderer(kWidth, kHeight);
    const render::Image image = renderThreeSpheres(renderer);
    const engine::CameraSettings cam = headOnCamera();
    const Rgb red = toRgb(engine::stateColor(engine::BodyState::Colliding));
    const Rgb green = toRgb(engine::stateColor(engine::BodyState::Apart));

    // Points of the bounding spheres' great circles that sit on the outline seen from +z.
    const std::vector<Vec3> red_points = {
        {-4, 0, 0}, {-3, 1, 0}, {-3, -1, 0}, {-1.6, 1.2, 0}, {-0.6, 0.2, 0}};
    const std::vector<Vec3> green_points = {{1.6, 0, 0}, {3.6, 0, 0}, {2.6, 1, 0}, {2.6, -1, 0}};
    for (const Vec3& p : red_points) {
        const PixelPos px = project(cam, kWidth, kHeight, p);
        EXPECT_TRUE(colorNear(image, px, red)) << "no red near " << px.x << "," << px.y;
        EXPECT_FALSE(colorNear(image, px, green)) << "green near " << px.x << "," << px.y;
    }
    for (const Vec3& p : green_points) {
        const PixelPos px = project(cam, kWidth, kHeight, p);
        EXPECT_TRUE(colorNear(image, px, green)) << "no green near " << px.x << "," << px.y;
        EXPECT_FALSE(colorNear(image, px, red)) << "red near " << px.x << "," << px.y;
    }
}

// A pair the broad phase flags but the narrow phase rejects is drawn yellow. Two spheres whose
// AABBs overlap on every axis (|dx| = |dy| = 1.2 < 2r = 1.6) while their centres are 1.2 sqrt(2)
// = 1.70 > 1.6 apart: `sap` (on AABBs) flags them, the exact sphere test does not confirm them.
//
//        y
//        |        ( E )               E (0, 0.6), D (-1.2, -0.6), r = 0.8
//   -----+----( D )---------( F )---- x      F (2.8, 0) alone: green
TEST(Renderer, BackgroundIsTheBackgroundColour) {
    render::Renderer renderer(kWidth, kHeight);
    const render::Image image = renderThreeSpheres(renderer);
    const Rgb background = toRgb(render::kBackgroundColor);
    EXPECT_EQ(background, (Rgb{26, 28, 36}));
    // Corners, the top and bottom middle, and the gap between B and C.
    const engine::CameraSettings cam = headOnCamera();
    const PixelPos gap = project(cam, kWidth, kHeight, Vec3(0.5, 0, 0));
    const std::vector<std::array<int, 2>> spots = {{0, 0},
                                                   {kWidth - 1, 0},
                                                   {0, kHeight - 1},
                                                   {kWidth - 1, kHeight - 1},
                                                   {kWidth / 2, 5},
                                                   {kWidth / 2, kHeight - 6},
                                                   {int(gap.x), int(gap.y)}};
    for (const auto& s : spots) {
        EXPECT_EQ(pixelAt(image, s[0], s[1]), background) << "at " << s[0] << "," << s[1];
    }
}

TEST(Renderer, BodiesAreShadedGreyBlueInsideTheirOutline) {
    render::Renderer renderer(kWidth, kHeight);
    const render::Image image = renderThreeSpheres(renderer);
    const engine::CameraSettings cam = headOnCamera();
    // A body pixel between the wire circles (the YZ circle projects to a thin ellipse left of
    // this point, the XZ circle to the horizontal through the centre): lit, blue > red.
    const PixelPos px = project(cam, kWidth, kHeight, Vec3(2.6 + 0.35, -0.35, 0.86));
    const Rgb c = pixelAt(image, int(px.x), int(px.y));
    EXPECT_GT(c[2], c[0]);
    EXPECT_GT(c[0] + c[1] + c[2], 3 * 60) << "too dark";
    EXPECT_FALSE(close(c, toRgb(render::kBackgroundColor), 10));
    EXPECT_FALSE(close(c, toRgb(engine::stateColor(engine::BodyState::Apart)), 60));

    render::FrameOptions no_bodies = plainOptions();
    no_bodies.draw.bodies = false;
    const render::Image wire = renderThreeSpheres(renderer, no_bodies);
    EXPECT_EQ(pixelAt(wire, int(px.x), int(px.y)), toRgb(render::kBackgroundColor));
}

TEST(Renderer, SameStateRendersBitIdentical) {
    render::Renderer renderer(kWidth, kHeight);
    render::FrameOptions options = plainOptions();
    options.draw.aabb = options.draw.obb = options.draw.bounds = options.draw.hud = true;
    options.hud_text = "frame 3  t=0.050 s  sap";
    const render::Image first = renderThreeSpheres(renderer, options);
    const render::Image second = renderThreeSpheres(renderer, options);
    EXPECT_EQ(first.rgb, second.rgb);
    render::Renderer other(kWidth, kHeight);
    const render::Image third = renderThreeSpheres(other, options);
    EXPECT_EQ(first.rgb, third.rgb);
}

// Metamorphic: moving the whole scene and the camera far from the origin must not change the
// picture beyond rounding (vertices are eye-relative before they become floats).
TEST(Renderer, TranslatingSceneAndCameraKeepsThePicture) {
    const Vec3 shift(1e5, -1e5, 1e5);
    engine::WorldSettings settings;
    settings.bounds = collision::Aabb{Vec3::Constant(-20) + shift, Vec3::Constant(20) + shift};
    engine::World far_world(settings);
    far_world.addBody(sphereBody("a", 1, Vec3(-3, 0, 0) + shift));
    far_world.addBody(sphereBody("b", 1, Vec3(-1.6, 0.2, 0) + shift));
    far_world.addBody(sphereBody("c", 1, Vec3(2.6, 0, 0) + shift));
    far_world.detect();
    engine::CameraSettings far_camera = headOnCamera();
    far_camera.position += shift;
    far_camera.look_at += shift;

    render::Renderer renderer(kWidth, kHeight);
    const render::Image near_image = renderThreeSpheres(renderer);
    const render::Image far_image = renderer.render(far_world, far_camera, plainOptions());
    int differing = 0;
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            differing += !close(pixelAt(near_image, x, y), pixelAt(far_image, x, y), 8);
        }
    }
    EXPECT_LT(differing, kWidth * kHeight / 200) << differing << " pixels differ";
}

// Regression: with the camera inside a crowd, bodies behind it were tessellated at the finest
// level and everything went into one vertex array (15,000 spheres took 2.7 GB and 30 s a frame;
// 150,000 crashed). Culling what lies outside the view and drawing in batches must change no
// pixel: the reference draws everything in one batch.
TEST(Renderer, CullingAndBatchingChangeNoPixel) {
    engine::WorldSettings settings;
    settings.bounds = collision::Aabb{Vec3::Constant(-12), Vec3::Constant(12)};
    engine::World world(settings);
    int n = 0;
    for (int i = -4; i <= 4; ++i) {
        for (int j = -4; j <= 4; ++j) {
            for (int k = -4; k <= 4; ++k) {
                const Vec3 p(2.5 * i + 0.3 * j, 2.5 * j + 0.2 * k, 2.5 * k + 0.1 * i);
                const std::string name = std::to_string(n);
                switch (n++ % 3) {
                    case 0:
                        world.addBody(sphereBody(name, 0.9, p));
                        break;
                    case 1:
                        world.addBody(makeShapeBody(
                            name, collision::Shape::box(Vec3(0.9, 0.4, 0.6)), p,
                            Quat(Eigen::AngleAxis<Real>(Real(0.1 * n), Vec3::UnitZ()))));
                        break;
                    default:
                        world.addBody(makeShapeBody(name, collision::Shape::capsule(0.4, 0.5), p));
                        break;
                }
            }
        }
    }
    world.detect();
    engine::CameraSettings camera;  // inside the crowd, looking along a diagonal
    camera.position = Vec3(0.4, 1.3, 1.1);
    camera.look_at = Vec3(8, 3, -6);
    camera.up = Vec3::UnitY();
    camera.fov_deg = 60;
    render::FrameOptions reference = plainOptions();
    reference.draw.aabb = reference.draw.obb = true;
    reference.cull = false;
    reference.triangle_batch_vertices = std::int64_t(1) << 40;
    render::FrameOptions fast = reference;
    fast.cull = true;
    fast.triangle_batch_vertices = 2000;

    render::Renderer renderer(kWidth, kHeight);
    const render::Image all = renderer.render(world, camera, reference);
    const render::FrameStats all_stats = renderer.lastFrameStats();
    const render::Image culled = renderer.render(world, camera, fast);
    const render::FrameStats culled_stats = renderer.lastFrameStats();
    EXPECT_EQ(all.rgb, culled.rgb);
    EXPECT_EQ(all_stats.bodies_drawn, n);
    EXPECT_EQ(all_stats.bodies_culled + all_stats.volumes_culled, 0);
    EXPECT_EQ(all_stats.batches, 1);
    // Most of the crowd is behind or beside the camera; what is left still shows bodies.
    EXPECT_GT(culled_stats.bodies_culled, n / 2);
    EXPECT_GT(culled_stats.volumes_culled, n);
    EXPECT_EQ(culled_stats.bodies_drawn + culled_stats.bodies_culled, n);
    EXPECT_GT(culled_stats.bodies_drawn, 10);
    EXPECT_GT(culled_stats.batches, 3);
    EXPECT_LT(culled_stats.triangle_vertices, all_stats.triangle_vertices / 2);
    // A batch closes at the first body past the limit: at most one body's worth beyond it.
    EXPECT_LT(culled_stats.largest_batch_vertices, 2000 + 64 * 32 * 6);
    int background = 0;
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            background += pixelAt(culled, x, y) == toRgb(render::kBackgroundColor);
        }
    }
    EXPECT_LT(background, kWidth * kHeight * 9 / 10);
}

TEST(Renderer, EveryShapeTypeIsDrawn) {
    engine::WorldSettings settings;
    settings.bounds = collision::Aabb{Vec3::Constant(-20), Vec3::Constant(20)};
    engine::World world(settings);
    // A capsule turned 90 degrees about z lies along x.
    const Quat turn(Eigen::AngleAxis<Real>(Real(kPi / 2), Vec3::UnitZ()));
    world.addBody(
        makeShapeBody("capsule", collision::Shape::capsule(0.4, 1.0), Vec3(-3, 1.5, 0), turn));
    world.addBody(
        makeShapeBody("box", collision::Shape::box(Vec3(0.6, 0.6, 0.6)), Vec3(0, 1.5, 0)));
    const std::vector<Vec3> tetra = {
        {-0.8, -0.6, -0.6}, {0.8, -0.6, -0.6}, {0, 0.8, -0.6}, {0, 0, 0.8}};
    const collision::ConvexHullOutput hull = collision::computeConvexHull(tetra);
    ASSERT_TRUE(hull.ok) << hull.error;
    auto polytope = std::make_shared<const collision::ConvexPolytope>(hull.hull);
    world.addBody(makeShapeBody("hull", collision::Shape::convexHull(polytope), Vec3(3, 1.5, 0)));
    auto mesh = std::make_shared<collision::TriangleMesh>();
    mesh->vertices = tetra;
    mesh->triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
    world.addBody(
        makeShapeBody("mesh", collision::Shape::triangleMesh(mesh, polytope), Vec3(0, -1.8, 0)));
    world.detect();

    render::Renderer renderer(kWidth, kHeight);
    render::FrameOptions options = plainOptions();
    options.draw.sphere = false;  // bodies only
    const render::Image image = renderer.render(world, headOnCamera(), options);
    const engine::CameraSettings cam = headOnCamera();
    const Rgb background = toRgb(render::kBackgroundColor);
    auto shaded = [&](const Vec3& p) {
        const PixelPos px = project(cam, kWidth, kHeight, p);
        return pixelAt(image, int(px.x), int(px.y)) != background;
    };
    EXPECT_TRUE(shaded(Vec3(-3, 1.5, 0.4)));         // capsule centre
    EXPECT_TRUE(shaded(Vec3(-3 + 1.2, 1.5, 0.3)));   // capsule cap, along world x
    EXPECT_FALSE(shaded(Vec3(-3, 1.5 + 0.9, 0)));    // above the thin capsule: nothing
    EXPECT_TRUE(shaded(Vec3(0, 1.5, 0.6)));          // box face
    EXPECT_TRUE(shaded(Vec3(0.5, 1.5 + 0.5, 0.6)));  // box corner region
    EXPECT_TRUE(shaded(Vec3(3, 1.5, 0.5)));          // hull
    EXPECT_TRUE(shaded(Vec3(0, -1.8, 0.5)));         // mesh
    EXPECT_FALSE(shaded(Vec3(1.5, 0, 0)));           // between them
}

TEST(Renderer, WorldBoundsAreDrawnAsAGreyBox) {
    engine::WorldSettings settings;
    settings.bounds = collision::Aabb{Vec3::Constant(-2), Vec3::Constant(2)};
    engine::World world(settings);
    world.addBody(sphereBody("s", 0.3, Vec3::Zero()));
    world.detect();
    render::Renderer renderer(kWidth, kHeight);
    render::FrameOptions options = plainOptions();
    options.draw.bounds = true;
    const render::Image image = renderer.render(world, headOnCamera(), options);
    const engine::CameraSettings cam = headOnCamera();
    // The middle of the near top edge and of a near vertical edge.
    for (const Vec3& p : {Vec3(0, 2, 2), Vec3(2, 0, 2), Vec3(0, -2, -2)}) {
        const PixelPos px = project(cam, kWidth, kHeight, p);
        const bool grey = colorNear(image, px, {189, 194, 209}, 2, 50);
        EXPECT_TRUE(grey) << "no bounds line near " << px.x << "," << px.y;
    }
}

TEST(Renderer, VolumeSelectionControlsWhichWireframesAppear) {
    render::Renderer renderer(kWidth, kHeight);
    const engine::CameraSettings cam = headOnCamera();
    const Rgb green = toRgb(engine::stateColor(engine::BodyState::Apart));
    // The AABB corner of C lies outside its bounding sphere: green only when aabb is drawn.
    const PixelPos corner = project(cam, kWidth, kHeight, Vec3(3.6, 1, 1));
    render::FrameOptions options = plainOptions();
    options.draw.sphere = false;
    EXPECT_FALSE(colorNear(renderThreeSpheres(renderer, options), corner, green, 1));
    options.draw.aabb = true;
    EXPECT_TRUE(colorNear(renderThreeSpheres(renderer, options), corner, green, 1));
}

TEST(Renderer, HudTextChangesTopLeftPixelsOnly) {
    render::Renderer renderer(kWidth, kHeight);
    const render::Image plain = renderThreeSpheres(renderer);
    render::FrameOptions options = plainOptions();
    options.hud_text = "frame 12";
    const render::Image hud = renderThreeSpheres(renderer, options);
    int changed_top_left = 0;
    int changed_elsewhere = 0;
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            if (pixelAt(plain, x, y) == pixelAt(hud, x, y)) continue;
            (x < 70 && y < 20 ? changed_top_left : changed_elsewhere) += 1;
        }
    }
    EXPECT_GT(changed_top_left, 50);
    EXPECT_EQ(changed_elsewhere, 0);
}

TEST(Renderer, HudTextIsScaledUpFrom720p) {
    auto hudRows = [](int width, int height) {
        render::Renderer renderer(width, height);
        render::FrameOptions options = plainOptions();
        const render::Image plain = renderThreeSpheres(renderer, options);
        options.hud_text = "frame 1";
        const render::Image hud = renderThreeSpheres(renderer, options);
        int last_row = -1;
        for (int y = 0; y < height; ++y) {
            for (int x = 0; x < width / 4; ++x) {
                if (pixelAt(plain, x, y) != pixelAt(hud, x, y)) last_row = y;
            }
        }
        return last_row;
    };
    const int small = hudRows(640, 360);
    const int large = hudRows(1280, 720);
    EXPECT_GT(small, 0);
    EXPECT_GE(large, 2 * small - 2) << "720p text is not 2x";
}

TEST(Renderer, LegendAppearsBottomLeftWithTheHud) {
    render::Renderer renderer(kWidth, kHeight);
    render::FrameOptions options = plainOptions();
    const render::Image plain = renderThreeSpheres(renderer, options);
    options.draw.hud = true;
    const render::Image legend = renderThreeSpheres(renderer, options);
    int changed = 0;
    for (int y = kHeight - 20; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) changed += pixelAt(plain, x, y) != pixelAt(legend, x, y);
    }
    EXPECT_GT(changed, 50);
}

TEST(Renderer, RejectsNonPositiveSize) {
    EXPECT_THROW(render::Renderer(0, 10), render::RenderError);
    EXPECT_THROW(render::Renderer(10, -1), render::RenderError);
}

TEST(StateColor, MatchesTheDocumentedColours) {
    EXPECT_EQ(toRgb(engine::stateColor(engine::BodyState::Apart)), (Rgb{26, 217, 51}));
    EXPECT_EQ(toRgb(engine::stateColor(engine::BodyState::Flagged)), (Rgb{255, 217, 0}));
    EXPECT_EQ(toRgb(engine::stateColor(engine::BodyState::Colliding)), (Rgb{255, 26, 26}));
}

TEST(HudLine, ShowsFrameTimeBroadPhaseAndCounts) {
    const engine::World world = makeThreeSphereWorld();
    const engine::StepStats& st = world.lastStats();
    const std::string counters = "BV tests " + std::to_string(st.broad.volume_tests) +
                                 "  updated " + std::to_string(st.broad.volumes_updated) +
                                 "  narrow tests " + std::to_string(st.narrow_tests) +
                                 "  triangle tests " + std::to_string(st.triangle_tests);
    EXPECT_EQ(render::hudLine(world, 12, false),
              "frame 12  t=0.000 s  sap  flagged 1  colliding 1\n" + counters);
    EXPECT_EQ(st.narrow_tests, 1);  // the one flagged pair went to the narrow phase
    const std::string timed = render::hudLine(world, 12, true);
    EXPECT_EQ(
        timed.rfind("frame 12  t=0.000 s  sap  flagged 1  colliding 1\n" + counters + "\nstep ", 0),
        0u)
        << timed;
    EXPECT_EQ(timed.substr(timed.size() - 3), " ms");
}

// ---------------------------------------------------------------------------------------------

TEST(Png, WriteThenReadRoundTripsExactly) {
    RenderDir dir;
    render::Renderer renderer(kWidth, kHeight);
    render::FrameOptions options = plainOptions();
    options.hud_text = "round trip";
    const render::Image image = renderThreeSpheres(renderer, options);
    const fs::path file = dir.path() / "frame.png";
    render::writePng(file, image);
    ASSERT_TRUE(fs::exists(file));
    EXPECT_FALSE(fs::exists(dir.path() / "frame.png.partial"));
    const render::Image back = render::readPng(file);
    EXPECT_EQ(back.width, image.width);
    EXPECT_EQ(back.height, image.height);
    EXPECT_EQ(back.rgb, image.rgb);
}

TEST(Png, WritingIntoAMissingDirectoryThrows) {
    RenderDir dir;
    render::Image image;
    image.width = 4;
    image.height = 2;
    image.rgb.assign(4 * 2 * 3, 128);
    const fs::path file = dir.path() / "no_such_dir" / "frame.png";
    EXPECT_THROW(render::writePng(file, image), render::RenderError);
    EXPECT_FALSE(fs::exists(file));
}

TEST(Png, WritingAMalformedImageThrows) {
    RenderDir dir;
    render::Image image;
    image.width = 4;
    image.height = 2;
    image.rgb.assign(5, 0);
    EXPECT_THROW(render::writePng(dir.path() / "bad.png", image), render::RenderError);
    EXPECT_FALSE(fs::exists(dir.path() / "bad.png"));
}

TEST(Png, ReadingAMissingOrBrokenFileThrows) {
    RenderDir dir;
    EXPECT_THROW(render::readPng(dir.path() / "missing.png"), render::RenderError);
    const fs::path junk = dir.path() / "junk.png";
    std::ofstream(junk) << "not a png";
    EXPECT_THROW(render::readPng(junk), render::RenderError);
}

// ---------------------------------------------------------------------------------------------

TEST(Video, TenFramesMakeANonEmptyMp4) {
    if (!render::ffmpegAvailable()) GTEST_SKIP() << "ffmpeg not on PATH";
    RenderDir dir;
    engine::World world = makeThreeSphereWorld();
    render::Renderer renderer(kWidth, kHeight);
    const fs::path file = dir.path() / "clip.mp4";
    {
        render::VideoWriter video(file, kWidth, kHeight, 30);
        for (int frame = 0; frame < 10; ++frame) {
            render::FrameOptions options = plainOptions();
            options.hud_text = render::hudLine(world, frame, false);
            video.addFrame(renderer.render(world, headOnCamera(), options));
            world.step();
        }
        EXPECT_FALSE(fs::exists(file)) << "visible before finish()";
        video.finish();
    }
    ASSERT_TRUE(fs::exists(file));
    EXPECT_GT(fs::file_size(file), 1000u);
    EXPECT_FALSE(fs::exists(dir.path() / "clip.partial.mp4"));
    // An MP4 starts with an 'ftyp' box.
    std::ifstream in(file, std::ios::binary);
    char head[8] = {};
    in.read(head, 8);
    EXPECT_EQ(std::string(head + 4, 4), "ftyp");
}

// Every container of supportedVideoExtensions() is written with a codec it holds (the raw H.264
// stream into a .webm or .gif used to fail inside ffmpeg): WebM starts with the EBML magic, GIF
// with its signature; an odd size is fine for GIF (no chroma subsampling).
TEST(Video, WebmAndGifAreWritten) {
    if (!render::ffmpegAvailable()) GTEST_SKIP() << "ffmpeg not on PATH";
    RenderDir dir;
    render::Renderer renderer(kWidth, kHeight);
    const render::Image frame = renderThreeSpheres(renderer);
    for (const char* name : {"clip.webm", "clip.gif", "clip.mkv", "clip.mov"}) {
        const fs::path file = dir.path() / name;
        {
            render::VideoWriter video(file, kWidth, kHeight, 30);
            for (int i = 0; i < 5; ++i) video.addFrame(frame);
            video.finish();
        }
        ASSERT_TRUE(fs::exists(file)) << name;
        EXPECT_GT(fs::file_size(file), 100u) << name;
    }
    std::ifstream webm(dir.path() / "clip.webm", std::ios::binary);
    unsigned char ebml[4] = {};
    webm.read(reinterpret_cast<char*>(ebml), 4);
    EXPECT_EQ(ebml[0], 0x1A);
    EXPECT_EQ(ebml[1], 0x45);
    EXPECT_EQ(ebml[2], 0xDF);
    EXPECT_EQ(ebml[3], 0xA3);
    std::ifstream gif(dir.path() / "clip.gif", std::ios::binary);
    char sig[6] = {};
    gif.read(sig, 6);
    EXPECT_EQ(std::string(sig, 3), "GIF");
    EXPECT_NO_THROW(render::VideoWriter(dir.path() / "odd.gif", 161, 121, 30));
}

TEST(Video, UnsupportedContainerIsRefusedWithTheList) {
    RenderDir dir;
    try {
        render::VideoWriter video(dir.path() / "clip.avi", kWidth, kHeight, 30);
        FAIL() << "no error for .avi";
    } catch (const render::RenderError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("unsupported video container '.avi'"), std::string::npos) << what;
        EXPECT_NE(what.find(".webm"), std::string::npos) << what;
    }
    EXPECT_FALSE(render::isSupportedVideoFile("x.avi"));
    EXPECT_TRUE(render::isSupportedVideoFile("x.gif"));
    EXPECT_TRUE(render::isSupportedVideoFile("x"));  // no extension: mp4
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(Video, AnUnfinishedVideoLeavesNoFile) {
    if (!render::ffmpegAvailable()) GTEST_SKIP() << "ffmpeg not on PATH";
    RenderDir dir;
    const fs::path file = dir.path() / "abandoned.mp4";
    {
        render::VideoWriter video(file, kWidth, kHeight, 30);
        render::Renderer renderer(kWidth, kHeight);
        video.addFrame(renderThreeSpheres(renderer));
    }
    EXPECT_FALSE(fs::exists(file));
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(Video, OddSizeOrWrongFrameSizeThrows) {
    if (!render::ffmpegAvailable()) GTEST_SKIP() << "ffmpeg not on PATH";
    RenderDir dir;
    EXPECT_THROW(render::VideoWriter(dir.path() / "odd.mp4", 161, 120, 30), render::RenderError);
    EXPECT_THROW(render::VideoWriter(dir.path() / "fps.mp4", 160, 120, 0), render::RenderError);
    render::VideoWriter video(dir.path() / "size.mp4", 160, 120, 30);
    render::Image small;
    small.width = 2;
    small.height = 2;
    small.rgb.assign(12, 0);
    EXPECT_THROW(video.addFrame(small), render::RenderError);
}

// Writes 50 uniform frames (2.9 MB), far past the 64 KiB a pipe buffers, so a reader that died
// or stopped reading is met by addFrame.
void feedPastThePipeBuffer(render::VideoWriter& video) {
    render::Image frame;
    frame.width = kWidth;
    frame.height = kHeight;
    frame.rgb.assign(std::size_t(kWidth) * kHeight * 3, 7);
    for (int i = 0; i < 50; ++i) video.addFrame(frame);
}

// Regression guard for SIGPIPE: an ffmpeg that dies at once must turn into a RenderError, not
// kill the test process when we write into its closed pipe.
//
//   us --frames--> [pipe] --x  fake "ffmpeg" (exit 3)
TEST(Video, AnFfmpegThatDiesBecomesARenderError) {
    RenderDir dir;
    const cdlab_test::DeadFfmpegOnPath dead_ffmpeg(dir.path());
    bool threw = false;
    try {
        render::VideoWriter video(dir.path() / "dead.mp4", kWidth, kHeight, 30);
        feedPastThePipeBuffer(video);
        video.finish();
    } catch (const render::RenderError&) {
        threw = true;
    }
    EXPECT_TRUE(threw);
    EXPECT_FALSE(fs::exists(dir.path() / "dead.mp4"));
    EXPECT_FALSE(fs::exists(dir.path() / "dead.partial.mp4"));
}

// Regression: an ffmpeg that stops reading hung the run forever (blocking writes, no timeout).
// A fake "ffmpeg" that never reads, and one that reads everything but never exits: each is a
// RenderError after the stall timeout (here 300 ms), and no output is left behind.
//
//   us --frames--> [pipe, 64 KiB] --x  "exec sleep 30"          (addFrame stalls)
//   us --frames--> [pipe] --> "cat > /dev/null; exec sleep 30"  (finish stalls)
TEST(Video, AStalledFfmpegIsAnErrorAfterTheTimeout) {
    const char* scripts[] = {"#!/bin/sh\nexec sleep 30\n",
                             "#!/bin/sh\ncat > /dev/null\nexec sleep 30\n"};
    const char* old_path = std::getenv("PATH");
    const std::string saved = old_path ? old_path : "";
    for (const char* script : scripts) {
        SCOPED_TRACE(script);
        RenderDir dir;
        const fs::path fake = dir.path() / "ffmpeg";
        std::ofstream(fake) << script;
        fs::permissions(fake, fs::perms::owner_all);
        ::setenv("PATH", (dir.path().string() + ":" + saved).c_str(), 1);
        std::string message;
        const auto start = std::chrono::steady_clock::now();
        try {
            render::VideoWriter video(dir.path() / "stalled.mp4", kWidth, kHeight, 30,
                                      std::chrono::milliseconds(300));
            feedPastThePipeBuffer(video);
            video.finish();
        } catch (const render::RenderError& e) {
            message = e.what();
        }
        ::setenv("PATH", saved.c_str(), 1);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_NE(message.find("(stalled encoder; the video was abandoned)"), std::string::npos)
            << message;
        EXPECT_LT(seconds, 10);
        EXPECT_FALSE(fs::exists(dir.path() / "stalled.mp4"));
        EXPECT_FALSE(fs::exists(dir.path() / "stalled.partial.mp4"));
    }
}

}  // namespace

namespace {

// Two interlocked tori, A in the xy plane at the origin and B standing in the xz plane with its
// centre at x = 1.3, so B's inner tube cuts A's tube near x = 0.65..0.8 (both sides of z = 0):
//
//        y                    camera at (0.4, 0.3, 7) looking at (0.4, 0, 0)
//        |  ___A___
//        | /   |B  \          B seen edge-on: the vertical bar |B, from x = 0.5 to 2.1
//   -----+-----|----+-------- x
//
engine::World makeTwoTorusWorld() {
    engine::WorldSettings settings;
    settings.bounds = collision::Aabb{Vec3::Constant(-20), Vec3::Constant(20)};
    engine::World world(settings);
    auto meshShape = [](collision::TriangleMesh m) {
        auto mesh = std::make_shared<collision::TriangleMesh>(std::move(m));
        const collision::ConvexHullOutput hull = collision::computeConvexHull(mesh->vertices);
        return collision::Shape::triangleMesh(
            mesh, std::make_shared<const collision::ConvexPolytope>(hull.hull));
    };
    world.addBody(
        makeShapeBody("a", meshShape(cdlab_test::makeTorusMesh(1.0, 0.35, 48, 16)), Vec3::Zero()));
    const Quat b_rot = Quat(Eigen::AngleAxis<Real>(0.12, Vec3::UnitZ())) *
                       Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitX()));
    world.addBody(makeShapeBody("b", meshShape(cdlab_test::makeTorusMesh(0.8, 0.3, 40, 15)),
                                Vec3(1.3, 0, 0), b_rot));
    world.detect();
    return world;
}

engine::CameraSettings torusCamera() {
    engine::CameraSettings camera;
    camera.position = Vec3(0.4, 0.3, 7);
    camera.look_at = Vec3(0.4, 0, 0);
    return camera;
}


}  // namespace

// draw.bvh_depth: every node of the cut is drawn as its box in its state's colour. The states
// come from collision::markBvhLevels (tested against brute force in bvh_level_test); here the
// pixels at each node's box corners must take that colour, for nodes of all three states.
TEST(Renderer, HierarchyLevelNodesTakeTheirStateColour) {
    const engine::World world = makeTwoTorusWorld();
    ASSERT_EQ(world.collidingPairs().size(), 1u);
    constexpr int kW = 320;
    constexpr int kH = 240;
    render::Renderer renderer(kW, kH);
    render::FrameOptions options = plainOptions();
    options.draw.bodies = false;
    options.draw.sphere = false;
    options.draw.bvh_depth = 2;
    const render::Image image = renderer.render(world, torusCamera(), options);

    const auto bodies = world.bodies();
    collision::BvhLevel la = collision::makeBvhLevel(*bodies[0].shape.bvh, 2);
    collision::BvhLevel lb = collision::makeBvhLevel(*bodies[1].shape.bvh, 2);
    collision::markBvhLevels(la, *bodies[0].shape.bvh, bodies[0].pose(), lb, *bodies[1].shape.bvh,
                             bodies[1].pose(),
                             collision::collidingTrianglePairs(bodies[0].shape, bodies[0].pose(),
                                                               bodies[1].shape, bodies[1].pose()));
    int seen[3] = {0, 0, 0};
    for (const auto& [level, body] : {std::pair{&la, &bodies[0]}, std::pair{&lb, &bodies[1]}}) {
        for (std::size_t k = 0; k < level->nodes.size(); ++k) {
            const collision::BvhNodeState state = level->states[k];
            const Rgb color = toRgb(engine::nodeColor(state));
            const collision::Obb box = collision::transformObb(level->nodes[k].box, body->pose());
            Vec3 corners[8];
            box.corners(corners);
            int hits = 0;
            for (const Vec3& c : corners) {
                hits += colorNear(image, project(torusCamera(), kW, kH, c), color, 2, 60);
            }
            // Corners can be covered by other nodes' lines; most of them show the colour.
            EXPECT_GE(hits, 5) << "node " << k << " state " << int(state);
            ++seen[int(state)];
        }
    }
    EXPECT_GT(seen[0], 0);  // apart
    EXPECT_GT(seen[1], 0);  // overlapping at that level only
    EXPECT_GT(seen[2], 0);  // holding a confirmed triangle
    EXPECT_EQ(countColor(image, toRgb(engine::kContactColor)), 0);

    // Off: no node is drawn, so none of the state colours appears (bodies and volumes are off).
    options.draw.bvh_depth = -1;
    const render::Image off = renderer.render(world, torusCamera(), options);
    for (const auto s : {collision::BvhNodeState::Apart, collision::BvhNodeState::Overlapping,
                         collision::BvhNodeState::Confirmed}) {
        EXPECT_EQ(countColor(off, toRgb(engine::nodeColor(s))), 0);
    }
}

// draw.contacts: a magenta cross at the witness points of the confirmed triangle pairs, none
// without the key; the same state renders bit-identical frames with both overlays on.
TEST(Renderer, ContactWitnessesAreDrawnInMagentaAndFramesAreDeterministic) {
    const engine::World world = makeTwoTorusWorld();
    constexpr int kW = 320;
    constexpr int kH = 240;
    render::Renderer renderer(kW, kH);
    render::FrameOptions options = plainOptions();
    options.draw.sphere = false;
    options.draw.contacts = true;
    const Rgb magenta = toRgb(engine::kContactColor);
    const render::Image image = renderer.render(world, torusCamera(), options);
    const auto bodies = world.bodies();
    const auto witnesses = collision::contactWitnesses(bodies[0].shape, bodies[0].pose(),
                                                       bodies[1].shape, bodies[1].pose());
    ASSERT_FALSE(witnesses.empty());
    int near = 0;
    for (const auto& w : witnesses) {
        near += colorNear(image, project(torusCamera(), kW, kH, w.point_a), magenta, 2, 60);
    }
    // Witnesses on the far side of a body are drawn faintly (x-ray): most are in front.
    EXPECT_GT(near, int(witnesses.size()) / 2);
    EXPECT_GT(countColor(image, magenta), 20);
    options.draw.contacts = false;
    EXPECT_EQ(countColor(renderer.render(world, torusCamera(), options), magenta), 0);

    options.draw.contacts = true;
    options.draw.bvh_depth = 3;
    const render::Image first = renderer.render(world, torusCamera(), options);
    const render::Image second = renderer.render(makeTwoTorusWorld(), torusCamera(), options);
    EXPECT_EQ(first.rgb, second.rgb);
}

// CCD: the pose at the time of impact is drawn in blue in the frame of the step that acted on
// it, and nothing is blue in a frame without events. The bar of tunnel_bar_ccd.yaml first hits
// the wall in step 3 (t = 0.072 s), not in step 1.
TEST(Renderer, TimeOfImpactPoseIsDrawnInBlue) {
    const engine::Scene scene =
        engine::loadScene(fs::path(CDLAB_SOURCE_DIR) / "scenes" / "tunnel_bar_ccd.yaml");
    engine::World world = engine::makeWorld(scene);
    render::Renderer renderer(320, 180);
    render::FrameOptions options;
    options.draw = scene.draw;
    const Rgb blue = toRgb(engine::kToiColor);
    auto countBlue = [&blue](const render::Image& image) {
        int n = 0;
        for (int y = 0; y < image.height; ++y) {
            for (int x = 0; x < image.width; ++x) n += close(pixelAt(image, x, y), blue, 40);
        }
        return n;
    };
    world.step();
    ASSERT_TRUE(world.toiEvents().empty());
    EXPECT_EQ(countBlue(renderer.render(world, scene.camera, options)), 0);
    for (int i = 1; i < 30 && world.toiEvents().empty(); ++i) world.step();
    ASSERT_FALSE(world.toiEvents().empty());
    EXPECT_GT(countBlue(renderer.render(world, scene.camera, options)), 50);
}

// screenRect() is where render() draws: a turned box's AABB wireframe (the only thing drawn)
// fills exactly the rectangle screenRect() gives for that AABB, to within the line's width.
TEST(Renderer, ScreenRectIsWhereTheAabbIsDrawn) {
    engine::World world(engine::WorldSettings{});
    world.addBody(
        makeShapeBody("box", collision::Shape::box(Vec3(1.2, 0.5, 0.7)), Vec3(1.5, -0.8, 1),
                      Quat(Eigen::AngleAxis<Real>(Real(0.6), Vec3(1, 2, 3).normalized()))));
    world.detect();
    engine::CameraSettings camera = headOnCamera();
    camera.position = Vec3(2, 3, 9);
    render::FrameOptions options = plainOptions();
    options.draw.bodies = false;
    options.draw.sphere = false;
    options.draw.aabb = true;
    render::Renderer renderer(kWidth, kHeight);
    const render::Image image = renderer.render(world, camera, options);
    const Rgb green = toRgb(engine::stateColor(engine::BodyState::Apart));
    int x0 = kWidth, y0 = kHeight, x1 = -1, y1 = -1;
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            if (!close(pixelAt(image, x, y), green, 60)) continue;
            x0 = std::min(x0, x);
            y0 = std::min(y0, y);
            x1 = std::max(x1, x + 1);
            y1 = std::max(y1, y + 1);
        }
    }
    ASSERT_GE(x1, 0) << "nothing drawn";
    const collision::Aabb& box = world.volumes()[0].aabb;
    const std::optional<render::ScreenRect> rect =
        render::screenRect(camera, kWidth, kHeight, box.min, box.max);
    ASSERT_TRUE(rect.has_value());
    EXPECT_NEAR(rect->x0, x0, 1.5);
    EXPECT_NEAR(rect->y0, y0, 1.5);
    EXPECT_NEAR(rect->x1, x1, 1.5);
    EXPECT_NEAR(rect->y1, y1, 1.5);
    // Behind the camera: no rectangle.
    EXPECT_FALSE(render::screenRect(camera, kWidth, kHeight, Vec3(0, 0, 20), Vec3(1, 1, 21)));
}
