// render/image.h -- an RGB8 picture, the PNG writer and the ffmpeg video pipe.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace render {

/// A failure to render or to write output: message says what and where.
class RenderError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Row-major RGB8, row 0 at the top.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgb;  ///< width * height * 3 bytes

    const std::uint8_t* pixel(int x, int y) const { return &rgb[(std::size_t(y) * width + x) * 3]; }
};

/// Writes an 8-bit RGB PNG (libpng). Writes to a temporary name and renames, so a file that
/// exists is complete. Throws RenderError.
void writePng(const std::filesystem::path& file, const Image& image);
/// The bytes writePng writes for `image`, in memory (a live session's frames). Throws
/// RenderError.
std::string pngBytes(const Image& image);
/// Reads an 8-bit RGB or RGBA PNG (for tests and tools). Throws RenderError.
Image readPng(const std::filesystem::path& file);

/// True when `ffmpeg` can be run from PATH.
bool ffmpegAvailable();

/// The video containers VideoWriter writes, by file extension: ".mp4, .mov, .mkv, .webm, .gif".
std::string supportedVideoExtensions();
/// True when VideoWriter can write `file` (its extension is supported; none means .mp4).
bool isSupportedVideoFile(const std::filesystem::path& file);

/// Pipes raw frames to ffmpeg, the codec chosen by the file's extension: H.264 yuv420p for .mp4,
/// .mov (+faststart, so browsers play the file) and .mkv; VP9 for .webm; GIF with one palette
/// for .gif. Any other extension is a RenderError before ffmpeg starts. A video ffmpeg printed an
/// error about is a failure, whatever its exit status, with ffmpeg's words in the message.
/// The output appears under its final name only after finish() succeeded. An ffmpeg that stops
/// reading (or never exits) is an error after `stall_timeout` without progress, not a hang.
class VideoWriter {
public:
    /// Starts ffmpeg; throws RenderError when it cannot (missing ffmpeg, odd size).
    VideoWriter(const std::filesystem::path& file, int width, int height, int fps,
                std::chrono::milliseconds stall_timeout = std::chrono::seconds(60));
    ~VideoWriter();  ///< abandons an unfinished video (the partial file is removed)
    VideoWriter(const VideoWriter&) = delete;
    VideoWriter& operator=(const VideoWriter&) = delete;

    /// Throws RenderError if ffmpeg died, or accepted no byte for the stall timeout.
    void addFrame(const Image& image);
    /// Waits for ffmpeg (at most the stall timeout); throws RenderError on failure.
    void finish();
    /// The encoder's user + system CPU seconds, once finish() has succeeded (0 before).
    double encoderCpuSeconds() const { return encoder_cpu_s_; }

private:
    void abandon() noexcept;  ///< kills ffmpeg (our child, by pid) and removes the partial file

    std::filesystem::path file_;
    std::filesystem::path partial_;
    int width_;
    int height_;
    std::chrono::milliseconds stall_timeout_;
    int pipe_fd_ = -1;  ///< write end of ffmpeg's stdin, non-blocking
    int pid_ = -1;      ///< ffmpeg's process id while it runs
    /// ffmpeg's stderr: an unnamed temporary file, read at finish(). With -loglevel error,
    /// anything in it is an error, even when ffmpeg exits 0 (ffmpeg 5.1 does after "Error
    /// writing trailer ...: No space left on device", leaving a truncated file).
    std::FILE* log_ = nullptr;
    double encoder_cpu_s_ = 0;
};

}  // namespace render
