// app/lab/serve/serve_http.h -- `cdlab serve SCENE` (or `--replay RECORDING`): a live session
// (live_session.h) behind a local web server (http_server.h: Boost.Beast's asynchronous sessions,
// Debian's libboost-dev, header-only) with a page to drive it and a plain HTTP API for scripts:
//
//   GET  /                      the page (self-contained: style, scripts and Chart.js inlined)
//   POST /api/command           one command as JSON or YAML ({"pause": true}); answer
//                               {"ok": true, "at_frame": F, "frame": G} or {"ok": false,
//                               "error": "..."} (400 refused, 429 busy, 503 stopped)
//   GET  /api/frame.png         the newest picture (?after=V: wait up to 2 s for one newer than
//                               version V; ?version=V: that picture while it is held); headers
//                               X-Cdlab-Frame and X-Cdlab-Version
//   GET  /api/state.json        the pause dump of the newest picture's frame with "session":
//                               the view, HUD, body rectangles and version (?after=V as above)
//   GET  /api/session.yaml      every command applied so far with its frame: an events track
//   GET  /api/timeline.json     frames reached, from ?from=K on
//   GET  /api/pair.json         ?a=NAME&b=NAME: the frames that pair was flagged and confirmed in
//
// Nothing a request carries names a file; bodies over 64 KiB are refused (413), a request not
// read whole within 5 s of the connection waiting for it is dropped (a client trickling bytes
// included), commands beyond the queue's bound are "busy". No connection holds a thread, so a
// client holding many open delays no one else. Answers go out without Nagle's delay
// (TCP_NODELAY) and a kept-alive connection serves any number of requests (docs/serve.md: "Why
// Boost.Beast").
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "engine/scene.h"

namespace app {

struct ServeOptions {
    std::filesystem::path scene;
    std::string host = "127.0.0.1";
    int port = 8080;  ///< 0: any free port (printed)
    /// Where `dump: true` writes its files; default out/<scene stem>.
    std::filesystem::path out_dir;
    /// The session log (an events file), kept current on disk; default <out>/session.yaml.
    std::optional<std::filesystem::path> session_log;
    bool paused = false;          ///< start paused at frame 0 (logged as a pause command)
    bool draw_structure = false;  ///< draw the broad phase's structure
    std::optional<std::string> broad_phase;  ///< overrides the scene's broad phase
    std::vector<engine::SceneOverride> overrides;
    /// Show this recording (`cdlab run --record`) instead of simulating: its scene is the one it
    /// names, or `scene` when given (one moved since); --broadphase and --set are refused.
    std::optional<std::filesystem::path> replay;
    bool dry_run = false;
};

/// Serves until SIGINT or SIGTERM, then writes the session log and returns 0. Prints the URL
/// on `out` once it listens. 2: bad input (scene, flags); 1: cannot listen, or the session
/// failed.
int serveScene(const ServeOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app
