// engine/src/stage_clock.h -- the clock the world's stages are timed by (StepStats' seconds).
#pragma once

#include <chrono>

namespace engine {

using StageClock = std::chrono::steady_clock;

/// Wall seconds from `start` to now.
inline double secondsSince(StageClock::time_point start) {
    return std::chrono::duration<double>(StageClock::now() - start).count();
}

}  // namespace engine
