// app/lab/run_scene.h -- `cdlab run`: scene -> simulation -> PNG frames, video, pause dumps.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "engine/scene.h"

namespace app {

/// The longest --pause-hold: an hour of one picture is a mistake, not a demo.
inline constexpr double kMaxPauseHoldSeconds = 3600;

struct RunOptions {
    std::filesystem::path scene;
    std::filesystem::path out_dir;               ///< default: out/<scene stem>
    std::optional<int> frames;                   ///< overrides the scene's frame count
    std::optional<std::filesystem::path> video;  ///< default: <out_dir>/<scene stem>.mp4
    bool no_video = false;
    bool no_frames = false;                  ///< skip the per-frame PNGs
    std::optional<std::string> broad_phase;  ///< overrides the scene's broad phase
    std::optional<std::string> pair_order;   ///< overrides the scene's pair_order
    std::vector<int> pause_at;               ///< frames to dump
    /// An events track (engine/demo_commands.h) to follow instead of the scene's own `events:`.
    std::optional<std::filesystem::path> events;
    /// Seconds each pause picture stays on screen in the video (repeated at the video's fps),
    /// as a live demo holds its pause; 0 = not held. Finite, 0..kMaxPauseHoldSeconds.
    double pause_hold_s = 2.0;
    bool hud_timing = true;                  ///< step time in the HUD (off: bit-identical frames)
    bool progress = true;                    ///< progress bar when stderr is a terminal
    bool timing = false;                     ///< print a per-stage time line at the end
    bool draw_structure = false;             ///< draw the broad phase's own structure
    bool check_broad_phase = false;          ///< compare every step with the brute reference
    std::optional<std::filesystem::path> stats_csv;  ///< one row of counters per frame
    /// Scene values replaced before validation (`--set world.time_step=0.01`).
    std::vector<engine::SceneOverride> overrides;
    /// One JSON line per frame: time, every body's position and orientation, confirmed pairs
    /// sorted by (a, b) whatever the pair order (`cdlab sweep --float-binary` compares a float
    /// build's trace with the double one's).
    std::optional<std::filesystem::path> trace;
    /// Write a recording (engine/recording.h) of every frame the run reaches, in frame order.
    std::optional<std::filesystem::path> record;
    /// Write index.html beside the frames (run_html.h): the video, the timeline of pairs and
    /// stage times with a cursor following the video, the pause pictures with their bodies.
    bool html = false;
    /// Check everything above (scene loaded with its overrides, flags, video container) and
    /// return 0 before anything is written or run (`cdlab --dry-run run ...`).
    bool dry_run = false;
};

/// Exit codes: 0 success, 1 output or runtime failure, 2 bad input (scene, flags),
/// 3 --check-broadphase found a step where the broad phase differs from its reference.
int runScene(const RunOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app
