// app/lab/replay/replay_check.h -- `cdlab replay RECORDING`: what a recording holds and, with
// --check, the scene simulated again from its recorded settings and compared with it frame by
// frame: the first frame whose state hash differs is named with the first body and quantity
// that differ, which is how a divergence between two builds or machines is found.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>

namespace app {

struct ReplayOptions {
    std::filesystem::path recording;
    /// The scene file, when it has moved since the recording (its bytes must be the same).
    std::optional<std::filesystem::path> scene;
    bool check = false;         ///< simulate again and compare every frame
    std::optional<int> frames;  ///< compare only frames 0..frames-1
    /// Open the recording and load its scene, then return 0 (`cdlab --dry-run replay ...`).
    bool dry_run = false;
};

/// 0: summary printed, or every frame compared equal; 2: bad input (not a recording, a scene
/// that changed, bad flags); 3: a frame differs (named on `out`); 1: the simulation failed.
int replayRecording(const ReplayOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app
