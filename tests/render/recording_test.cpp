// tests/render/recording_test.cpp -- a recorded frame placed in a fresh world of its scene
// (World::place) is the frame the run showed, on every shipped scene: the same state hash,
// pairs, HUD (the recorded step's counters) and picture, with every proxy volume, the contacts
// and the broad phase's structure drawn, whatever order the frames are visited in.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/recording.h"
#include "engine/scene.h"
#include "engine/volume_overlaps.h"
#include "engine/world.h"
#include "render/image.h"
#include "render/occlusion_oracle.h"
#include "render/renderer.h"
#include "shipped_scenes.h"

namespace recording_test {

namespace fs = std::filesystem;

constexpr int kWidth = 160;
constexpr int kHeight = 90;
constexpr int kFrames = 10;

struct Shown {
    std::uint64_t hash = 0;
    std::vector<collision::ProxyPair> flagged;
    std::vector<collision::ProxyPair> colliding;
    std::string hud;
    std::vector<std::uint8_t> pixels;
};

// Every proxy volume, the contacts, the scene's own layers (hierarchy cuts included: a
// deforming mesh's, refitted from wherever the placed world had it, equals the run's while
// neither rebuilt it) and the broad phase's structure (rebuilt from the placed volumes).
Shown show(render::Renderer& renderer, const engine::Scene& scene, const engine::World& world,
           int frame) {
    render::FrameOptions options;
    options.draw = engine::drawSettingsFor(scene.draw, world);
    options.draw.sphere = options.draw.aabb = options.draw.obb = true;
    options.draw.contacts = true;
    options.draw_structure = true;
    options.hud_text = render::hudLine(world, frame, false);
    Shown s;
    s.hash = world.stateHash();
    s.flagged.assign(world.flaggedPairs().begin(), world.flaggedPairs().end());
    s.colliding.assign(world.collidingPairs().begin(), world.collidingPairs().end());
    s.hud = options.hud_text;
    s.pixels = renderer.render(world, scene.camera, options).rgb;
    return s;
}

std::vector<fs::path> shippedScenes() {
    std::vector<fs::path> scenes;
    for (const auto& e : fs::directory_iterator(cdlab_test::kScenes)) {
        if (e.path().extension() == ".yaml") scenes.push_back(e.path());
    }
    std::sort(scenes.begin(), scenes.end());
    return scenes;
}

class Recording : public ::testing::Test {
protected:
    void SetUp() override { render::installOcclusionQueryOracle(); }  // cullide.yaml
};

TEST_F(Recording, APlacedFrameIsTheFrameTheRunShowed) {
    const std::vector<fs::path> scenes = shippedScenes();
    ASSERT_GE(scenes.size(), 15u);
    const fs::path dir = fs::temp_directory_path() / "cdlab_recording_test";
    fs::create_directories(dir);
    render::Renderer renderer(kWidth, kHeight);
    for (const fs::path& file : scenes) {
        SCOPED_TRACE(file.filename().string());
        const engine::Scene scene = engine::loadScene(file);
        const fs::path rec_file = dir / (file.stem().string() + ".rec");
        std::vector<Shown> run;
        {
            engine::World world = engine::makeWorld(scene);
            engine::RecordingWriter writer(rec_file, engine::recordingHeader(file, {}, scene));
            for (int f = 0; f < kFrames; ++f) {
                if (f > 0) {
                    for (int s = 0; s < scene.steps_per_frame; ++s) world.step();
                }
                writer.write(engine::recordFrame(world, f));
                run.push_back(show(renderer, scene, world, f));
            }
            writer.finish();
        }
        const engine::Recording recording = engine::Recording::open(rec_file);
        ASSERT_EQ(recording.frames(), kFrames);
        EXPECT_EQ(recording.ended(), "");
        engine::World placed = engine::makeWorld(scene);
        for (const int f : {7, 0, 9, 3, 4, 8, 1, 2, 6, 5, 5}) {
            SCOPED_TRACE("frame " + std::to_string(f));
            const engine::RecordedFrame rec = recording.frame(f);
            placed.place(rec.state, rec.impacts, rec.counters);
            const Shown got = show(renderer, scene, placed, f);
            const Shown& want = run[std::size_t(f)];
            EXPECT_EQ(got.hash, want.hash);
            EXPECT_EQ(rec.state_hash, want.hash);
            EXPECT_EQ(got.flagged, want.flagged);
            EXPECT_EQ(got.colliding, want.colliding);
            EXPECT_EQ(got.hud, want.hud);
            EXPECT_TRUE(got.pixels == want.pixels) << "the picture differs";
        }
        fs::remove(rec_file);
    }
}

}  // namespace recording_test
