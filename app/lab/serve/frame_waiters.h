// app/lab/serve/frame_waiters.h -- long-polls without a thread each: one thread waits on the live
// session (live_session.h) for every new picture and wakes the requests waiting for a picture
// newer than theirs. What the HTTP server (http_server.h) answers `?after=V` with.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <thread>

namespace app {

class LiveSession;

class FrameWaiters {
public:
    /// Starts the waiting thread on `session`, which must outlive this object.
    explicit FrameWaiters(const LiveSession& session);
    /// stop().
    ~FrameWaiters();
    FrameWaiters(const FrameWaiters&) = delete;
    FrameWaiters& operator=(const FrameWaiters&) = delete;

    /// Registers `wake`, called once from the waiting thread when a picture newer than version
    /// `after` is published, or at stop(); returns true. Returns false without registering when
    /// the newest picture is newer already, or after stop(). `wake` must be quick (hand the work
    /// to another thread) and must not call this object.
    bool wakeWhenNewer(std::uint64_t after, std::function<void()> wake);

    /// Wakes every waiter and joins the thread; safe to call more than once.
    void stop();

private:
    void loop();

    const LiveSession& session_;
    std::mutex mutex_;  ///< guards everything below
    std::condition_variable stopped_;
    std::uint64_t newest_ = 0;  ///< the newest version the waiting thread has seen
    /// The wake-ups, by the version they wait past.
    std::multimap<std::uint64_t, std::function<void()>> waiting_;
    bool stopping_ = false;
    std::thread thread_;
};

}  // namespace app
