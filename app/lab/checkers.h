// app/lab/checkers.h -- the graders of `cdlab check`: one Checker per kind of expectation of a scene's
// `expect:` section (engine/scene.h). Each watches the same single run through the same hooks and
// then writes its rows; checkScene (check.cpp) runs them. Frame 0 is the initial state,
// frame k is after k * steps_per_frame steps. A run through an events track (CheckRun::session)
// goes back and forth: the hooks see every step taken, re-simulated ones included, and every
// frame shown, as often as it is shown.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "demo/demo_session.h"
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
    /// `session`: the run follows an events track on it (its world is `world_in`); null for a
    /// straight run of frames 0..frames-1.
    CheckRun(const engine::Scene& scene_in, const engine::World& world_in, int frames_in,
             std::filesystem::path dump_dir_in, const DemoSession* session_in = nullptr)
        : scene(scene_in), world(world_in), frames(frames_in), dump_dir(std::move(dump_dir_in)),
          session(session_in) {}

    const engine::Scene& scene;
    const engine::World& world;
    const int frames;
    const std::filesystem::path dump_dir;
    /// The session a run through events plays on (its view, camera, frame); null otherwise.
    const DemoSession* const session;

    render::Renderer& renderer();

    /// A run through events records each frame it shows (checkScene calls this).
    void markShown(int frame);
    /// The first frame of `range` the run never showed, or -1 when it showed them all (a run
    /// without events shows every frame below `frames`).
    int firstUnshown(const engine::FrameRange& range) const;
    /// Why an expectation on `frame` (from firstUnshown) is not graded: "the run has only N
    /// frames", or for a run through events "frame F is never reached through the events".
    std::string unshownReason(int frame) const;

private:
    std::unique_ptr<render::Renderer> renderer_;
    std::vector<char> shown_;  // by frame, in a run through events
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
    /// After frame 0 and after the last step of every later frame. In a run through events: at
    /// every frame shown, before the entries at it (demo_playback.h).
    virtual void observeFrame(CheckRun& run, int frame) {
        (void)run;
        (void)frame;
    }
    /// In a run through events only: after an entry's commands were applied at `frame` (the
    /// frame the session is at then; `commands.dump` is for the checker to write, as run does).
    virtual void observeEvent(CheckRun& run, int frame, const engine::DemoCommands& commands) {
        (void)run;
        (void)frame;
        (void)commands;
    }
    /// This kind's rows, in the order of the scene file.
    virtual void report(const CheckRun& run, std::vector<CheckRow>& rows) const = 0;
};

/// The checkers of `scene.expect`, in the order their rows are printed: bodies, moving and
/// rotating, broad phases, broad phases in use, energy, tunnelling, times of impact, rest, self
/// collision, pause dumps, pairs, colours. (A run through events has no colours: the loader
/// refuses them, engine::requireGradableThroughEvents.) `world` is the run's world before its first step (checkers take their start state
/// from it).
std::vector<std::unique_ptr<Checker>> makeCheckers(const engine::Scene& scene,
                                                   const engine::World& world);

}  // namespace app
