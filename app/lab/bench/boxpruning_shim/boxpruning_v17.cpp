// app/lab/bench/boxpruning_shim/boxpruning_v17.cpp -- boxPruningV17() over his CompleteBoxPruning.
#include "boxpruning_v17.h"

#include "Stdafx.h"

namespace app {

std::span<const std::uint32_t> boxPruningV17(const float* boxes, std::uint32_t n) {
    static_assert(sizeof(AABB) == 6 * sizeof(float));
    static thread_local Container found;
    found.Reset();
    if (n == 0) return {};
    Meshmerizer::CompleteBoxPruning(n, reinterpret_cast<const AABB*>(boxes), found);
    return {found.GetEntries(), found.GetNbEntries()};
}

}  // namespace app
