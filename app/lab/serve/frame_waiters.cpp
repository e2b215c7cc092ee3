// app/lab/serve/frame_waiters.cpp -- see frame_waiters.h.
// Invariant: every waiter waits past a version >= newest_, the newest version the thread has
// seen; the thread raises newest_ and takes out the waiters below it under one lock, so a waiter
// registered while a picture is being published is either refused (newer already) or woken by
// that picture's round.
#include "serve/frame_waiters.h"

#include <chrono>
#include <memory>
#include <vector>

#include "serve/live_session.h"

namespace app {

namespace {

// How long one wait on the session lasts before the thread looks at stop() again.
constexpr auto kWaitSlice = std::chrono::milliseconds(200);

}  // namespace

FrameWaiters::FrameWaiters(const LiveSession& session) : session_(session) {
    thread_ = std::thread([this] { loop(); });
}

FrameWaiters::~FrameWaiters() { stop(); }

bool FrameWaiters::wakeWhenNewer(std::uint64_t after, std::function<void()> wake) {
    // The session first: the thread may not have seen its newest picture yet.
    if (const auto f = session_.frame(); f && f->version > after) return false;
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_ || newest_ > after) return false;
    waiting_.emplace(after, std::move(wake));
    return true;
}

void FrameWaiters::stop() {
    std::multimap<std::uint64_t, std::function<void()>> woken;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
        woken.swap(waiting_);
    }
    stopped_.notify_all();
    for (auto& [after, wake] : woken) wake();
    if (thread_.joinable() && thread_.get_id() != std::this_thread::get_id()) thread_.join();
}

void FrameWaiters::loop() {
    std::uint64_t seen = 0;
    for (;;) {
        const auto start = std::chrono::steady_clock::now();
        const std::shared_ptr<const LiveFrame> f = session_.frame(seen, kWaitSlice);
        std::vector<std::function<void()>> due;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            if (stopping_) return;
            if (!f || f->version <= seen) {
                // Nothing new: a quiet slice, or a session that has stopped and so answers at
                // once; a short rest keeps the latter from spinning.
                if (std::chrono::steady_clock::now() - start < kWaitSlice / 2) {
                    stopped_.wait_for(lock, std::chrono::milliseconds(20),
                                      [&] { return stopping_; });
                }
                continue;
            }
            seen = newest_ = f->version;
            const auto end = waiting_.lower_bound(newest_);
            for (auto it = waiting_.begin(); it != end; ++it) due.push_back(std::move(it->second));
            waiting_.erase(waiting_.begin(), end);
        }
        for (const std::function<void()>& wake : due) wake();
    }
}

}  // namespace app
