// engine/src/toi_query.h -- the continuous stage's one way of asking a time-of-impact query, for
// rigid pairs (world_continuous.cpp) and pairs with a chain link (world_chains.cpp).
#pragma once

#include "collision/ccd/ccd.h"
#include "engine/world.h"

namespace engine {

/// Runs `query` (a time-of-impact query reading `in`) and counts it in `stats`. A pair already
/// within the target gap at t = 0 (typically: stopped there by the previous step) is asked again
/// for half its present gap, with a quarter of it as tolerance, so a separating pair is free to
/// go and an approaching one still stops before contact.
template <typename Query>
collision::ToiOutput askTimeOfImpact(collision::ToiQuery& in, StepStats& stats, Query&& query) {
    collision::ToiOutput out = query();
    ++stats.toi_queries;
    stats.toi_iterations += out.iterations;
    if (out.state == collision::CcdState::Hit && out.t == 0 && out.distance > 0) {
        in.target_gap = out.distance / 2;
        in.tolerance = out.distance / 4;
        out = query();
        ++stats.toi_queries;
        stats.toi_iterations += out.iterations;
    }
    return out;
}

}  // namespace engine
