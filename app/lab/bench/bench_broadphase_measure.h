// app/lab/bench/bench_broadphase_measure.h -- timing one broad-phase method (runMethod, declared in
// bench_rows.h) and the clocks and counts the report shares with it.
#pragma once

#include <vector>

#include "bench_broadphase.h"

namespace app {

/// Frames in the "first" and "last" medians of a row.
inline constexpr int kEdgeFrames = 100;

/// The median of `v` (the mean of the two middle values when even); NaN when empty.
double median(std::vector<double> v);
/// This thread's CPU time, s.
double threadCpuSeconds();
/// Repetitions of a one-shot table (create + insert + find pairs each): --frames, at most 100.
int oneShotRepetitions(const BenchOptions& options);

}  // namespace app
