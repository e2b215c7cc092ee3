// app/lab/serve/live_session.h -- a demo session running live: a thread of its own steps and
// draws the scene (DemoSession, the off-screen renderer), plays at the scene's frame rate times
// the speed, and takes the demo commands (engine/demo_commands.h) of any number of callers,
// each applied at the next frame boundary. What `cdlab serve` puts behind its HTTP API.
//
// Reproducible: every command applied is logged with the frame it took effect at, and that log
// is an events track (eventsYaml) for `cdlab run SCENE --events LOG --no-hud-timing`, whose
// frame_F.png is the live session's last picture of frame F, byte for byte (the same session,
// renderer and HUD; the live HUD never shows the step time, which differs between runs).
//
// Threads: the session thread alone touches the world and the renderer (an OSMesa context is
// current on one thread); callers see immutable published frames (shared_ptr to const) and wait
// on a condition variable, never on a frame being drawn.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "engine/demo_commands.h"
#include "engine/recording.h"
#include "engine/scene.h"
#include "serve/pair_history.h"

namespace app {

/// One published picture of the session and what a pause dump says of it.
struct LiveFrame {
    std::uint64_t version = 0;  ///< 1, 2, ...: one per picture published
    int frame = 0;
    bool playing = false;
    std::string png;     ///< the PNG bytes `cdlab run` writes for this picture
    std::string state;   ///< JSON: the pause dump of the frame plus the session's view
};

/// The answer to one command: the frame it took effect at and the frame shown after it, or why
/// it was refused (and then nothing changed).
struct LiveAnswer {
    bool ok = false;
    int at_frame = 0;  ///< the frame the command was applied at (its `frame:` in the log)
    int frame = 0;     ///< the frame shown once it was applied
    std::string error;
};

struct LiveOptions {
    bool structure = false;  ///< draw the broad phase's structure (as `run --draw-structure`)
    bool paused = false;     ///< start paused at frame 0 (the log's first command says so)
    /// Where `dump: true` writes pause_F.png and pause_F.json; none: dump is refused.
    std::optional<std::filesystem::path> dump_dir;
    /// The session log (an events file), rewritten after every command applied and at stop().
    std::optional<std::filesystem::path> log_file;
    /// Commands waiting at most; more are refused as "busy" (a client flooding the session
    /// cannot grow its memory or delay the others' frames without bound).
    std::size_t max_queued = 64;
    /// Show this recording's frames instead of simulating (DemoSession of a recording); it must
    /// outlive the session and is read by the session thread alone.
    const engine::Recording* replay = nullptr;
    /// Comment lines (without '#') at the head of the log file: how to replay it.
    std::vector<std::string> log_comment;
};

class LiveSession {
public:
    /// Starts the session thread on `scene` (which must outlive the session) at frame 0,
    /// playing. Throws what engine::makeWorld or the renderer throws (an OSMesa context that
    /// cannot be made), before returning.
    LiveSession(const engine::Scene& scene, LiveOptions options);
    /// stop().
    ~LiveSession();
    LiveSession(const LiveSession&) = delete;
    LiveSession& operator=(const LiveSession&) = delete;

    /// Reads `text` (one command as JSON or YAML, as parseDemoCommands) and applies it at the
    /// next frame boundary; waits for that, at most `timeout`. A command that does not parse,
    /// that cannot apply (a step past the last frame), or that finds the queue full or the
    /// session stopped is refused with the reason, changing nothing.
    LiveAnswer command(const std::string& text,
                       std::chrono::milliseconds timeout = std::chrono::seconds(10));

    /// The newest picture; with `after`, waits (at most `timeout`) for one newer than that
    /// version, then returns the newest, new or not.
    std::shared_ptr<const LiveFrame> frame(std::optional<std::uint64_t> after = std::nullopt,
                                           std::chrono::milliseconds timeout =
                                               std::chrono::milliseconds(0)) const;

    /// The picture of that version while it is among the last kHeldFrames published, else null.
    std::shared_ptr<const LiveFrame> frameAt(std::uint64_t version) const;
    static constexpr std::size_t kHeldFrames = 16;

    /// The session log so far, as an events file (eventsYaml) after the log comment. Before any
    /// command: a comment saying so and `events: []`.
    std::string logYaml() const;

    /// The timeline rows of frames first reached from index `from` on, as a JSON array of
    /// {frame, time, flagged, colliding, step_ms, render_ms, png_ms, state_ms} (the world steps
    /// that reached the frame; drawing its first picture, encoding it, its state JSON; null
    /// until published); at most 10,000 rows per call.
    std::string timelineJson(std::size_t from) const;

    /// One pair's history, as JSON: {"a", "b", "frames", "flagged": [[first, last], ...],
    /// "colliding": [...]}, the frames (ranges, inclusive) it was flagged and confirmed in among
    /// frames 0..frames-1: those the simulation has reached so far, or every frame of a
    /// recording. Throws std::invalid_argument naming a body that is not in the scene, or a
    /// pair of one body with itself.
    std::string pairHistoryJson(const std::string& a, const std::string& b) const;

    /// The first error that stopped the session thread (a step that failed), or "".
    std::string failure() const;

    /// Stops the session thread (a command waiting is refused) and writes the log file. Safe to
    /// call more than once.
    void stop();

private:
    struct Pending {
        engine::DemoCommands commands;
        std::uint64_t id = 0;
    };
    struct TimelineRow {
        int frame = 0;
        double time = 0;
        std::size_t flagged = 0;
        std::size_t colliding = 0;
        double step_ms = 0;
        /// What the frame's first picture cost: drawing it, encoding the PNG, the state JSON
        /// (negative until it is published).
        double render_ms = -1;
        double png_ms = -1;
        double state_ms = -1;
    };

    void loop(std::promise<void>& started);
    void writeLog() const;

    const engine::Scene& scene_;
    LiveOptions options_;

    mutable std::mutex mutex_;  ///< guards everything below
    mutable std::condition_variable changed_;  ///< a frame published, a command or an answer
    std::deque<Pending> queue_;
    std::vector<std::pair<std::uint64_t, LiveAnswer>> answers_;
    std::uint64_t next_id_ = 1;
    std::shared_ptr<const LiveFrame> latest_;
    std::deque<std::shared_ptr<const LiveFrame>> held_;  ///< the last kHeldFrames published
    std::vector<engine::DemoEvent> log_;
    std::vector<TimelineRow> timeline_;
    PairHistory history_;
    std::string failure_;
    bool stopping_ = false;

    std::thread thread_;
};

}  // namespace app
