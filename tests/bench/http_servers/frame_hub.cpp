// tests/bench/http_servers/frame_hub.cpp -- see frame_hub.h.
// Versions only grow, and a waiter is woken by every publish, so a long-poll for "newer than V"
// returns within one frame period of V+1 being out, whichever backend waits on it.
#include "frame_hub.h"

#include <algorithm>
#include <cstring>
#include <random>

namespace httpbench {

std::int64_t steadyNowNs() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

FrameHub::FrameHub(std::size_t frame_bytes, double fps) : blob_(frame_bytes, '\0') {
    // Incompressible bytes, like a PNG's; a fixed seed so every run serves the same frames.
    std::mt19937 rng(1);
    for (char& c : blob_) c = char(rng() & 0xff);
    publish();
    publisher_ = std::thread([this, fps] { publishLoop(fps); });
}

FrameHub::~FrameHub() { stop(); }

void FrameHub::stop() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
    }
    published_.notify_all();
    if (publisher_.joinable()) publisher_.join();
}

std::shared_ptr<const Frame> FrameHub::newest() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return newest_;
}

std::shared_ptr<const Frame> FrameHub::waitNewer(std::uint64_t after,
                                                 std::chrono::milliseconds timeout) const {
    std::unique_lock<std::mutex> lock(mutex_);
    published_.wait_for(lock, timeout, [&] { return stopping_ || newest_->version > after; });
    return newest_;
}

bool FrameHub::wakeWhenNewer(std::uint64_t after, std::function<void()> wake) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (newest_->version > after) return false;
    wakes_.push_back(std::move(wake));
    return true;
}

void FrameHub::publishLoop(double fps) {
    const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(1.0 / fps));
    auto next = std::chrono::steady_clock::now() + period;
    std::unique_lock<std::mutex> lock(mutex_);
    while (!published_.wait_until(lock, next, [&] { return stopping_; })) {
        lock.unlock();
        publish();
        lock.lock();
        next += period;
    }
}

void FrameHub::publish() {
    // The copy is made outside the lock, as the session encodes its PNG before publishing it.
    auto frame = std::make_shared<Frame>();
    frame->bytes = blob_;
    std::vector<std::function<void()>> wakes;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        frame->version = newest_ ? newest_->version + 1 : 1;
        std::memcpy(frame->bytes.data(), &frame->version,
                    std::min(sizeof frame->version, frame->bytes.size()));
        frame->published_ns = steadyNowNs();
        newest_ = std::move(frame);
        wakes.swap(wakes_);
    }
    published_.notify_all();
    for (std::function<void()>& wake : wakes) wake();
}

}  // namespace httpbench
