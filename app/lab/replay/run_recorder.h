// app/lab/replay/run_recorder.h -- `cdlab run --record FILE` and the scene of a recording: the
// recording's header from the run's scene and flags, its frames written as the run first
// reaches them, and the same scene loaded again (and proven the same) to show or check it.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/demo_commands.h"
#include "engine/recording.h"
#include "engine/scene.h"
#include "engine/world.h"

namespace app {

/// Why a run of `scene` following `events` cannot be recorded, or "": with pair_order: found a
/// broad-phase switch changes the order of the pairs and so the motion, which `cdlab replay
/// --check` (the scene simulated again, without the events) could not reproduce.
std::string recordRefusal(const engine::Scene& scene, const std::vector<engine::DemoEvent>& events);

/// Writes the frames of a run as it reaches them: frame 0 at construction, then frame k the
/// first time the world is at step k * steps_per_frame (a session that goes back and steps
/// forward again re-simulates frames it already wrote; those are not written twice).
class RunRecorder {
public:
    /// Creates the file (engine::RecordingWriter) and writes `world` as frame 0.
    RunRecorder(const std::filesystem::path& file, const engine::RecordingHeader& header,
                const engine::World& world);
    /// After every step of the world.
    void observe(const engine::World& world);
    /// The end record: `ended` is "" for a run that completed, else why it stopped.
    void finish(const std::string& ended = "");
    /// "recorded N frames to FILE (B bytes, X bytes per body per frame)".
    std::string summary() const;

private:
    engine::RecordingWriter writer_;
    int steps_per_frame_ = 1;
    std::size_t bodies_ = 0;
};

/// The scene a recording was made of, loaded again: its file (or `scene_file`, for one moved
/// since) with the recorded overrides, frames, broad phase and pair order. Throws
/// engine::SceneError for a scene that no longer loads and engine::RecordingError when the file's
/// hash, body or chain count, steps per frame or time step is not the recorded one.
engine::Scene loadRecordedScene(const engine::Recording& recording,
                                const std::optional<std::filesystem::path>& scene_file);

}  // namespace app
