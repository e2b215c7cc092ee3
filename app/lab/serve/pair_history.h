// app/lab/serve/pair_history.h -- every frame's flagged and confirmed pairs as a session first
// reaches it, so the page can show one pair's history: the frames it was flagged and confirmed,
// as ranges.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "collision/broadphase/broad_phase.h"

namespace app {

class PairHistory {
public:
    /// Frames of ranges (inclusive) and how many frames were looked at.
    struct Ranges {
        std::vector<std::pair<int, int>> flagged;
        std::vector<std::pair<int, int>> colliding;
        int frames = 0;
    };

    /// The most pairs kept over all frames (256 MB); frames past it are not kept, and
    /// frames() says how far the history goes.
    static constexpr std::size_t kMaxPairs = std::size_t(1) << 25;

    /// Frame frames()'s pairs, in any order; any other frame (one reached again, or one past a
    /// gap) is ignored, as is every frame once kMaxPairs are kept.
    void add(int frame, std::span<const collision::ProxyPair> flagged,
             std::span<const collision::ProxyPair> colliding);
    /// Frames 0..frames()-1 are kept.
    int frames() const { return static_cast<int>(flagged_.size()); }
    /// The frames pair (a, b) (either order) was flagged and confirmed in.
    Ranges of(collision::ProxyId a, collision::ProxyId b) const;

private:
    std::vector<std::vector<collision::ProxyPair>> flagged_;  ///< per frame, sorted
    std::vector<std::vector<collision::ProxyPair>> colliding_;
    std::size_t kept_ = 0;
    bool full_ = false;
};

}  // namespace app
