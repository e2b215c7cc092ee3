// app/lab/run_html.h -- a run's index.html (`cdlab run --html`): the video, the timeline of pairs
// and stage times per frame with a cursor that follows the video, and the pause pictures with
// their bodies and pairs. One self-contained file beside the frames (html_page.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "render/renderer.h"

namespace app {

/// One frame of the timeline: what the frame's steps found and what they cost (the columns of
/// `cdlab run --stats`).
struct RunPageFrame {
    int frame = 0;
    double time = 0;             ///< s, simulated, at the end of the frame
    std::int64_t flagged = 0;    ///< broad-phase pairs at the end of the frame
    std::int64_t colliding = 0;  ///< narrow-phase confirmed pairs at the end of the frame
    double integrate_ms = 0, volumes_ms = 0, broadphase_ms = 0, narrowphase_ms = 0, ccd_ms = 0,
           response_ms = 0;  ///< wall-clock ms of each stage, summed over the frame's steps
    double step_ms = 0;      ///< wall-clock ms of the frame's steps
};

/// One pause picture: pause_FRAME.png beside the page, and its dump (pause_dump.h).
struct RunPagePause {
    int frame = 0;
    std::string dump_json;  ///< pause_FRAME.json's text
    /// Where each body's AABB shows in the picture (render::screenRect), by body id; nothing
    /// for a body off the picture or reaching behind the camera.
    std::vector<std::optional<render::ScreenRect>> body_rects;
};

/// What index.html shows of a finished run.
struct RunPage {
    std::string scene;  ///< the scene file as given on the command line
    std::string scene_name;
    std::string broad_phase;
    std::size_t bodies = 0;
    int width = 0, height = 0;  ///< pixels of the frames and the video
    int fps = 30;               ///< frames per second of the video
    /// The video, relative to the page (a URL path); empty when there is none.
    std::string video;
    /// Why there is no video ("the run was made with --no-video"); shown instead of a player.
    std::string no_video_reason;
    /// Video frames each pause picture is held after its frame (the video's frame f is the
    /// run's frame f plus the holds of the pauses before it).
    long hold_frames = 0;
    bool frames_written = true;  ///< frame_NNNNN.png beside the page
    std::vector<RunPageFrame> frames;
    std::vector<RunPagePause> pauses;
};

/// index.html for `page`: every scene-supplied string escaped, the data embedded as JSON,
/// Chart.js and the page's script inlined. Throws nlohmann::json::exception when a pause dump is
/// not valid JSON (a programmer error: pauseDumpJson() wrote it).
std::string runPageHtml(const RunPage& page);

}  // namespace app
