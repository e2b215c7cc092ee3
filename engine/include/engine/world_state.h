// engine/world_state.h -- the part of a world's state that shows it as it was: what
// World::state reads, World::place puts back and a recording keeps of each frame.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/body.h"

namespace engine {

/// What a step changes of one body, and all World::stateHash reads of it besides the overlap
/// states.
struct BodyMotion {
    Vec3 position = Vec3::Zero();
    Quat orientation = Quat::Identity();
    Vec3 linear_momentum = Vec3::Zero();
    Vec3 angular_momentum = Vec3::Zero();
};

/// A chain's clock: World::chainTime and chainHalted.
struct ChainClock {
    Real time = 0;
    bool halted = false;
};

/// The part of a world's state that shows it as it was (World::state, World::place): time,
/// bodies' motion, chains' clocks. What a recording keeps of a frame (engine/recording.h); not
/// enough to step on from (broad-phase coherence, solver warm starts are not in it).
struct WorldState {
    Real time = 0;
    std::int64_t steps = 0;
    std::vector<BodyMotion> bodies;
    std::vector<ChainClock> chains;
};

}  // namespace engine
