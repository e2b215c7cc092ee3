// render/src/image.cpp -- PNG files through libpng's simplified API, and the ffmpeg video pipe.
// Invariant: an output file exists under its final name only when it is complete. Every writer
// writes a sibling ".partial" file and renames it at the end (render/output_file.h: only ever over
// a regular file); failures remove the partial file.
#include "render/image.h"

#include <fcntl.h>
#include <png.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "render/output_file.h"

extern char** environ;

namespace render {
namespace fs = std::filesystem;

namespace {

std::string errnoText(int err) { return std::error_code(err, std::generic_category()).message(); }

// Writes to a pipe without letting SIGPIPE kill the process when the reader has died: the
// signal is blocked in this thread for the duration, and a SIGPIPE raised by our write is
// consumed before unblocking (the classic library-safe pattern; the process's handlers are
// never touched). Returns false when the reader is gone or the write failed.
class SigpipeGuard {
public:
    SigpipeGuard() {
        sigemptyset(&pipe_set_);
        sigaddset(&pipe_set_, SIGPIPE);
        sigset_t pending;
        sigemptyset(&pending);
        sigpending(&pending);
        was_pending_ = sigismember(&pending, SIGPIPE) == 1;
        pthread_sigmask(SIG_BLOCK, &pipe_set_, &old_mask_);
    }
    ~SigpipeGuard() {
        if (!was_pending_) {
            // Swallow the SIGPIPE our own write raised, if any, so unblocking does not deliver it.
            const timespec zero{0, 0};
            while (sigtimedwait(&pipe_set_, nullptr, &zero) == SIGPIPE) {
            }
        }
        pthread_sigmask(SIG_SETMASK, &old_mask_, nullptr);
    }
    SigpipeGuard(const SigpipeGuard&) = delete;
    SigpipeGuard& operator=(const SigpipeGuard&) = delete;

private:
    sigset_t pipe_set_;
    sigset_t old_mask_;
    bool was_pending_ = false;
};

void checkImage(const Image& image, const char* what) {
    if (image.width <= 0 || image.height <= 0 ||
        image.rgb.size() != std::size_t(image.width) * std::size_t(image.height) * 3) {
        throw RenderError(std::string(what) + ": image is " + std::to_string(image.width) + "x" +
                          std::to_string(image.height) + " with " +
                          std::to_string(image.rgb.size()) + " bytes (expected w*h*3)");
    }
}

}  // namespace

namespace {

// PNG compression chosen by measuring every zlib level (1, 2, 3, 6, 9) with each row filter and
// strategy on coursework frames at 1280x720 (README, "Output"): libpng's simplified API (zlib
// level 6, adaptive filters) took 44 ms a frame for 81 KiB; level 2 with the Up filter takes
// 6.5 ms for 99 KiB. The Up filter suits these pictures (flat background, long horizontal edges
// of wireframes repeated row to row); adaptive filtering and higher levels cost two to ten times
// the time for 2-20 % smaller files. Pixels are the same at every level.
constexpr int kPngZlibLevel = 2;
constexpr int kPngFilters = PNG_FILTER_UP;

void appendPngBytes(png_structp png, png_bytep data, png_size_t length) {
    auto* bytes = static_cast<std::string*>(png_get_io_ptr(png));
    bytes->append(reinterpret_cast<const char*>(data), length);
}

void flushNothing(png_structp) {}

// The PNG file's bytes, or false with libpng's message. Only C calls and trivially destructible
// locals between setjmp and a longjmp from libpng's error handler.
bool encodePng(const Image& image, std::string& bytes, std::string& message) {
    std::vector<png_bytep> rows(std::size_t(image.height));
    for (int y = 0; y < image.height; ++y) {
        rows[std::size_t(y)] = const_cast<png_bytep>(image.pixel(0, y));
    }
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &message,
                                              [](png_structp p, png_const_charp text) {
                                                  *static_cast<std::string*>(png_get_error_ptr(p)) =
                                                      text;
                                                  png_longjmp(p, 1);
                                              },
                                              nullptr);
    if (png == nullptr) {
        message = "cannot allocate a PNG writer";
        return false;
    }
    png_infop info = png_create_info_struct(png);
    if (info == nullptr || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        if (message.empty()) message = "cannot allocate a PNG writer";
        return false;
    }
    png_set_write_fn(png, &bytes, appendPngBytes, flushNothing);
    png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_set_compression_level(png, kPngZlibLevel);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, kPngFilters);
    png_write_info(png, info);
    png_write_image(png, rows.data());
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return true;
}

}  // namespace

std::string pngBytes(const Image& image) {
    checkImage(image, "a PNG in memory");
    std::string bytes;
    bytes.reserve(image.rgb.size() / 8);
    std::string message;
    if (!encodePng(image, bytes, message)) throw RenderError("cannot encode PNG: " + message);
    return bytes;
}

void writePng(const fs::path& file, const Image& image) {
    checkImage(image, file.c_str());
    std::string bytes;
    bytes.reserve(image.rgb.size() / 8);
    std::string message;
    if (!encodePng(image, bytes, message)) {
        throw RenderError(file.string() + ": cannot write PNG: " + message);
    }
    writeFileAtomically(file, bytes);
}

Image readPng(const fs::path& file) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&png, file.c_str())) {
        const std::string message = png.message;
        png_image_free(&png);
        throw RenderError(file.string() + ": cannot read PNG: " + message);
    }
    png.format = PNG_FORMAT_RGB;
    Image image;
    image.width = static_cast<int>(png.width);
    image.height = static_cast<int>(png.height);
    image.rgb.resize(PNG_IMAGE_SIZE(png));
    // An alpha channel is composited onto black, the way a viewer without alpha shows it.
    const png_color black{0, 0, 0};
    if (!png_image_finish_read(&png, &black, image.rgb.data(), 0, nullptr)) {
        const std::string message = png.message;
        png_image_free(&png);
        throw RenderError(file.string() + ": cannot read PNG: " + message);
    }
    return image;
}

bool ffmpegAvailable() {
    const char* path = std::getenv("PATH");
    if (!path) return false;
    std::string_view rest(path);
    while (true) {
        const std::size_t colon = rest.find(':');
        const std::string_view dir = rest.substr(0, colon);
        const fs::path candidate = fs::path(dir.empty() ? "." : std::string(dir)) / "ffmpeg";
        struct stat st {};
        if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
            ::access(candidate.c_str(), X_OK) == 0) {
            return true;
        }
        if (colon == std::string_view::npos) return false;
        rest.remove_prefix(colon + 1);
    }
}

namespace {

// What ffmpeg is asked to encode into each container Debian's ffmpeg writes: H.264 (mp4, mov,
// mkv; +faststart so browsers start playing before the end), VP9 at constant quality (webm;
// realtime speed, so a 300-frame run does not wait minutes), GIF with one palette made for the
// whole video (gif).
struct VideoContainer {
    std::string_view extension;
    std::vector<const char*> codec_args;
    bool needs_even_size;  ///< yuv420p halves the chroma resolution
};

const std::vector<VideoContainer>& videoContainers() {
    static const std::vector<VideoContainer> containers{
        {".mp4", {"-c:v", "libx264", "-pix_fmt", "yuv420p", "-movflags", "+faststart"}, true},
        {".mov", {"-c:v", "libx264", "-pix_fmt", "yuv420p", "-movflags", "+faststart"}, true},
        {".mkv", {"-c:v", "libx264", "-pix_fmt", "yuv420p"}, true},
        {".webm",
         {"-c:v", "libvpx-vp9", "-pix_fmt", "yuv420p", "-b:v", "0", "-crf", "32", "-deadline",
          "realtime", "-cpu-used", "8"},
         true},
        {".gif",
         {"-filter_complex", "[0:v]split[a][b];[a]palettegen[p];[b][p]paletteuse", "-c:v", "gif"},
         false},
    };
    return containers;
}

const VideoContainer* findVideoContainer(const fs::path& file) {
    const std::string ext = file.has_extension() ? file.extension().string() : ".mp4";
    for (const VideoContainer& c : videoContainers()) {
        if (c.extension == ext) return &c;
    }
    return nullptr;
}

}  // namespace

std::string supportedVideoExtensions() {
    std::string list;
    for (const VideoContainer& c : videoContainers()) {
        if (!list.empty()) list += ", ";
        list += c.extension;
    }
    return list;
}

bool isSupportedVideoFile(const fs::path& file) { return findVideoContainer(file) != nullptr; }

VideoWriter::VideoWriter(const fs::path& file, int width, int height, int fps,
                         std::chrono::milliseconds stall_timeout)
    : file_(file), width_(width), height_(height), stall_timeout_(stall_timeout) {
    const VideoContainer* container = findVideoContainer(file);
    if (container == nullptr) {
        throw RenderError(file.string() + ": unsupported video container '" +
                          file.extension().string() + "' (supported: " +
                          supportedVideoExtensions() + ")");
    }
    if (width <= 0 || height <= 0 ||
        (container->needs_even_size && (width % 2 != 0 || height % 2 != 0))) {
        throw RenderError(file.string() + ": video size " + std::to_string(width) + "x" +
                          std::to_string(height) + " must be positive" +
                          (container->needs_even_size ? " and even (yuv420p)" : ""));
    }
    if (fps <= 0) {
        throw RenderError(file.string() + ": video fps " + std::to_string(fps) + " must be > 0");
    }
    // ffmpeg picks the container from the extension, so the partial name keeps it last:
    // "clip.mp4" is written as "clip.partial.mp4".
    const fs::path ext = file.has_extension() ? file.extension() : fs::path(".mp4");
    checkOutputPath(file);
    partial_ = file;
    partial_.replace_extension(".partial" + ext.string());
    claimPartial(partial_);

    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) {
        throw RenderError(file.string() + ": cannot create a pipe to ffmpeg: " + errnoText(errno));
    }
    const std::string size = std::to_string(width) + "x" + std::to_string(height);
    const std::string rate = std::to_string(fps);
    const std::string out = partial_.string();
    std::vector<const char*> argv = {"ffmpeg", "-y",         "-loglevel", "error",
                                     "-f",     "rawvideo",   "-pix_fmt",  "rgb24",
                                     "-s",     size.c_str(), "-r",        rate.c_str(),
                                     "-i",     "-"};
    argv.insert(argv.end(), container->codec_args.begin(), container->codec_args.end());
    argv.push_back(out.c_str());
    argv.push_back(nullptr);
    log_ = std::tmpfile();
    if (log_ == nullptr) {
        const int err = errno;
        ::close(fds[0]);
        ::close(fds[1]);
        throw RenderError(file.string() + ": cannot make a file for ffmpeg's messages: " +
                          errnoText(err));
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, ::fileno(log_), STDERR_FILENO);
    // dup2 clears close-on-exec on fd 0 only; the child never holds our write end, so closing
    // it is the end-of-stream that lets ffmpeg finish.
    posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
    pid_t pid = -1;
    const int spawn_error =
        ::posix_spawnp(&pid, "ffmpeg", &actions, nullptr, const_cast<char* const*>(argv.data()),
                       environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[0]);
    if (spawn_error != 0) {
        ::close(fds[1]);
        throw RenderError(file.string() + ": cannot start ffmpeg: " + errnoText(spawn_error));
    }
    pid_ = pid;
    pipe_fd_ = fds[1];
    // Non-blocking, so a frame write waits in poll() with a deadline instead of in write().
    const int flags = ::fcntl(pipe_fd_, F_GETFL);
    if (flags < 0 || ::fcntl(pipe_fd_, F_SETFL, flags | O_NONBLOCK) != 0) {
        const int err = errno;
        abandon();
        throw RenderError(file.string() + ": cannot set up the pipe to ffmpeg: " + errnoText(err));
    }
}

VideoWriter::~VideoWriter() { abandon(); }

void VideoWriter::abandon() noexcept {
    if (pipe_fd_ >= 0) {
        ::close(pipe_fd_);
        pipe_fd_ = -1;
    }
    if (pid_ > 0) {
        // Our own child, by id: stop it rather than let it encode a video nobody keeps.
        ::kill(pid_, SIGKILL);
        int status = 0;
        while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
        }
        pid_ = -1;
    }
    if (!partial_.empty()) removeQuietly(partial_);
    if (log_ != nullptr) {
        std::fclose(log_);
        log_ = nullptr;
    }
}

void VideoWriter::addFrame(const Image& image) {
    if (pipe_fd_ < 0) throw RenderError(file_.string() + ": video already finished or abandoned");
    if (image.width != width_ || image.height != height_ ||
        image.rgb.size() != std::size_t(width_) * std::size_t(height_) * 3) {
        throw RenderError(file_.string() + ": frame is " + std::to_string(image.width) + "x" +
                          std::to_string(image.height) + ", video is " + std::to_string(width_) +
                          "x" + std::to_string(height_));
    }
    // Each wait for room in the pipe is bounded by the stall timeout: progress resets it.
    const std::uint8_t* data = image.rgb.data();
    std::size_t left = image.rgb.size();
    SigpipeGuard guard;
    while (left > 0) {
        const ssize_t n = ::write(pipe_fd_, data, left);
        if (n > 0) {
            data += n;
            left -= static_cast<std::size_t>(n);
            continue;
        }
        if (n < 0 && errno == EINTR) continue;
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            pollfd p{pipe_fd_, POLLOUT, 0};
            const int ready = ::poll(&p, 1, static_cast<int>(stall_timeout_.count()));
            if (ready > 0 || (ready < 0 && errno == EINTR)) continue;
            if (ready == 0) {
                abandon();
                throw RenderError(file_.string() + ": ffmpeg accepted no frame data for " +
                                  std::to_string(stall_timeout_.count()) +
                                  " ms (stalled encoder; the video was abandoned)");
            }
        }
        const int err = errno;
        abandon();
        throw RenderError(file_.string() + ": ffmpeg stopped accepting frames: " + errnoText(err));
    }
}

void VideoWriter::finish() {
    if (pipe_fd_ < 0 || pid_ <= 0) {
        throw RenderError(file_.string() + ": video already finished or abandoned");
    }
    const bool closed = ::close(pipe_fd_) == 0;
    pipe_fd_ = -1;
    // ffmpeg finishes encoding after end of input: wait for it, but not forever.
    int status = 0;
    pid_t waited = 0;
    const auto deadline = std::chrono::steady_clock::now() + stall_timeout_;
    rusage usage{};
    while ((waited = ::wait4(pid_, &status, WNOHANG, &usage)) == 0 ||
           (waited < 0 && errno == EINTR)) {
        if (std::chrono::steady_clock::now() > deadline) {
            abandon();
            throw RenderError(file_.string() + ": ffmpeg did not finish within " +
                              std::to_string(stall_timeout_.count()) +
                              " ms after the last frame (stalled encoder; the video was abandoned)");
        }
        const timespec pause{0, 5'000'000};
        ::nanosleep(&pause, nullptr);
    }
    pid_ = -1;
    if (waited > 0) {
        encoder_cpu_s_ = double(usage.ru_utime.tv_sec) + 1e-6 * double(usage.ru_utime.tv_usec) +
                         double(usage.ru_stime.tv_sec) + 1e-6 * double(usage.ru_stime.tv_usec);
    }
    const bool exited_ok = waited > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
    std::error_code ec;
    const bool has_output = fs::file_size(partial_, ec) > 0 && !ec;
    // What ffmpeg said (at most 1 KiB of it, on one line).
    std::string said;
    if (log_ != nullptr) {
        std::rewind(log_);
        char buffer[1024];
        said.assign(buffer, std::fread(buffer, 1, sizeof buffer, log_));
        std::fclose(log_);
        log_ = nullptr;
        while (!said.empty() && std::isspace(static_cast<unsigned char>(said.back()))) said.pop_back();
        for (char& c : said) c = c == '\n' ? ';' : c;
    }
    if (!closed || !exited_ok || !has_output || !said.empty()) {
        removeQuietly(partial_);
        std::string why =
            !closed      ? "the pipe to ffmpeg broke"
            : !exited_ok ? (WIFEXITED(status)
                                ? "ffmpeg exited with status " + std::to_string(WEXITSTATUS(status))
                                : std::string("ffmpeg was killed by a signal"))
                         : !has_output ? std::string("ffmpeg wrote no output")
                                       : std::string("ffmpeg reported an error");
        throw RenderError(file_.string() + ": video failed: " + why +
                          (said.empty() ? "" : " (ffmpeg: " + said + ")"));
    }
    const fs::path partial = partial_;
    partial_.clear();
    commitPartial(partial, file_);
}

}  // namespace render
