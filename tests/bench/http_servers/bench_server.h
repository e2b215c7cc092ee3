// tests/bench/http_servers/bench_server.h -- the seam the bench swaps HTTP server libraries at:
// each backend serves the same two routes over a FrameHub, on 127.0.0.1, with the same limits.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "frame_hub.h"

namespace httpbench {

/// The limits `cdlab serve` sets (app/lab/serve/serve_http.cpp), applied to every backend.
struct ServeLimits {
    int threads = 8;                     ///< request threads (cpp-httplib's pool on 2 cores)
    std::chrono::seconds io_timeout{5};  ///< a client that stops sending or reading
    std::size_t max_body = 64 * 1024;    ///< larger request bodies get 413
    std::chrono::milliseconds long_poll{2000};
    /// TCP_NODELAY on accepted sockets; off as `cdlab serve` ships (no backend sets it unasked).
    bool tcp_nodelay = false;
    /// Requests one kept-alive connection may carry before the server closes it; 0: the
    /// library's default (cpp-httplib 0.11: 5; civetweb and Beast: no limit). cpp-httplib only.
    int keep_alive_requests = 0;
};

/// GET /frame.png?after=V: the newest frame once newer than V (or after long_poll), with headers
/// X-Version and X-Published-Ns. POST /command: answered once the next frame is out, with
/// {"ok":true,"version":V,"published_ns":T} of that frame.
class BenchServer {
public:
    virtual ~BenchServer() = default;
    /// The port it listens on (bound before the constructor returns).
    virtual int port() const = 0;
    /// Stops listening and ends every request thread; called once.
    virtual void stop() = 0;
};

std::unique_ptr<BenchServer> startHttplib(FrameHub& hub, const ServeLimits& limits);
std::unique_ptr<BenchServer> startCivetweb(FrameHub& hub, const ServeLimits& limits);
std::unique_ptr<BenchServer> startBeast(FrameHub& hub, const ServeLimits& limits);

/// A version number as text ("12"), 0 when empty or malformed.
std::uint64_t parseVersion(std::string_view text);

/// `after=` of a raw query string ("x=1&after=12"), 0 when absent or malformed.
std::uint64_t afterParam(std::string_view query);

/// The body of a POST /command answer for frame f.
std::string commandAnswer(const Frame& f);

}  // namespace httpbench
