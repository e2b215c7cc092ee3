// tests/engine/recording_format_test.cpp -- the recording file (engine/recording.h): frames and
// header read back bit for bit, extreme values included; and a file that is cut anywhere, has any
// byte of its records changed, is of a newer version or is not a recording at all is refused
// with a RecordingError, never read past or half-read.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "engine/recording.h"

namespace recording_format_test {

namespace fs = std::filesystem;
using engine::Real;
using engine::Vec3;

fs::path tempFile(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / "cdlab_recording_format_test";
    fs::create_directories(dir);
    return dir / name;
}

std::string slurp(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void spit(const fs::path& file, const std::string& bytes) {
    std::ofstream(file, std::ios::binary | std::ios::trunc).write(bytes.data(),
                                                                 std::streamsize(bytes.size()));
}

engine::RecordingHeader header() {
    engine::RecordingHeader h;
    h.scene = "/some where/scène with spaces.yaml";
    h.scene_hash = 0xfedcba9876543210ull;
    h.overrides = {{"world.time_step", "0.01"}, {"bodies.2.name", "a=b: c"}};
    h.frames = 5;
    h.broad_phase = "hgrid";
    h.pair_order = collision::PairOrder::Found;
    h.steps_per_frame = 3;
    h.time_step = Real(1) / 180;
    h.bodies = 3;
    h.chains = 1;
    return h;
}

// Frame `k` of three bodies at the extremes of double: huge, tiny (subnormal), signed zero.
engine::RecordedFrame frame(int k) {
    const Real big = std::numeric_limits<Real>::max() / 3;
    const Real tiny = std::numeric_limits<Real>::denorm_min();
    engine::RecordedFrame f;
    f.frame = k;
    f.state_hash = 0x0123456789abcdefull + std::uint64_t(k);
    f.broad_phase = k % 2 ? "sap" : "tree";
    f.state.time = Real(k) / 60;
    f.state.steps = 3 * k;
    f.state.bodies = {
        {Vec3(big, -tiny, -0.0), engine::Quat(0.5, -0.5, 0.5, -0.5), Vec3(1e-300, 0, k),
         Vec3(-big, tiny, 1)},
        {Vec3(1e9 + k, 1e-9, 3), engine::Quat::Identity(), Vec3::Zero(), Vec3::Zero()},
        {Vec3(-7, 8, -9), engine::Quat(std::sqrt(0.5), 0, std::sqrt(0.5), 0), Vec3(2, 3, 4),
         Vec3(5, 6, 7)}};
    f.state.chains = {{Real(k) / 61, k == 4}};
    f.flagged = {{0, 1}, {0, 2}, {1, 2}};
    f.colliding = {{1, 2}};
    if (k == 2) {
        engine::ToiEvent e;
        e.a = 2;
        e.b = 0;
        e.t = Real(0.3125);
        e.pose_a = {Vec3(1, 2, 3), engine::Quat(0, 1, 0, 0)};
        e.pose_b = {Vec3(-tiny, big, 0), engine::Quat::Identity()};
        e.point = Vec3(0.5, 0.25, -0.125);
        e.normal = Vec3(0, 0, -1);
        e.failed = true;
        f.impacts.push_back(e);
    }
    f.counters.broad.volume_tests = 1000 + k;
    f.counters.broad.volumes_updated = 3;
    f.counters.narrow_tests = 3;
    f.counters.triangle_tests = std::numeric_limits<std::int64_t>::max();
    f.counters.toi_events = k == 2 ? 1 : 0;
    return f;
}

fs::path writeSmall(const std::string& name, int frames = 5, bool finish = true) {
    const fs::path file = tempFile(name);
    engine::RecordingWriter w(file, header());
    for (int k = 0; k < frames; ++k) w.write(frame(k));
    if (finish) w.finish();
    return file;
}

bool sameBits(const Vec3& a, const Vec3& b) { return std::memcmp(a.data(), b.data(), 24) == 0; }
bool sameBits(const engine::Quat& a, const engine::Quat& b) {
    return std::memcmp(a.coeffs().data(), b.coeffs().data(), 32) == 0;
}

// Opens `file` and reads every frame: what a viewer and replay --check do.
void readAll(const fs::path& file) {
    const engine::Recording r = engine::Recording::open(file);
    for (int k = 0; k < r.frames(); ++k) (void)r.frame(k);
}

TEST(RecordingFormat, FramesAndHeaderReadBackBitForBit) {
    const fs::path file = writeSmall("roundtrip.rec");
    const engine::Recording r = engine::Recording::open(file);
    const engine::RecordingHeader want = header();
    const engine::RecordingHeader& got = r.header();
    EXPECT_EQ(got.version, engine::kRecordingVersion);
    EXPECT_EQ(got.scene, want.scene);
    EXPECT_EQ(got.scene_hash, want.scene_hash);
    ASSERT_EQ(got.overrides.size(), 2u);
    EXPECT_EQ(got.overrides[1].key, "bodies.2.name");
    EXPECT_EQ(got.overrides[1].value, "a=b: c");
    EXPECT_EQ(got.frames, 5);
    EXPECT_EQ(got.broad_phase, "hgrid");
    EXPECT_EQ(got.pair_order, collision::PairOrder::Found);
    EXPECT_EQ(got.steps_per_frame, 3);
    EXPECT_EQ(got.time_step, want.time_step);
    EXPECT_EQ(got.bodies, 3u);
    EXPECT_EQ(got.chains, 1u);
    ASSERT_EQ(r.frames(), 5);
    EXPECT_EQ(r.ended(), "");
    EXPECT_EQ(r.bytes(), fs::file_size(file));
    for (const int k : {3, 0, 4, 2, 1, 2}) {
        SCOPED_TRACE("frame " + std::to_string(k));
        const engine::RecordedFrame a = frame(k);
        const engine::RecordedFrame b = r.frame(k);
        EXPECT_EQ(b.frame, k);
        EXPECT_EQ(b.state_hash, a.state_hash);
        EXPECT_EQ(b.broad_phase, a.broad_phase);
        EXPECT_EQ(std::memcmp(&b.state.time, &a.state.time, sizeof(Real)), 0);
        EXPECT_EQ(b.state.steps, a.state.steps);
        ASSERT_EQ(b.state.bodies.size(), 3u);
        for (std::size_t i = 0; i < 3; ++i) {
            EXPECT_TRUE(sameBits(b.state.bodies[i].position, a.state.bodies[i].position));
            EXPECT_TRUE(sameBits(b.state.bodies[i].orientation, a.state.bodies[i].orientation));
            EXPECT_TRUE(sameBits(b.state.bodies[i].linear_momentum, a.state.bodies[i].linear_momentum));
            EXPECT_TRUE(sameBits(b.state.bodies[i].angular_momentum, a.state.bodies[i].angular_momentum));
        }
        EXPECT_TRUE(std::signbit(b.state.bodies[0].position.z()));  // -0.0 stays negative
        ASSERT_EQ(b.state.chains.size(), 1u);
        EXPECT_EQ(b.state.chains[0].time, a.state.chains[0].time);
        EXPECT_EQ(b.state.chains[0].halted, a.state.chains[0].halted);
        EXPECT_EQ(b.flagged, a.flagged);
        EXPECT_EQ(b.colliding, a.colliding);
        ASSERT_EQ(b.impacts.size(), a.impacts.size());
        for (std::size_t i = 0; i < a.impacts.size(); ++i) {
            EXPECT_EQ(b.impacts[i].a, a.impacts[i].a);
            EXPECT_EQ(b.impacts[i].b, a.impacts[i].b);
            EXPECT_EQ(b.impacts[i].t, a.impacts[i].t);
            EXPECT_TRUE(sameBits(b.impacts[i].pose_b.position, a.impacts[i].pose_b.position));
            EXPECT_TRUE(sameBits(b.impacts[i].pose_a.orientation, a.impacts[i].pose_a.orientation));
            EXPECT_TRUE(sameBits(b.impacts[i].normal, a.impacts[i].normal));
            EXPECT_EQ(b.impacts[i].failed, a.impacts[i].failed);
        }
        EXPECT_EQ(b.counters.broad.volume_tests, a.counters.broad.volume_tests);
        EXPECT_EQ(b.counters.triangle_tests, a.counters.triangle_tests);
        EXPECT_EQ(b.counters.toi_events, a.counters.toi_events);
    }
    EXPECT_THROW((void)r.frame(5), engine::RecordingError);
    EXPECT_THROW((void)r.frame(-1), engine::RecordingError);
}

TEST(RecordingFormat, TheEndRecordSaysWhyARunStopped) {
    const fs::path file = tempFile("stopped.rec");
    {
        engine::RecordingWriter w(file, header());
        w.write(frame(0));
        w.write(frame(1));
        w.finish("stopped: frame 2: body 'a': position is not finite");
    }
    const engine::Recording r = engine::Recording::open(file);
    EXPECT_EQ(r.frames(), 2);
    EXPECT_EQ(r.ended(), "stopped: frame 2: body 'a': position is not finite");
}

TEST(RecordingFormat, AWriterTakesFramesInTurnAndOfTheHeadersShape) {
    engine::RecordingWriter w(tempFile("turns.rec"), header());
    EXPECT_THROW(w.write(frame(1)), std::invalid_argument);
    w.write(frame(0));
    engine::RecordedFrame two_bodies = frame(1);
    two_bodies.state.bodies.pop_back();
    EXPECT_THROW(w.write(two_bodies), std::invalid_argument);
    EXPECT_EQ(w.frames(), 1);
    EXPECT_THROW(engine::RecordingWriter(tempFile("no such folder") / "x.rec", header()),
                 engine::RecordingError);
}

TEST(RecordingFormat, AFileCutAnywhereIsRefused) {
    const fs::path whole = writeSmall("whole.rec", 3);
    const std::string bytes = slurp(whole);
    const fs::path cut = tempFile("cut.rec");
    for (std::size_t n = 0; n < bytes.size(); ++n) {
        spit(cut, bytes.substr(0, n));
        EXPECT_THROW(readAll(cut), engine::RecordingError) << "cut at byte " << n;
    }
    // One without its end record (a run killed) says so.
    const fs::path killed = writeSmall("killed.rec", 3, false);
    try {
        (void)engine::Recording::open(killed);
        ADD_FAILURE() << "a recording without its end record was opened";
    } catch (const engine::RecordingError& e) {
        EXPECT_NE(std::string(e.what()).find("cut short after 3 frames"), std::string::npos)
            << e.what();
    }
}

TEST(RecordingFormat, AnyChangedByteOfTheRecordsIsRefused) {
    const fs::path whole = writeSmall("flip.rec", 3);
    const std::string bytes = slurp(whole);
    std::uint32_t header_bytes = 0;
    std::memcpy(&header_bytes, bytes.data() + 12, 4);
    const std::size_t records = 16 + header_bytes;
    const fs::path flipped = tempFile("flipped.rec");
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        for (const unsigned char bit : {0x01}) {
            std::string b = bytes;
            b[i] = char(static_cast<unsigned char>(b[i]) ^ bit);
            spit(flipped, b);
            if (i >= records || i < 16) {
                EXPECT_THROW(readAll(flipped), engine::RecordingError)
                    << "byte " << i;
            } else {
                // A changed header is refused or read as another header, never crashes.
                try {
                    readAll(flipped);
                } catch (const engine::RecordingError&) {
                }
            }
        }
    }
}

TEST(RecordingFormat, OtherFilesAreRefusedByName) {
    const fs::path not_one = tempFile("scene.yaml");
    spit(not_one, "world: {}\n");
    try {
        (void)engine::Recording::open(not_one);
        ADD_FAILURE();
    } catch (const engine::RecordingError& e) {
        EXPECT_NE(std::string(e.what()).find(not_one.string() + ": not a cdlab recording"),
                  std::string::npos)
            << e.what();
    }
    std::string newer = slurp(writeSmall("v1.rec"));
    newer[8] = 2;
    const fs::path v2 = tempFile("v2.rec");
    spit(v2, newer);
    try {
        (void)engine::Recording::open(v2);
        ADD_FAILURE();
    } catch (const engine::RecordingError& e) {
        EXPECT_NE(std::string(e.what()).find("format version 2; this cdlab reads version 1"),
                  std::string::npos)
            << e.what();
    }
    std::string trailing = slurp(writeSmall("t.rec")) + "x";
    spit(v2, trailing);
    EXPECT_THROW((void)engine::Recording::open(v2), engine::RecordingError);
    EXPECT_THROW((void)engine::Recording::open(tempFile("absent.rec")), engine::RecordingError);
    EXPECT_THROW((void)engine::Recording::open(fs::temp_directory_path()), engine::RecordingError);
}

}  // namespace recording_format_test
