// app/lab/demo/demo_playback.h -- an events track played on a DemoSession in the order
// `cdlab run --events` plays it: the frames it shows and the entries it applies, for a caller
// that renders (run) or grades (check) what the run goes through.
#pragma once

#include <functional>
#include <vector>

#include "demo/demo_session.h"
#include "engine/demo_commands.h"

namespace app {

/// What a caller does at the moments of a played track.
struct DemoPlaybackHooks {
    /// A frame the run shows: the first, each one playing reaches, each frame a step passes
    /// (either way) and a seek's target. The session is at that frame, before the entries at it.
    std::function<void()> frame_shown;
    /// After an entry's commands were applied (DemoSession::apply); its `dump` and `wait`, which
    /// apply() leaves to the caller, are this hook's.
    std::function<void(const engine::DemoEvent&)> event_applied;
};

/// Plays `events` (checked whole: engine::checkEventTrack) on `session` from its current frame:
/// shows the frame, applies the entries at it in order, and plays on one frame at a time while
/// the session plays; returns when it ends paused (a track that ends paused ends the run there)
/// or at the last frame. World steps run through session.on_step. Throws std::logic_error when
/// the session refuses an entry (a track checkEventTrack passed for the session's frames never
/// is refused), and whatever on_step and the hooks throw.
void playDemo(DemoSession& session, const std::vector<engine::DemoEvent>& events,
              const DemoPlaybackHooks& hooks);

}  // namespace app
