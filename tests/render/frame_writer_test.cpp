// tests/render/frame_writer_test.cpp -- the run pipeline's writer threads: PNGs identical to the
// one-at-a-time writer, video frames in submission order, and every failure (a PNG that cannot
// be written, an encoder that dies) stopping the writer with an error instead of a run that
// looks complete.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "render/frame_writer.h"
#include "render/image.h"
#include "test_dir.h"

namespace {

namespace fs = std::filesystem;

constexpr int kW = 64;
constexpr int kH = 48;

// A fresh directory per test.
class FrameWriterDir : public cdlab_test::TempDir {
public:
    FrameWriterDir() : cdlab_test::TempDir("cdlab_frame_writer_") {}
};

// A frame with a gradient (so PNG filters have work) and a frame-specific grey level.
std::shared_ptr<render::Image> testFrame(int k) {
    auto image = std::make_shared<render::Image>();
    image->width = kW;
    image->height = kH;
    image->rgb.resize(std::size_t(kW) * kH * 3);
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            std::uint8_t* p = &image->rgb[(std::size_t(y) * kW + x) * 3];
            p[0] = std::uint8_t(x * 4);
            p[1] = std::uint8_t(y * 5);
            p[2] = std::uint8_t(k * 40);
        }
    }
    return image;
}

std::string readBytes(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string frameName(int k) { return "frame_" + std::to_string(k) + ".png"; }

// Eight frames through three PNG workers and a queue of two: every PNG is the file writePng
// writes for that frame, byte for byte, whatever worker wrote it.
TEST(FrameWriter, PngsAreTheBytesWritePngWrites) {
    FrameWriterDir dir;
    fs::create_directories(dir.path() / "serial");
    {
        render::FrameWriter writer(nullptr, 3, 2);
        for (int k = 0; k < 8; ++k) writer.submit(testFrame(k), dir.path() / frameName(k), 1);
        writer.finish();
        EXPECT_EQ(writer.times().png_files, 8);
        EXPECT_EQ(writer.times().video_frames, 0);
    }
    for (int k = 0; k < 8; ++k) {
        SCOPED_TRACE(k);
        const fs::path serial = dir.path() / "serial" / frameName(k);
        render::writePng(serial, *testFrame(k));
        const std::string bytes = readBytes(dir.path() / frameName(k));
        ASSERT_FALSE(bytes.empty());
        EXPECT_EQ(bytes, readBytes(serial));
        EXPECT_EQ(render::readPng(dir.path() / frameName(k)).rgb, testFrame(k)->rgb);
    }
}

// A file submitted twice (a frame seen again after stepping back) holds the second picture,
// even when the first is slower to compress and another worker takes the second: a large noisy
// frame, then a small one, to each of six files through four workers.
TEST(FrameWriter, AFileSubmittedTwiceHoldsTheLastPicture) {
    FrameWriterDir dir;
    auto large = std::make_shared<render::Image>();
    large->width = 1024;
    large->height = 768;
    large->rgb.resize(std::size_t(large->width) * large->height * 3);
    std::uint32_t noise = 12345;
    for (std::uint8_t& v : large->rgb) {
        noise = noise * 1664525u + 1013904223u;
        v = std::uint8_t(noise >> 24);
    }
    {
        render::FrameWriter writer(nullptr, 4, 8);
        for (int k = 0; k < 6; ++k) {
            writer.submit(large, dir.path() / frameName(k), 0);
            writer.submit(testFrame(k), dir.path() / frameName(k), 0);
        }
        writer.finish();
        EXPECT_EQ(writer.times().png_files, 12);
    }
    for (int k = 0; k < 6; ++k) {
        EXPECT_EQ(render::readPng(dir.path() / frameName(k)).rgb, testFrame(k)->rgb) << k;
    }
}

// A PNG path that is a directory cannot be written: the writer stops, and the error, naming the
// file, comes out of a later submit() or of finish(), never silently.
TEST(FrameWriter, AFailedPngStopsTheWriterWithTheFileNamed) {
    FrameWriterDir dir;
    fs::create_directories(dir.path() / frameName(3));
    std::string message;
    try {
        render::FrameWriter writer(nullptr, 2, 2);
        for (int k = 0; k < 40; ++k) writer.submit(testFrame(k % 6), dir.path() / frameName(k), 1);
        writer.finish();
    } catch (const render::RenderError& e) {
        message = e.what();
    }
    EXPECT_NE(message.find(frameName(3)), std::string::npos) << message;
    EXPECT_NE(message.find("is a directory"), std::string::npos) << message;
}

// Frames of distinct greys, each a given number of times: the video holds them in that order
// (decoded by ffmpeg, each frame's mean blue within H.264's loss of the grey submitted).
TEST(FrameWriter, VideoFramesComeInSubmissionOrder) {
    if (!render::ffmpegAvailable()) GTEST_SKIP() << "ffmpeg not on PATH";
    FrameWriterDir dir;
    const fs::path video = dir.path() / "order.mp4";
    const std::vector<int> greys = {0, 5, 1, 4, 2, 3};
    const std::vector<long> repeats = {1, 2, 1, 3, 1, 1};
    {
        render::FrameWriter writer(std::make_unique<render::VideoWriter>(video, kW, kH, 30), 2, 1);
        for (std::size_t i = 0; i < greys.size(); ++i) {
            writer.submit(testFrame(greys[i]), fs::path(), repeats[i]);
        }
        writer.finish();
        EXPECT_EQ(writer.times().video_frames, 9);
        EXPECT_EQ(writer.times().png_files, 0);
    }
    ASSERT_TRUE(fs::exists(video));
    const fs::path raw = dir.path() / "frames.rgb";
    const std::string cmd = "ffmpeg -loglevel error -i '" + video.string() +
                            "' -f rawvideo -pix_fmt rgb24 '" + raw.string() + "'";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const std::string bytes = readBytes(raw);
    const std::size_t frame_bytes = std::size_t(kW) * kH * 3;
    ASSERT_EQ(bytes.size(), 9 * frame_bytes);
    std::vector<int> expected;
    for (std::size_t i = 0; i < greys.size(); ++i) {
        for (long r = 0; r < repeats[i]; ++r) expected.push_back(greys[i] * 40);
    }
    for (std::size_t f = 0; f < expected.size(); ++f) {
        double blue = 0;
        for (std::size_t p = 0; p < std::size_t(kW) * kH; ++p) {
            blue += std::uint8_t(bytes[f * frame_bytes + p * 3 + 2]);
        }
        blue /= double(kW * kH);
        EXPECT_NEAR(blue, expected[f], 12) << "video frame " << f;
    }
}

// An encoder that exits at once: the writer reports it (from submit() or finish()), and no video
// file is left under its final or its partial name.
//
//   writer --frames--> [pipe] --x  fake "ffmpeg" (exit 3)
TEST(FrameWriter, AnEncoderThatDiesIsAnError) {
    FrameWriterDir dir;
    const cdlab_test::DeadFfmpegOnPath dead_ffmpeg(dir.path());
    std::string message;
    try {
        render::FrameWriter writer(
            std::make_unique<render::VideoWriter>(dir.path() / "dead.mp4", kW, kH, 30), 1, 2);
        // Past the pipe's 64 KiB buffer, so the writes themselves meet the closed pipe.
        for (int k = 0; k < 60; ++k) writer.submit(testFrame(k % 6), fs::path(), 1);
        writer.finish();
    } catch (const render::RenderError& e) {
        message = e.what();
    }
    EXPECT_NE(message.find("dead.mp4"), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(dir.path() / "dead.mp4"));
    EXPECT_FALSE(fs::exists(dir.path() / "dead.partial.mp4"));
}

// ffmpeg 5.1 exits 0 after "Error writing trailer ...: No space left on device" and leaves a
// truncated file, which was once renamed into place as complete. An encoder that reads every
// frame, writes a file, prints that and exits 0 is a failure naming what it said.
TEST(FrameWriter, AnEncoderThatReportsAnErrorAndExitsZeroIsAnError) {
    FrameWriterDir dir;
    const cdlab_test::DeadFfmpegOnPath lying_ffmpeg(
        dir.path(),
        "cat > /dev/null\n"
        "for last in \"$@\"; do :; done\n"
        "printf 'half a video' > \"$last\"\n"
        "echo \"[mp4 @ 0x55] Error writing trailer of $last: No space left on device\" >&2\n"
        "exit 0\n");
    std::string message;
    try {
        render::FrameWriter writer(
            std::make_unique<render::VideoWriter>(dir.path() / "full.mp4", kW, kH, 30), 1, 2);
        for (int k = 0; k < 6; ++k) writer.submit(testFrame(k), fs::path(), 1);
        writer.finish();
    } catch (const render::RenderError& e) {
        message = e.what();
    }
    EXPECT_NE(message.find("full.mp4: video failed: ffmpeg reported an error"), std::string::npos)
        << message;
    EXPECT_NE(message.find("No space left on device"), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(dir.path() / "full.mp4"));
    EXPECT_FALSE(fs::exists(dir.path() / "full.partial.mp4"));
}

// Images handed out for rendering come back for reuse once every writer is done with them.
TEST(FrameWriter, BlankFramesAreRecycled) {
    render::FrameWriter writer(nullptr, 1, 1);
    const render::Image* first = nullptr;
    {
        std::shared_ptr<render::Image> image = writer.blankFrame();
        first = image.get();
        image->rgb.resize(100);
    }
    std::shared_ptr<render::Image> again = writer.blankFrame();
    EXPECT_EQ(again.get(), first);
    EXPECT_GE(again->rgb.capacity(), 100u);
    writer.finish();
}

}  // namespace
