// tests/bench/http_servers/measure.h -- the workloads the bench drives a server with, from its
// own process: long-polling watchers, commands beside two watchers, and a hostile client.
#pragma once

#include <cstddef>
#include <vector>

namespace httpbench {

/// What long-polling clients received over a window.
struct WatchResult {
    double fps_mean = 0;            ///< new frames per second, averaged over the clients
    double fps_min = 0;             ///< the slowest client's
    double delivery_ms_median = 0;  ///< frame published -> its last byte in the client's hands
    double delivery_ms_p95 = 0;
    double longest_gap_ms = 0;  ///< the longest wait for a new frame, any client
    int failed_requests = 0;    ///< errors and timeouts (a stalled long-poll counts)
};

/// `clients` threads long-poll GET /frame.png?after=V for `seconds`.
WatchResult watch(int port, int clients, double seconds, std::size_t frame_bytes);

struct CommandResult {
    double round_trip_ms_median = 0;  ///< POST sent -> answer in hand
    double round_trip_ms_p95 = 0;
    double after_publish_ms_median = 0;  ///< the frame it waited for published -> answer in hand
    double after_publish_ms_p95 = 0;
    int failed = 0;
};

/// `count` POST /command, each after a pause drawn uniformly in one frame period (fixed seed),
/// so commands fall at every phase of the frame clock, while two watchers stream.
CommandResult commands(int port, int count, double fps, std::size_t frame_bytes);

enum class Hostility { Idle, SlowHeaders };

struct HostileResult {
    double fps = 0;             ///< the normal watcher's frames per second during the attack
    double longest_gap_ms = 0;  ///< its longest wait for a new frame during the attack
    double fps_after = 0;       ///< in the second after the attack ended
    int dropped_by_server = 0;  ///< hostile connections the server closed during the attack
    double new_client_ms = 0;   ///< a client arriving 2 s into the attack: ms to its first frame
};

/// A watcher streams; after 1 s one client opens `connections` connections and either sends
/// nothing or trickles header lines (one per connection per second, never ending the headers)
/// for `attack_seconds`, then closes them; the watcher goes on for one more second. A second,
/// new client (a reloaded page) asks for a frame 2 s into the attack, waiting at most until the
/// watcher stops.
HostileResult hostile(int port, Hostility kind, int connections, double attack_seconds,
                      std::size_t frame_bytes);

}  // namespace httpbench
