// tests/bench/http_servers/measure.cpp -- see measure.h.
// Every loop here ends by its own clock: a server that stops answering costs the bench its
// deadline, never a hang. Percentiles are nearest-rank.
#include "measure.h"

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <mutex>
#include <random>
#include <string>
#include <thread>

#include "frame_hub.h"
#include "http_client.h"

namespace httpbench {

namespace {

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const std::size_t rank = std::size_t(std::max(1.0, std::ceil(p * double(v.size()))));
    return v[std::min(rank, v.size()) - 1];
}

double msSince(Clock::time_point t0, Clock::time_point t1) {
    return std::chrono::duration<double, std::milli>(t1 - t0).count();
}

Clock::time_point after(Clock::time_point t, double seconds) {
    return t + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

// One long-polling client until `end`; appends delivery times, returns frames received.
struct Watcher {
    int frames = 0;
    int failed = 0;
    double longest_gap_ms = 0;
    std::vector<double> delivery_ms;
    // Frames received in [counted_from, counted_to) and the longest gap inside it.
    Clock::time_point counted_from;
    Clock::time_point counted_to;
    int frames_after = 0;  // frames at or after counted_to

    void run(int port, Clock::time_point end, std::size_t frame_bytes) {
        HttpConnection conn(port);
        std::uint64_t version = 0;
        Clock::time_point last = counted_from;
        HttpAnswer a;
        while (Clock::now() < end) {
            const std::string target = "/frame.png?after=" + std::to_string(version);
            if (!conn.request("GET", target, {}, end, a) || a.status != 200 ||
                a.body.size() != frame_bytes) {
                if (Clock::now() < end) {
                    ++failed;
                    std::this_thread::sleep_for(std::chrono::milliseconds(10));
                }
                continue;
            }
            const Clock::time_point now = Clock::now();
            if (a.version <= version) continue;  // the long-poll ended without a new frame
            version = a.version;
            if (now < counted_from) continue;
            if (now >= counted_to) {
                ++frames_after;
                continue;
            }
            ++frames;
            longest_gap_ms = std::max(longest_gap_ms, msSince(last, now));
            last = now;
            delivery_ms.push_back(double(steadyNowNs() - a.published_ns) / 1e6);
        }
        // A client that got nothing waited the whole window.
        longest_gap_ms = std::max(longest_gap_ms, msSince(last, std::min(end, counted_to)));
    }
};

}  // namespace

WatchResult watch(int port, int clients, double seconds, std::size_t frame_bytes) {
    std::vector<Watcher> watchers(static_cast<std::size_t>(clients));
    const Clock::time_point start = Clock::now();
    const Clock::time_point end = after(start, seconds);
    std::vector<std::thread> threads;
    for (Watcher& w : watchers) {
        w.counted_from = start;
        w.counted_to = end;
        threads.emplace_back([&w, port, end, frame_bytes] { w.run(port, end, frame_bytes); });
    }
    for (std::thread& t : threads) t.join();
    WatchResult r;
    std::vector<double> delivery;
    r.fps_min = 1e300;
    for (const Watcher& w : watchers) {
        const double fps = w.frames / seconds;
        r.fps_mean += fps / clients;
        r.fps_min = std::min(r.fps_min, fps);
        r.longest_gap_ms = std::max(r.longest_gap_ms, w.longest_gap_ms);
        r.failed_requests += w.failed;
        delivery.insert(delivery.end(), w.delivery_ms.begin(), w.delivery_ms.end());
    }
    r.delivery_ms_median = percentile(delivery, 0.5);
    r.delivery_ms_p95 = percentile(delivery, 0.95);
    return r;
}

CommandResult commands(int port, int count, double fps, std::size_t frame_bytes) {
    std::atomic<bool> done{false};
    std::vector<std::thread> watchers;
    for (int i = 0; i < 2; ++i) {
        watchers.emplace_back([&done, port, frame_bytes] {
            HttpConnection conn(port);
            std::uint64_t version = 0;
            HttpAnswer a;
            while (!done) {
                const Clock::time_point deadline = after(Clock::now(), 5);
                if (conn.request("GET", "/frame.png?after=" + std::to_string(version), {}, deadline,
                                 a) &&
                    a.body.size() == frame_bytes) {
                    version = std::max(version, a.version);
                }
            }
        });
    }
    CommandResult r;
    std::vector<double> round_trip;
    std::vector<double> after_publish;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> pause(0.0, 1.0 / fps);
    HttpConnection conn(port);
    HttpAnswer a;
    const std::string body = R"({"show": ["obb"]})";  // a demo command's size
    for (int i = 0; i < count; ++i) {
        std::this_thread::sleep_for(std::chrono::duration<double>(pause(rng)));
        const Clock::time_point t0 = Clock::now();
        const bool ok = conn.request("POST", "/command", body, after(t0, 5), a);
        const Clock::time_point t1 = Clock::now();
        const std::size_t at = a.body.find("\"published_ns\":");
        if (!ok || a.status != 200 || at == std::string::npos) {
            ++r.failed;
            continue;
        }
        std::int64_t published = 0;
        std::from_chars(a.body.data() + at + 15, a.body.data() + a.body.size(), published);
        round_trip.push_back(msSince(t0, t1));
        after_publish.push_back(double(steadyNowNs() - published) / 1e6);
    }
    done = true;
    for (std::thread& t : watchers) t.join();
    r.round_trip_ms_median = percentile(round_trip, 0.5);
    r.round_trip_ms_p95 = percentile(round_trip, 0.95);
    r.after_publish_ms_median = percentile(after_publish, 0.5);
    r.after_publish_ms_p95 = percentile(after_publish, 0.95);
    return r;
}

HostileResult hostile(int port, Hostility kind, int connections, double attack_seconds,
                      std::size_t frame_bytes) {
    const Clock::time_point start = Clock::now();
    const Clock::time_point attack_start = after(start, 1.0);
    const Clock::time_point attack_end = after(attack_start, attack_seconds);
    const Clock::time_point end = after(attack_end, 1.0);
    Watcher w;
    w.counted_from = attack_start;
    w.counted_to = attack_end;
    std::thread watcher([&] { w.run(port, end, frame_bytes); });

    double new_client_ms = 0;
    std::thread new_client([&] {
        const Clock::time_point asked = after(attack_start, 2.0);
        std::this_thread::sleep_until(asked);
        HttpConnection conn(port);
        HttpAnswer a;
        conn.request("GET", "/frame.png?after=0", {}, end, a);
        new_client_ms = msSince(asked, Clock::now());
    });

    std::this_thread::sleep_until(attack_start);
    std::vector<int> fds;
    for (int i = 0; i < connections; ++i) {
        const int fd = connectLoopback(port, after(Clock::now(), 1.0));
        if (fd >= 0) fds.push_back(fd);
    }
    if (kind == Hostility::SlowHeaders) {
        const std::string line = "GET /frame.png HTTP/1.1\r\nHost: 127.0.0.1\r\n";
        for (int fd : fds) (void)::send(fd, line.data(), line.size(), MSG_NOSIGNAL);
    }
    HostileResult r;
    std::vector<bool> closed(fds.size(), false);
    int tick = 0;
    while (Clock::now() < attack_end) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        const bool trickle = kind == Hostility::SlowHeaders && ++tick % 10 == 0;
        for (std::size_t i = 0; i < fds.size(); ++i) {
            if (closed[i]) continue;
            // The server closed it if it is readable and reads end-of-stream or an error.
            pollfd p{fds[i], POLLIN, 0};
            char byte;
            if (::poll(&p, 1, 0) > 0 && ::recv(fds[i], &byte, 1, MSG_DONTWAIT) <= 0) {
                closed[i] = true;
                ++r.dropped_by_server;
                continue;
            }
            if (trickle) {
                const std::string header = "X-Slow-" + std::to_string(tick) + ": 1\r\n";
                if (::send(fds[i], header.data(), header.size(), MSG_NOSIGNAL) < 0) {
                    closed[i] = true;
                    ++r.dropped_by_server;
                }
            }
        }
    }
    for (int fd : fds) ::close(fd);
    watcher.join();
    new_client.join();
    r.new_client_ms = new_client_ms;
    r.fps = w.frames / attack_seconds;
    r.longest_gap_ms = w.longest_gap_ms;
    r.fps_after = w.frames_after / 1.0;
    return r;
}

}  // namespace httpbench
