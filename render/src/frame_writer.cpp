// render/src/frame_writer.cpp -- see render/frame_writer.h.
// Invariants: each queue holds at most queue_frames entries (the producer blocks, memory stays
// bounded); the video thread is the only one that writes to the encoder, and it takes frames in
// submission order, so the video is the same whatever the timing; two PNGs of the same file are
// written one after the other in submission order, so the last one submitted is the file's (a
// frame seen twice, stepping back); the first failure is kept and
// every later submit() or finish() reports it, so a run never ends looking complete when a frame
// was lost.
#include "render/frame_writer.h"

#include <pthread.h>
#include <time.h>

#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <cstdint>
#include <map>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

namespace render {

namespace fs = std::filesystem;

namespace {

double threadCpuSeconds() {
    timespec t{};
    ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double wallSeconds() {
    timespec t{};
    ::clock_gettime(CLOCK_MONOTONIC, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// A bounded FIFO between threads. close() lets consumers drain what is queued; abort() drops it.
template <typename T>
class BoundedQueue {
public:
    explicit BoundedQueue(std::size_t capacity) : capacity_(capacity) {}

    /// False when the queue was closed or aborted (the item is dropped).
    bool push(T item) {
        std::unique_lock<std::mutex> lock(mutex_);
        not_full_.wait(lock, [&] { return items_.size() < capacity_ || closed_; });
        if (closed_) return false;
        items_.push_back(std::move(item));
        not_empty_.notify_one();
        return true;
    }
    /// Nothing once the queue is closed and empty, or aborted.
    std::optional<T> pop() {
        std::unique_lock<std::mutex> lock(mutex_);
        not_empty_.wait(lock, [&] { return !items_.empty() || closed_; });
        if (items_.empty() || aborted_) return std::nullopt;
        T item = std::move(items_.front());
        items_.pop_front();
        not_full_.notify_one();
        return item;
    }
    void close() {
        std::lock_guard<std::mutex> lock(mutex_);
        closed_ = true;
        not_empty_.notify_all();
        not_full_.notify_all();
    }
    void abort() {
        std::lock_guard<std::mutex> lock(mutex_);
        closed_ = aborted_ = true;
        items_.clear();
        not_empty_.notify_all();
        not_full_.notify_all();
    }

private:
    std::size_t capacity_;
    std::mutex mutex_;
    std::condition_variable not_full_;
    std::condition_variable not_empty_;
    std::deque<T> items_;
    bool closed_ = false;
    bool aborted_ = false;
};

struct PngJob {
    std::shared_ptr<const Image> image;
    fs::path file;
    std::uint64_t turn = 0;  ///< its place among the jobs for the same file, from 0
};

// The jobs for one file: how many were submitted, how many are written.
struct FileTurns {
    std::uint64_t issued = 0;
    std::uint64_t written = 0;
};

struct VideoJob {
    std::shared_ptr<const Image> image;
    long repeats = 0;
};

// Images whose writers are done, kept for the next frame. Shared with every image handed out,
// so an image released after the writer is gone still has somewhere to go.
struct ImagePool {
    std::mutex mutex;
    std::vector<std::unique_ptr<Image>> free;
    static constexpr std::size_t kMaxFree = 16;
};

}  // namespace

struct FrameWriter::Impl {
    Impl(std::unique_ptr<VideoWriter> v, int queue_frames)
        : video(std::move(v)), png_queue(std::size_t(queue_frames)),
          video_queue(std::size_t(queue_frames)) {}

    std::unique_ptr<VideoWriter> video;
    BoundedQueue<PngJob> png_queue;
    BoundedQueue<VideoJob> video_queue;
    std::vector<std::thread> png_threads;
    std::thread video_thread;
    std::shared_ptr<ImagePool> pool = std::make_shared<ImagePool>();
    bool finished = false;

    mutable std::mutex mutex;  ///< guards everything below
    std::optional<std::string> failure;
    FrameWriterTimes times;
    /// The files with jobs not yet written: a job writes its file only once every job
    /// submitted for it before has.
    std::map<fs::path, FileTurns> turns;
    std::condition_variable written;

    void fail(const std::string& message) {
        {
            std::lock_guard<std::mutex> lock(mutex);
            if (!failure) failure = message;
        }
        written.notify_all();
        png_queue.abort();
        video_queue.abort();
    }
    void throwIfFailed() const {
        std::lock_guard<std::mutex> lock(mutex);
        if (failure) throw RenderError(*failure);
    }

    void pngWorker() {
        ::pthread_setname_np(::pthread_self(), "cdlab-png");
        while (std::optional<PngJob> job = png_queue.pop()) {
            {
                // Workers take jobs in submission order but may finish them in any: a job
                // waits until the earlier jobs for its file are written (or the writer failed).
                std::unique_lock<std::mutex> lock(mutex);
                written.wait(lock, [&] {
                    return failure.has_value() || turns[job->file].written == job->turn;
                });
                if (failure) return;
            }
            const double t0 = threadCpuSeconds();
            std::string error;
            try {
                writePng(job->file, *job->image);
            } catch (const std::exception& e) {
                error = e.what();
            }
            {
                std::lock_guard<std::mutex> lock(mutex);
                FileTurns& t = turns[job->file];
                if (++t.written == t.issued) turns.erase(job->file);
                if (error.empty()) {
                    times.png_cpu_s += threadCpuSeconds() - t0;
                    ++times.png_files;
                }
            }
            written.notify_all();
            if (!error.empty()) {
                fail(error);
                return;
            }
        }
    }

    void videoWorker() {
        ::pthread_setname_np(::pthread_self(), "cdlab-video");
        while (std::optional<VideoJob> job = video_queue.pop()) {
            const double t0 = wallSeconds();
            try {
                for (long k = 0; k < job->repeats; ++k) video->addFrame(*job->image);
            } catch (const std::exception& e) {
                fail(e.what());
                return;
            }
            std::lock_guard<std::mutex> lock(mutex);
            times.video_feed_s += wallSeconds() - t0;
            times.video_frames += job->repeats;
        }
    }

    void join() {
        for (std::thread& t : png_threads) {
            if (t.joinable()) t.join();
        }
        if (video_thread.joinable()) video_thread.join();
    }
};

FrameWriter::FrameWriter(std::unique_ptr<VideoWriter> video, int png_threads, int queue_frames)
    : impl_(std::make_unique<Impl>(std::move(video), queue_frames < 1 ? 1 : queue_frames)) {
    if (png_threads < 1) png_threads = 1;
    try {
        for (int i = 0; i < png_threads; ++i) {
            impl_->png_threads.emplace_back([this] { impl_->pngWorker(); });
        }
        if (impl_->video) impl_->video_thread = std::thread([this] { impl_->videoWorker(); });
    } catch (const std::system_error& e) {
        impl_->fail(e.what());
        impl_->join();
        throw RenderError(std::string("cannot start the frame writer's threads: ") + e.what());
    }
}

FrameWriter::~FrameWriter() {
    if (!impl_->finished) {
        impl_->png_queue.abort();
        impl_->video_queue.abort();
    }
    impl_->join();
}

std::shared_ptr<Image> FrameWriter::blankFrame() {
    std::shared_ptr<ImagePool> pool = impl_->pool;
    std::unique_ptr<Image> image;
    {
        std::lock_guard<std::mutex> lock(pool->mutex);
        if (!pool->free.empty()) {
            image = std::move(pool->free.back());
            pool->free.pop_back();
        }
    }
    if (!image) image = std::make_unique<Image>();
    return std::shared_ptr<Image>(image.release(), [pool](Image* done) {
        std::unique_ptr<Image> owned(done);
        std::lock_guard<std::mutex> lock(pool->mutex);
        if (pool->free.size() < ImagePool::kMaxFree) pool->free.push_back(std::move(owned));
    });
}

void FrameWriter::submit(std::shared_ptr<const Image> image, const fs::path& png_file,
                         long video_repeats) {
    Impl& im = *impl_;
    if (im.finished) throw RenderError("frame writer: submit() after finish()");
    im.throwIfFailed();
    bool queued = true;
    if (!png_file.empty()) {
        std::uint64_t turn = 0;
        {
            std::lock_guard<std::mutex> lock(im.mutex);
            turn = im.turns[png_file].issued++;
        }
        queued = im.png_queue.push(PngJob{image, png_file, turn});
    }
    if (queued && im.video && video_repeats > 0) {
        queued = im.video_queue.push(VideoJob{std::move(image), video_repeats});
    }
    im.throwIfFailed();
    if (!queued) throw RenderError("frame writer: queue closed");
}

void FrameWriter::finish() {
    Impl& im = *impl_;
    if (im.finished) throw RenderError("frame writer: finish() called twice");
    im.finished = true;
    im.png_queue.close();
    im.video_queue.close();
    im.join();
    im.throwIfFailed();
    if (im.video) {
        im.video->finish();
        std::lock_guard<std::mutex> lock(im.mutex);
        im.times.encoder_cpu_s = im.video->encoderCpuSeconds();
    }
}

FrameWriterTimes FrameWriter::times() const {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    return impl_->times;
}

}  // namespace render
