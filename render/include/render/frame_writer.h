// render/frame_writer.h -- the output end of the run pipeline: rendered frames are compressed to
// PNG by a pool of worker threads and fed to the video encoder in frame order by another, while
// the caller simulates and renders the next frame.
#pragma once

#include <filesystem>
#include <memory>

#include "render/image.h"

namespace render {

/// Seconds spent by the writer's threads (thread CPU time for PNG work, wall time for the video
/// feed, which waits on the encoder whenever the pipe is full) and by the encoder process.
struct FrameWriterTimes {
    double png_cpu_s = 0;       ///< compressing and writing PNGs, summed over the workers
    double video_feed_s = 0;    ///< writing frames into the encoder's pipe (wall)
    double encoder_cpu_s = 0;   ///< the encoder process's user + system time, after finish()
    long long png_files = 0;    ///< PNGs written
    long long video_frames = 0; ///< frames given to the encoder
};

/// Writes frames behind the caller's back, in bounded queues, so simulation, rendering, PNG
/// compression and video encoding overlap on several cores. Every file is the one writePng()
/// and VideoWriter would write one frame at a time: the PNGs are the same bytes, and the video
/// gets the frames in the order submitted.
/// Errors: the first failure of any worker (a PNG that cannot be written, an encoder that dies
/// or stalls) stops the queues; the next submit() or finish() throws RenderError with its
/// message, and the video is abandoned (no file under its final name).
class FrameWriter {
public:
    /// `video` may be null (no video). `png_threads` >= 1 workers; at most `queue_frames` (>= 1)
    /// frames wait in each queue before submit() blocks, which bounds memory.
    FrameWriter(std::unique_ptr<VideoWriter> video, int png_threads, int queue_frames);
    /// Stops the workers; an unfinished video is abandoned, queued PNGs not yet written are not.
    ~FrameWriter();
    FrameWriter(const FrameWriter&) = delete;
    FrameWriter& operator=(const FrameWriter&) = delete;

    /// An image to render the next frame into: one whose earlier frame every writer is done
    /// with (its storage reused), or a new one. Holds nothing back: drop it and it returns.
    std::shared_ptr<Image> blankFrame();

    /// Queues `image` to be written as the PNG `png_file` (empty path: no PNG) and added
    /// `video_repeats` times to the video (0: not at all). Blocks while a queue is full. Throws
    /// RenderError when an earlier frame failed.
    void submit(std::shared_ptr<const Image> image, const std::filesystem::path& png_file,
                long video_repeats);
    /// Waits for every queued frame and finishes the video. Throws RenderError with the first
    /// failure. Call once.
    void finish();

    /// Times so far (encoder_cpu_s once finish() has returned).
    FrameWriterTimes times() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace render
