// tests/render/snapshot_test.cpp -- World::snapshot and restore on every shipped scene: a world
// restored to a snapshot and stepped on gives the same states, pairs, counters and pictures as
// one that never stopped, frame by frame. The pictures draw every proxy volume (each by its own
// test), the broad phase's structure and the contacts over the scene's own settings, and the HUD
// prints the step's counters, so coherence state a snapshot missed shows up as a pixel.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/scene.h"
#include "engine/volume_overlaps.h"
#include "engine/world.h"
#include "render/image.h"
#include "render/occlusion_oracle.h"
#include "render/renderer.h"
#include "shipped_scenes.h"

namespace {

constexpr int kWidth = 160;
constexpr int kHeight = 90;
constexpr int kLastFrame = 9;
constexpr int kSnapshotFrames[] = {1, 5};

/// What a frame of a run shows and holds.
struct FrameRecord {
    std::uint64_t hash = 0;
    std::vector<collision::ProxyPair> flagged;
    std::vector<collision::ProxyPair> colliding;
    std::string hud;
    std::vector<std::uint8_t> pixels;
};

class Recorder {
public:
    explicit Recorder(const engine::Scene& scene) : scene_(scene), renderer_(kWidth, kHeight) {}

    FrameRecord record(const engine::World& world, int frame) {
        render::FrameOptions options;
        options.draw = engine::drawSettingsFor(scene_.draw, world);
        options.draw.sphere = options.draw.aabb = options.draw.obb = true;
        options.draw.contacts = true;
        options.draw_structure = true;
        options.hud_text = render::hudLine(world, frame, false);
        FrameRecord r;
        r.hash = world.stateHash();
        r.flagged.assign(world.flaggedPairs().begin(), world.flaggedPairs().end());
        r.colliding.assign(world.collidingPairs().begin(), world.collidingPairs().end());
        r.hud = options.hud_text;
        r.pixels = renderer_.render(world, scene_.camera, options).rgb;
        return r;
    }

    /// Steps `world` from `frame` to kLastFrame, recording each frame after `frame`.
    std::vector<FrameRecord> run(engine::World& world, int frame) {
        std::vector<FrameRecord> out;
        for (int f = frame + 1; f <= kLastFrame; ++f) {
            for (int s = 0; s < scene_.steps_per_frame; ++s) world.step();
            out.push_back(record(world, f));
        }
        return out;
    }

private:
    const engine::Scene& scene_;
    render::Renderer renderer_;
};

void expectSameFrames(const std::vector<FrameRecord>& want, const std::vector<FrameRecord>& got,
                      int from) {
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
        const int frame = from + 1 + int(i);
        EXPECT_EQ(got[i].hash, want[i].hash) << "frame " << frame;
        EXPECT_EQ(got[i].flagged, want[i].flagged) << "frame " << frame;
        EXPECT_EQ(got[i].colliding, want[i].colliding) << "frame " << frame;
        EXPECT_EQ(got[i].hud, want[i].hud) << "frame " << frame;
        EXPECT_TRUE(got[i].pixels == want[i].pixels) << "frame " << frame << " differs";
    }
}

class Snapshot : public ::testing::Test {
protected:
    void SetUp() override { render::installOcclusionQueryOracle(); }  // cullide.yaml
};

TEST_F(Snapshot, RestoreAndStepGivesTheFramesOfARunThatNeverStopped) {
    std::vector<std::filesystem::path> scenes;
    for (const auto& e : std::filesystem::directory_iterator(cdlab_test::kScenes)) {
        if (e.path().extension() == ".yaml") scenes.push_back(e.path());
    }
    std::sort(scenes.begin(), scenes.end());
    ASSERT_GE(scenes.size(), 15u);
    for (const std::filesystem::path& file : scenes) {
        SCOPED_TRACE(file.filename().string());
        const engine::Scene scene = engine::loadScene(file);
        Recorder recorder(scene);
        engine::World world = engine::makeWorld(scene);
        std::vector<FrameRecord> straight;
        std::vector<engine::WorldSnapshot> snapshots;
        for (int f = 1; f <= kLastFrame; ++f) {
            if (std::find(std::begin(kSnapshotFrames), std::end(kSnapshotFrames), f - 1) !=
                std::end(kSnapshotFrames)) {
                snapshots.push_back(world.snapshot());
            }
            for (int s = 0; s < scene.steps_per_frame; ++s) world.step();
            straight.push_back(recorder.record(world, f));
        }
        ASSERT_EQ(snapshots.size(), std::size(kSnapshotFrames));
        for (std::size_t k = 0; k < snapshots.size(); ++k) {
            const int from = kSnapshotFrames[k];
            SCOPED_TRACE("restored at frame " + std::to_string(from));
            EXPECT_EQ(snapshots[k].steps(), std::int64_t(from) * scene.steps_per_frame);
            const std::vector<FrameRecord> want(straight.begin() + from, straight.end());
            // The same world, put back from its last frame...
            world.restore(snapshots[k]);
            expectSameFrames(want, recorder.run(world, from), from);
            // ...and a fresh world of the scene, taking everything from the snapshot.
            engine::World fresh = engine::makeWorld(scene);
            fresh.restore(snapshots[k]);
            expectSameFrames(want, recorder.run(fresh, from), from);
        }
    }
}

TEST_F(Snapshot, ASnapshotIsNotChangedByTheWorldSteppingOn) {
    // A deforming mesh changes its vertices and hierarchy in place: the snapshot keeps its own,
    // and so does every world restored from it.
    const engine::Scene scene = engine::loadScene(cdlab_test::kScenes / "deform_self.yaml");
    engine::World world = engine::makeWorld(scene);
    for (int s = 0; s < 3; ++s) world.step();
    auto meshVertices = [](const engine::World& w) {
        std::vector<collision::Vec3> out;
        for (const engine::Body& b : w.bodies()) {
            if (b.deform && b.shape.mesh) {
                out.insert(out.end(), b.shape.mesh->vertices.begin(), b.shape.mesh->vertices.end());
            }
        }
        return out;
    };
    const std::vector<collision::Vec3> vertices = meshVertices(world);
    ASSERT_FALSE(vertices.empty());
    Recorder recorder(scene);
    const FrameRecord picture = recorder.record(world, 3);
    const engine::WorldSnapshot at3 = world.snapshot();

    for (int s = 0; s < 20; ++s) world.step();  // the original moves its own meshes on
    ASSERT_NE(meshVertices(world), vertices);
    engine::World other = engine::makeWorld(scene);
    other.restore(at3);
    EXPECT_EQ(meshVertices(other), vertices);
    EXPECT_TRUE(recorder.record(other, 3).pixels == picture.pixels);
    engine::World again = engine::makeWorld(scene);
    again.restore(at3);
    for (int s = 0; s < 5; ++s) again.step();  // a second restored world is apart from the first
    EXPECT_EQ(meshVertices(other), vertices);
}

TEST_F(Snapshot, AnEmptySnapshotIsRefused) {
    const engine::Scene scene = engine::loadScene(cdlab_test::kScenes / "coursework.yaml");
    engine::World world = engine::makeWorld(scene);
    const std::uint64_t hash = world.stateHash();
    EXPECT_THROW(world.restore(engine::WorldSnapshot{}), std::invalid_argument);
    EXPECT_EQ(world.stateHash(), hash);
}

}  // namespace
