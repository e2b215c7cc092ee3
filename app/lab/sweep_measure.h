// app/lab/sweep_measure.h -- one run of `cdlab sweep`: the scene simulated for the sweep's interval,
// its stage times, counters, accuracy measures and memory, and its comparison with the
// reference run pair by pair through first-contact times.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "engine/scene.h"
#include "sweep.h"

namespace app::sweep {

using PairKey = std::pair<collision::ProxyId, collision::ProxyId>;
/// Every pair a run saw in contact, with the simulated time it first did.
using FirstContacts = std::map<PairKey, double>;

/// "key=value key=value", or "scene as written" without overrides.
std::string labelOf(const std::vector<engine::SceneOverride>& overrides);

/// Runs `scene` for `duration` simulated seconds and measures it; records every pair's first
/// contact in `first` (confirmed at a step's end, stopped by CCD, or pushed by the solver).
SweepRun measure(const engine::Scene& scene, double duration, FirstContacts& first);

/// Missed and extra pairs and first-contact errors of `run` against the reference's contacts.
void compareWithReference(SweepRun& run, const FirstContacts& mine, const FirstContacts& ref);

}  // namespace app::sweep
