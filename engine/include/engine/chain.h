// engine/chain.h -- articulated chains in the World: each link is a kinematic body whose pose
// follows collision::chainFrames of the chain's prescribed joint trajectories; what the
// continuous stage does when a link's time of impact is found.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "collision/ccd/chain.h"
#include "engine/body.h"

namespace engine {

/// What a chain does when the continuous stage finds a time of impact of one of its links
/// (scene key `on_impact`).
enum class ChainImpact : std::uint8_t {
    /// The chain's clock halts at the earliest time of impact of any of its links: every link
    /// keeps its pose of that time for the rest of the run (a robot that stops on contact).
    Stop,
    /// The event is recorded (and drawn); the chain keeps its trajectory (report only, the
    /// answer of a motion planner's continuous query).
    Continue,
};
std::string_view chainImpactName(ChainImpact impact);  ///< "stop", "continue"

/// A chain of the World. Link i is body `links[i]`; the body's pose (its centre-of-mass frame)
/// is frame_i(t) * shape_in_link[i], frame_i from collision::chainFrames(chain, t).
struct ChainSpec {
    std::string name;
    collision::Chain chain;
    std::vector<BodyId> links;
    std::vector<Pose> shape_in_link;  ///< the body frame in the link frame
    /// Parent-child links are paired (broad phase, narrow phase, continuous stage) only when
    /// true (scene key `collide_adjacent`, default false).
    bool collide_adjacent = false;
    ChainImpact on_impact = ChainImpact::Stop;
};

}  // namespace engine
