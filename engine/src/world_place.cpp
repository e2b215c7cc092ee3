// engine/src/world_place.cpp -- a world's state read out and put back for showing: what a
// recording keeps of a frame (engine/recording.h) and what `cdlab serve --replay` shows of it.
#include <stdexcept>
#include <string>

#include "engine/world.h"
#include "world_records.h"

namespace engine {

WorldState World::state() const {
    WorldState out;
    out.time = time_;
    out.steps = step_count_;
    out.bodies.reserve(bodies_.size());
    for (const Body& b : bodies_) {
        out.bodies.push_back({b.position, b.orientation, b.linear_momentum, b.angular_momentum});
    }
    out.chains.reserve(chain_state_.size());
    for (const ChainState& c : chain_state_) out.chains.push_back({c.clock, c.halted});
    return out;
}

void World::place(const WorldState& state, std::span<const ToiEvent> impacts,
                  const std::optional<StepStats>& reported) {
    if (state.bodies.size() != bodies_.size() || state.chains.size() != chain_state_.size()) {
        throw std::invalid_argument(
            "place: a state of " + std::to_string(state.bodies.size()) + " bodies and " +
            std::to_string(state.chains.size()) + " chains, for a world of " +
            std::to_string(bodies_.size()) + " bodies and " +
            std::to_string(chain_state_.size()) + " chains");
    }
    time_ = state.time;
    step_count_ = state.steps;
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
        const BodyMotion& m = state.bodies[i];
        Body& b = bodies_[i];
        b.position = m.position;
        b.orientation = m.orientation;
        b.linear_momentum = m.linear_momentum;
        b.angular_momentum = m.angular_momentum;
    }
    for (std::size_t c = 0; c < chain_state_.size(); ++c) {
        chain_state_[c].clock = state.chains[c].time;
        chain_state_[c].step_start = state.chains[c].time;
        chain_state_[c].halted = state.chains[c].halted;
    }
    for (DeformingMesh& d : deforming_) deformBody(d);
    detect();
    if (reported) stats_ = *reported;
    toi_events_.assign(impacts.begin(), impacts.end());
}

}  // namespace engine
