// app/lab/exit_codes.h -- the exit codes every cdlab command returns (README, "Exit codes").
#pragma once

namespace app {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;       ///< the run failed (I/O, simulation error, a check)
inline constexpr int kExitBadInput = 2;      ///< bad scene file or flags; nothing was done
inline constexpr int kExitCheckFailed = 3;   ///< run --check-broadphase found a difference

}  // namespace app
