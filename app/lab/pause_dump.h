// app/lab/pause_dump.h -- the data file written at a pause: every body's bounding volumes and state.
#pragma once

#include <string>

#include "engine/world.h"

namespace app {

/// The pause dump as JSON text: frame, time, broad phase, bodies (pose, sphere, AABB, OBB,
/// state), flagged and colliding pairs (sorted, i < j). Numbers are printed to round-trip.
std::string pauseDumpJson(const engine::World& world, int frame);

}  // namespace app
