// tests/bench/http_servers/frame_hub.h -- the live session's shape without the session: a
// publisher thread that puts out a new frame (a fixed blob standing for the PNG, and a version)
// at a fixed rate, for the HTTP server backends under measurement to serve.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace httpbench {

/// One published picture: its bytes are a fresh copy per frame, as a new PNG would be.
struct Frame {
    std::uint64_t version = 0;      ///< 1 for the first frame, +1 each frame
    std::int64_t published_ns = 0;  ///< steady clock (CLOCK_MONOTONIC), shared by every process
    std::string bytes;
};

/// Nanoseconds on the steady clock, comparable across the bench's processes.
std::int64_t steadyNowNs();

class FrameHub {
public:
    /// Starts publishing at once: `frame_bytes` bytes per frame, `fps` frames a second.
    FrameHub(std::size_t frame_bytes, double fps);
    ~FrameHub();
    FrameHub(const FrameHub&) = delete;
    FrameHub& operator=(const FrameHub&) = delete;

    /// Stops publishing and releases every waiter; the hub stays usable for reads. Idempotent.
    void stop();

    /// The newest frame (never null: the first is published by the constructor).
    std::shared_ptr<const Frame> newest() const;

    /// Blocks until a frame newer than `after` is out or `timeout` passes; the newest either way.
    std::shared_ptr<const Frame> waitNewer(std::uint64_t after,
                                           std::chrono::milliseconds timeout) const;

    /// For event-loop servers: false when a frame newer than `after` is already out (`wake` is
    /// dropped); otherwise `wake` is called once, on the publisher thread, at the next publish.
    /// `wake` must only post work elsewhere.
    bool wakeWhenNewer(std::uint64_t after, std::function<void()> wake);

private:
    void publishLoop(double fps);
    void publish();

    std::string blob_;
    mutable std::mutex mutex_;
    mutable std::condition_variable published_;
    std::shared_ptr<const Frame> newest_;
    std::vector<std::function<void()>> wakes_;
    bool stopping_ = false;
    std::thread publisher_;
};

}  // namespace httpbench
