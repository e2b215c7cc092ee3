// app/lab/demo/demo_session.h -- a running demo: a world at some frame of its scene, played,
// paused, stepped back and forth and seeked, with the view (volumes and layers, camera, selected
// body, speed) a user changes as it runs. What `cdlab run` follows through an `events:` track;
// a live session's commands go through the same apply().
//
// Going back is a restore: the session keeps snapshots of the world (World::snapshot) at every
// k-th frame it reaches, k = 8 and doubled whenever more than kMaxSnapshots would be kept, and
// reaches an earlier frame by restoring the nearest snapshot before it and stepping forward.
// World steps are deterministic, so a frame reached again is bit-identical to its first visit
// (the same state hash), unless the broad phase was switched in between with pair_order: found,
// where the pairs' order, and so the motion, follows the broad phase.
//
// A session of a recording (engine/recording.h) never steps: every frame it reaches is the
// recorded one placed in the world (World::place), checked against its recorded state hash.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>

#include "engine/demo_commands.h"
#include "engine/recording.h"
#include "engine/scene.h"
#include "engine/world.h"
#include "render/renderer.h"

namespace app {

/// What a demo shows of its world, changed by show, hide, select, camera and speed.
struct DemoView {
    engine::DrawSettings draw;  ///< volumes and layers
    bool structure = false;     ///< the broad phase's own structure
    std::optional<engine::BodyId> selected;
    engine::CameraSettings camera;  ///< as moved (camera() applies `follow`)
    std::optional<engine::BodyId> follow;
    double speed = 1;  ///< simulated frames per video frame
    /// The volumes drawn were chosen (by the scene's draw.volumes, or show/hide of a volume);
    /// otherwise they follow the broad phase: its tested kind, after every switch too.
    bool volumes_chosen = false;
};

class DemoSession {
public:
    /// Snapshots kept at most (the interval doubles beyond): bounded memory on any run length.
    static constexpr int kMaxSnapshots = 64;

    /// The scene at frame 0, playing, drawn as `cdlab run` draws it (`structure`: and the broad
    /// phase's structure). `scene` must outlive the session. Throws what engine::makeWorld
    /// throws.
    DemoSession(const engine::Scene& scene, bool structure);
    /// The frames of `recording` (of `scene`: replay/run_recorder.h loadRecordedScene), shown
    /// without simulating; both must outlive the session. Each frame shows the broad phase
    /// recorded for it until a command chooses one. Throws engine::RecordingError for a frame
    /// that cannot be read or whose placed state does not hash to the recorded hash (a
    /// recording of another build's detection).
    DemoSession(const engine::Scene& scene, bool structure, const engine::Recording& recording);
    /// A session of a recording.
    bool replaying() const { return recording_ != nullptr; }

    const engine::Scene& scene() const { return scene_; }
    const engine::World& world() const { return world_; }
    int frame() const { return frame_; }
    /// The last frame a session can reach: scene().frames - 1, or a recording's last.
    int lastFrame() const { return recording_ ? recording_->frames() - 1 : scene_.frames - 1; }
    bool playing() const { return playing_; }
    const DemoView& view() const { return view_; }
    /// Whether the current view shows `layer` (what show/hide last set, or the scene's draw).
    bool shows(engine::DemoLayer layer) const;
    /// The camera of the current frame: the view's, moved to look at the followed body.
    engine::CameraSettings camera() const;
    /// What a frame of the current view shows (HUD text left empty).
    render::FrameOptions frameOptions() const;
    /// The HUD of the current frame ("" when the hud layer is hidden): "PAUSED  " when
    /// `paused`, the frame's figures (the step time only when `timing` and not paused), and the
    /// selected body's line.
    std::string hudText(bool paused, bool timing) const;

    /// Called after every world step the session takes (going forward or re-simulating after a
    /// restore): counters, checks. May throw, which leaves the session at the frame before.
    std::function<void(const engine::World&)> on_step;

    /// Applies `commands` in their order (demo_commands.h), without dump and wait, which belong
    /// to the caller's output. `reached` is called at each frame a step passes (each frame from
    /// the current one to the target, either way) and at a seek's target. Returns "" or, when a
    /// step or seek would leave frames 0..lastFrame(), what is wrong, and then changes nothing.
    std::string apply(const engine::DemoCommands& commands,
                      const std::function<void()>& reached = {});

    /// One frame forward (scene().steps_per_frame world steps); false, and nothing done, at the
    /// last frame.
    bool advance();
    /// Goes to `frame` (0..lastFrame()): forward by stepping, back by a restore and stepping.
    void goTo(int frame);

    /// Snapshots held now, and the frames between them (for tests and the curious).
    std::size_t snapshots() const { return snapshots_.size(); }
    int snapshotInterval() const { return interval_; }

private:
    void keepSnapshot();
    void placeRecorded(int frame);
    /// After a broad-phase switch: unless volumes were chosen, draw the one it tests.
    void followBroadPhase();
    void show(engine::DemoLayer layer, bool on);
    void moveCamera(const engine::CameraCommand& c);

    const engine::Scene& scene_;  ///< outlives the session
    engine::World world_;
    DemoView view_;
    int frame_ = 0;
    bool playing_ = true;
    std::string broad_phase_;  ///< the broad phase chosen, re-installed after a restore
    std::map<int, engine::WorldSnapshot> snapshots_;
    int interval_ = 8;
    const engine::Recording* recording_ = nullptr;
    bool broad_phase_chosen_ = false;  ///< a command chose the broad phase (replay)
};

/// "selected NAME (sphere): colliding with A, B; flagged with C" for the HUD: the body's pairs of
/// the current frame by name, at most `max_names` of each kind (then "and N more").
std::string selectionLine(const engine::World& world, engine::BodyId id, int max_names = 6);

}  // namespace app
