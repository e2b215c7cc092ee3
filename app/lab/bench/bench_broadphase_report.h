// app/lab/bench/bench_broadphase_report.h -- `cdlab bench broadphase`'s tables and JSON.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "bench_broadphase.h"
#include "bench_rows.h"
#include "bench_workload.h"

namespace app {

/// `value` printed with `fmt`, or "-" when it is not finite.
std::string numberText(const char* fmt, double value);
/// The rows as one table (`frames`: the run's frames, to star rows stopped early).
void printTable(std::ostream& out, const std::vector<Row>& rows, int frames);
/// A workload's heading: its size, scene and pairs per body (or the one-shot protocol).
void printWorkloadHead(std::ostream& out, const MovingBoxes& workload,
                       const std::vector<PairSummary>& reference, const BenchOptions& options,
                       bool one_shot);
/// One workload's rows: each method's ratio to the best peer under both rules, the table, the
/// fastest cdlab method, and notes on stopped runs and pair caches.
void reportWorkload(std::ostream& out, std::vector<Row>& rows, const BenchOptions& options,
                    int frames);
/// The rows as JSON, written to FILE.partial then renamed; false (reported on `err`) on failure.
bool writeBenchJson(const std::filesystem::path& file, const BenchOptions& options,
                    const std::vector<Row>& rows, std::ostream& err);

}  // namespace app
