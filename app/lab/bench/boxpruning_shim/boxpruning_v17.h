// app/lab/bench/boxpruning_shim/boxpruning_v17.h -- a plain entry to Terdiman's BoxPruning17
// CompleteBoxPruning (compiled from CDLAB_BOXPRUNING_DIR when set), for the broad-phase bench and
// its test. Bench only: never part of the library.
#pragma once

#include <cstdint>
#include <span>

namespace app {

/// Box i is the six floats boxes[6i .. 6i+5]: min x y z, max x y z. Returns the overlapping
/// pairs as consecutive indices, in his order, in a buffer of the calling thread that the next
/// call reuses.
std::span<const std::uint32_t> boxPruningV17(const float* boxes, std::uint32_t n);

}  // namespace app
