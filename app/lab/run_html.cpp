// app/lab/run_html.cpp -- see run_html.h. The page is a frame of static HTML (title, player or
// "no video" message, chart canvases, the pause sections' places) and the data as one JSON
// element; app/lab/page/run_page.js draws the charts and the pause tables from the data.
#include "run_html.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "html_page.h"
#include "page_assets.h"

namespace app {

namespace {

constexpr int kMinVideoWidth = 480;

// The timeline as columns (one array per quantity, indexed like `frames`).
nlohmann::ordered_json timelineJson(const std::vector<RunPageFrame>& frames) {
    nlohmann::ordered_json frame = nlohmann::ordered_json::array(),
                           time = nlohmann::ordered_json::array(),
                           flagged = nlohmann::ordered_json::array(),
                           colliding = nlohmann::ordered_json::array(),
                           step = nlohmann::ordered_json::array();
    struct Stage {
        const char* name;
        double RunPageFrame::*ms;
    };
    const Stage stages[] = {{"integrate", &RunPageFrame::integrate_ms},
                            {"volumes", &RunPageFrame::volumes_ms},
                            {"broadphase", &RunPageFrame::broadphase_ms},
                            {"narrowphase", &RunPageFrame::narrowphase_ms},
                            {"ccd", &RunPageFrame::ccd_ms},
                            {"response", &RunPageFrame::response_ms}};
    nlohmann::ordered_json stage_ms = nlohmann::ordered_json::object();
    for (const Stage& s : stages) stage_ms[s.name] = nlohmann::ordered_json::array();
    for (const RunPageFrame& f : frames) {
        frame.push_back(f.frame);
        time.push_back(f.time);
        flagged.push_back(f.flagged);
        colliding.push_back(f.colliding);
        step.push_back(f.step_ms);
        for (const Stage& s : stages) stage_ms[s.name].push_back(f.*s.ms);
    }
    return {{"frame", frame},         {"time", time},    {"flagged", flagged},
            {"colliding", colliding}, {"step_ms", step}, {"stage_ms", stage_ms}};
}

nlohmann::ordered_json pageData(const RunPage& page) {
    nlohmann::ordered_json data;
    data["scene"] = page.scene;
    data["scene_name"] = page.scene_name;
    data["broadphase"] = page.broad_phase;
    data["bodies"] = page.bodies;
    data["width"] = page.width;
    data["height"] = page.height;
    data["fps"] = page.fps;
    data["video"] = page.video;
    data["hold_frames"] = page.hold_frames;
    data["frames_written"] = page.frames_written;
    data["timeline"] = timelineJson(page.frames);
    nlohmann::ordered_json pauses = nlohmann::ordered_json::array();
    for (const RunPagePause& p : page.pauses) {
        nlohmann::ordered_json rects = nlohmann::ordered_json::array();
        for (const std::optional<render::ScreenRect>& r : p.body_rects) {
            rects.push_back(r ? nlohmann::ordered_json{r->x0, r->y0, r->x1, r->y1}
                              : nlohmann::ordered_json());
        }
        pauses.push_back({{"frame", p.frame},
                          {"picture", "pause_" + std::to_string(p.frame) + ".png"},
                          {"rects", std::move(rects)},
                          {"dump", nlohmann::ordered_json::parse(p.dump_json)}});
    }
    data["pauses"] = std::move(pauses);
    return data;
}

// The player: the video, or a plain message where it would be.
std::string playerHtml(const RunPage& page) {
    std::string out = "<section id=\"player\">\n";
    const bool gif =
        page.video.size() >= 4 && page.video.compare(page.video.size() - 4, 4, ".gif") == 0;
    if (page.video.empty()) {
        out +=
            "<p class=\"missing\" id=\"no-video\">no video: " + html::escape(page.no_video_reason) +
            "</p>\n";
        // The frames instead, one at a time: the timeline's cursor picks which.
        if (page.frames_written && !page.frames.empty()) {
            out +=
                "<img id=\"frame-view\" alt=\"the frame at the cursor\" src=\"frame_00000.png\">\n";
        }
    } else if (gif) {
        // A GIF plays as a picture, without controls: no cursor to follow.
        out += "<img id=\"video-picture\" alt=\"the run's video\" src=\"" +
               html::escape(page.video) + "\">\n";
    } else {
        // Small videos are shown at least kMinVideoWidth wide (the browser scales them).
        const int shown_width = std::max(page.width, kMinVideoWidth);
        const int shown_height = page.width > 0 ? page.height * shown_width / page.width : 0;
        out += "<video id=\"video\" controls muted playsinline preload=\"auto\" width=\"" +
               std::to_string(shown_width) + "\" height=\"" + std::to_string(shown_height) +
               "\" src=\"" + html::escape(page.video) + "\"></video>\n";
        out += "<p class=\"missing\" id=\"no-video\" hidden></p>\n";
    }
    out += "<p id=\"readout\">frame 0</p>\n</section>\n";
    return out;
}

}  // namespace

std::string runPageHtml(const RunPage& page) {
    std::string out = html::pageStart("cdlab run: " + page.scene_name);
    out += "<header>\n<h1>" + html::escape(page.scene_name) + "</h1>\n<p class=\"meta\">" +
           html::escape(page.scene) + " &middot; broad phase " + html::escape(page.broad_phase) +
           " &middot; " + std::to_string(page.bodies) + " bodies &middot; " +
           std::to_string(page.frames.size()) + " frames at " + std::to_string(page.fps) +
           " fps</p>\n</header>\n<main>\n";
    out += playerHtml(page);
    out +=
        "<section id=\"timeline\">\n<h2>Timeline</h2>\n"
        "<p class=\"hint\">Per frame: pairs the broad phase flagged and the narrow phase "
        "confirmed, and the wall-clock time of each stage. ";
    out += page.video.empty()
               ? "The blue line marks the frame shown; click a chart to pick another, or step "
                 "with the arrow keys.</p>\n"
               : "The blue line follows the video; click a chart to move the video there, or "
                 "step with the arrow keys.</p>\n";
    out +=
        "<div class=\"chart-box\"><canvas id=\"pairs-chart\"></canvas></div>\n"
        "<div class=\"chart-box\"><canvas id=\"stages-chart\"></canvas></div>\n</section>\n";
    out += "<section id=\"pauses\">\n<h2>Pause pictures</h2>\n";
    if (page.pauses.empty()) {
        out += "<p class=\"hint\">None: cdlab run --pause-at FRAME writes one.</p>\n";
    }
    out += "</section>\n</main>\n";
    // A name that is not valid UTF-8 is shown with U+FFFD rather than failing the page.
    out += html::jsonScript(
        "run-data", pageData(page).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
    out += html::pageEnd(runPageJs());
    return out;
}

}  // namespace app
