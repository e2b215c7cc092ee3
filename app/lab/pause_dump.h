// app/lab/pause_dump.h -- the data file written at a pause: every body's bounding volumes and state.
#pragma once

#include <string>

#include "engine/world.h"

namespace app {

/// The pause dump as JSON text: frame, time, broad phase and the volume it tests
/// ("broadphase_volume"), bodies (pose, sphere, AABB, OBB, state, and "volume_states": each
/// volume's state by its own overlap test, "apart" / "overlapping" / "colliding", as the pause
/// picture colours it), flagged and colliding pairs, and "overlapping_pairs" per volume kind
/// (all pair lists sorted, i < j). Numbers are printed to round-trip.
std::string pauseDumpJson(const engine::World& world, int frame);

}  // namespace app
