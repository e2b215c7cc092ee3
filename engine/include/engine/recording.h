// engine/recording.h -- a run's frames kept on disk: after a header naming the scene (path and
// hash of its bytes) and the run's settings, per frame the world's state (WorldState), the
// broad phase in use, the flagged and confirmed pairs, the state hash and the counters the HUD
// shows. `cdlab run --record` writes one; `cdlab serve --replay` shows any frame of it without
// simulating; `cdlab replay --check` simulates the scene again and names the first frame whose
// state hash differs. The byte layout (version 1) is in docs/recording.md.
//
// Cost: 104 bytes per body per frame (13 doubles: position, orientation, both momenta, every
// bit, so a placed state has the recorded hash), 8 per pair, 9 per chain, 177 per time of
// impact of the frame's last step, about 150 per frame.
//
// A recording is read with the care of a scene file: a file that is not one, of a newer version,
// cut short (no end record: the run was stopped), with a frame whose checksum, counts or values
// are wrong is refused with a RecordingError naming the file and the frame; never read past.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "engine/scene.h"
#include "engine/world.h"

namespace engine {

inline constexpr int kRecordingVersion = 1;

/// A file that is not a readable recording, or one that cannot be written. what() begins with
/// the file's path.
class RecordingError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// What a recording says of the run that wrote it: enough to load the same scene again.
struct RecordingHeader {
    int version = kRecordingVersion;
    std::filesystem::path scene;    ///< the scene file, absolute, as it was when recorded
    std::uint64_t scene_hash = 0;   ///< fileHash of the scene file when recorded
    std::vector<SceneOverride> overrides;  ///< `--set KEY=VALUE`, in order
    int frames = 0;                 ///< frames the run had (after --frames)
    std::string broad_phase;        ///< the run's broad phase at frame 0 (after --broadphase)
    collision::PairOrder pair_order = collision::PairOrder::Sorted;
    int steps_per_frame = 1;
    Real time_step = 0;
    std::size_t bodies = 0;
    std::size_t chains = 0;
};

/// One frame as recorded. `counters` holds the last step's counters (times are zero).
struct RecordedFrame {
    int frame = 0;
    std::uint64_t state_hash = 0;  ///< World::stateHash
    std::string broad_phase;
    WorldState state;
    std::vector<collision::ProxyPair> flagged;    ///< World::flaggedPairs, in its order
    std::vector<collision::ProxyPair> colliding;  ///< World::collidingPairs
    std::vector<ToiEvent> impacts;                ///< World::toiEvents of the last step
    StepStats counters;
};

/// The header of a recording of `scene`, loaded from `scene_file` with `overrides` and then
/// given its run's frame count, broad phase and pair order (the values `scene` holds now).
/// Throws RecordingError when the scene file cannot be read for its hash.
RecordingHeader recordingHeader(const std::filesystem::path& scene_file,
                                const std::vector<SceneOverride>& overrides, const Scene& scene);

/// The frame `frame` of `world` now: its state, pairs, hash, broad phase and last step's counters.
RecordedFrame recordFrame(const World& world, int frame);

/// FNV-1a (64 bits) of a file's bytes; throws RecordingError when it cannot be read.
std::uint64_t fileHash(const std::filesystem::path& file);

/// Writes a recording frame by frame. Not thread-safe.
class RecordingWriter {
public:
    /// Creates (or truncates) `file` and writes the header. Throws RecordingError.
    RecordingWriter(const std::filesystem::path& file, const RecordingHeader& header);
    /// Appends the next frame; frames come 0, 1, 2, ... with the header's body and chain counts
    /// (std::invalid_argument otherwise). Throws RecordingError when the write fails.
    void write(const RecordedFrame& frame);
    /// Writes the end record (frames written, and `ended`: "" for a run that completed, else why
    /// it stopped) and closes the file. Without it the recording is refused as cut short.
    void finish(const std::string& ended = "");
    int frames() const { return frames_; }
    std::uint64_t bytes() const { return bytes_; }
    const std::filesystem::path& file() const { return file_; }

private:
    void putRecord(const std::string& record, std::uint32_t tag);

    std::filesystem::path file_;
    std::ofstream out_;
    RecordingHeader header_;
    int frames_ = 0;
    std::uint64_t bytes_ = 0;
    bool finished_ = false;
};

/// A recording opened for reading: its header and an index of its frames, read one at a time
/// from the file. Not thread-safe (one reader at a time).
class Recording {
public:
    /// Opens and indexes `file` (a scan of the record lengths, not of every byte). Throws
    /// RecordingError for a file that is not a whole recording of a version this build reads.
    static Recording open(const std::filesystem::path& file);

    const RecordingHeader& header() const { return header_; }
    const std::filesystem::path& file() const { return file_; }
    /// Frames held: 0 .. frames() - 1.
    int frames() const { return static_cast<int>(offsets_.size()); }
    /// "" for a run that completed, else why it stopped (the end record's word).
    const std::string& ended() const { return ended_; }
    std::uint64_t bytes() const { return bytes_; }
    /// Frame `k` (0 <= k < frames()), read and checked: its checksum, frame number, counts,
    /// pair indices and finite values. Throws RecordingError naming the frame.
    RecordedFrame frame(int k) const;

private:
    std::filesystem::path file_;
    mutable std::ifstream in_;
    RecordingHeader header_;
    std::vector<std::uint64_t> offsets_;  ///< of each frame record's tag
    std::string ended_;
    std::uint64_t bytes_ = 0;
};

}  // namespace engine
