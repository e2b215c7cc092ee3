// app/lab/replay/run_recorder.cpp -- see run_recorder.h.
#include "replay/run_recorder.h"

#include <cstdio>

namespace app {

namespace fs = std::filesystem;

std::string recordRefusal(const engine::Scene& scene, const std::vector<engine::DemoEvent>& events) {
    if (scene.world.pair_order != collision::PairOrder::Found) return "";
    for (const engine::DemoEvent& e : events) {
        if (e.commands.broad_phase && *e.commands.broad_phase != scene.world.broad_phase) {
            return "the events switch the broad phase (line " + std::to_string(e.line) +
                   ") and the pairs come in found order, so the motion follows the broad phase "
                   "and could not be checked against the scene alone (use pair_order: sorted)";
        }
    }
    return "";
}

RunRecorder::RunRecorder(const fs::path& file, const engine::RecordingHeader& header,
                         const engine::World& world)
    : writer_(file, header), steps_per_frame_(header.steps_per_frame), bodies_(header.bodies) {
    writer_.write(engine::recordFrame(world, 0));
}

void RunRecorder::observe(const engine::World& world) {
    if (world.stepCount() % steps_per_frame_ != 0) return;
    const std::int64_t frame = world.stepCount() / steps_per_frame_;
    if (frame == writer_.frames()) writer_.write(engine::recordFrame(world, int(frame)));
}

void RunRecorder::finish(const std::string& ended) { writer_.finish(ended); }

std::string RunRecorder::summary() const {
    const double per_body =
        double(writer_.bytes()) / (double(writer_.frames()) * double(std::max<std::size_t>(bodies_, 1)));
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.1f", per_body);
    return "recorded " + std::to_string(writer_.frames()) + " frames to " +
           writer_.file().string() + " (" + std::to_string(writer_.bytes()) + " bytes, " +
           buffer + " bytes per body per frame)";
}

engine::Scene loadRecordedScene(const engine::Recording& recording,
                                const std::optional<fs::path>& scene_file) {
    const engine::RecordingHeader& h = recording.header();
    const fs::path file = scene_file ? *scene_file : h.scene;
    const std::string name = recording.file().string();
    std::uint64_t hash = 0;
    try {
        hash = engine::fileHash(file);
    } catch (const engine::RecordingError&) {
        throw engine::RecordingError(name + ": its scene " + file.string() +
                                     " cannot be read (moved? --scene FILE names it)");
    }
    if (hash != h.scene_hash) {
        throw engine::RecordingError(name + ": its scene " + file.string() +
                                     " has changed since it was recorded (its bytes' hash differs)");
    }
    engine::Scene scene = engine::loadScene(file, h.overrides);
    scene.frames = h.frames;
    scene.world.broad_phase = h.broad_phase;
    scene.world.pair_order = h.pair_order;
    if (scene.bodies.size() != h.bodies || scene.chains.size() != h.chains ||
        scene.steps_per_frame != h.steps_per_frame || scene.world.time_step != h.time_step ||
        collision::findBroadPhase(h.broad_phase) == nullptr) {
        throw engine::RecordingError(name + ": its scene " + file.string() +
                                     " loads to other bodies, chains or timing than recorded");
    }
    return scene;
}

}  // namespace app
