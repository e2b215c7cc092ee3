// app/lab/checkers.h -- the graders of `cdlab check`: one Checker per kind of expectation of a scene's
// `expect:` section (engine/scene.h). Each watches the same single run through the same hooks and
// then writes its rows; checkScene (check.cpp) runs them. Frame 0 is the initial state,
// frame k is after k * steps_per_frame steps.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine/scene.h"
#include "engine/world.h"
#include "render/renderer.h"

namespace app {

/// One graded expectation of one scene.
struct CheckRow {
    std::string expectation;  ///< e.g. "pair ball0-crate1 colliding in 10..20 (every)"
    bool pass = false;
    std::string reason;  ///< why it failed (empty on pass); may carry a measured value
};

/// What every checker sees of the run: the scene, the world as it runs, the frames the run has,
/// where pause dumps go, and one renderer made the first time a checker asks for it.
class CheckRun {
public:
    CheckRun(const engine::Scene& scene_in, const engine::World& world_in, int frames_in,
             std::filesystem::path dump_dir_in)
        : scene(scene_in), world(world_in), frames(frames_in), dump_dir(std::move(dump_dir_in)) {}

    const engine::Scene& scene;
    const engine::World& world;
    const int frames;
    const std::filesystem::path dump_dir;

    render::Renderer& renderer();

private:
    std::unique_ptr<render::Renderer> renderer_;
};

class Checker {
public:
    virtual ~Checker() = default;
    /// Once at frame 0 (no step yet: `step_start` empty), then after every step, with the
    /// simulated time the step started at.
    virtual void observeStep(CheckRun& run, int frame, std::optional<double> step_start) {
        (void)run;
        (void)frame;
        (void)step_start;
    }
    /// After frame 0 and after the last step of every later frame.
    virtual void observeFrame(CheckRun& run, int frame) {
        (void)run;
        (void)frame;
    }
    /// This kind's rows, in the order of the scene file.
    virtual void report(const CheckRun& run, std::vector<CheckRow>& rows) const = 0;
};

/// The checkers of `scene.expect`, in the order their rows are printed: bodies, moving and
/// rotating, broad phases, energy, tunnelling, times of impact, rest, pause dumps, pairs,
/// colours. `world` is the run's world before its first step (checkers take their start state
/// from it).
std::vector<std::unique_ptr<Checker>> makeCheckers(const engine::Scene& scene,
                                                   const engine::World& world);

}  // namespace app
