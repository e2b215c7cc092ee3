// app/lab/bench/bench_peer_tuning.cpp -- each peer compared at its best: every configuration of its
// grid runs as long as the measured run, ranked by its own median (a short trial would rank a
// DBVT whose tree degrades over hundreds of frames by its good start).
#include "bench_peer_tuning.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace app {

namespace {

// Of one peer's configurations (rows of `sweep` from `first` on), the fastest by `ms`: among
// those that ran every frame, or, when none did, among those stopped by the budget.
const Row* fastestConfig(const std::vector<Row>& sweep, std::size_t first, double RunResult::*ms) {
    const Row* best = nullptr;
    for (const bool stopped : {false, true}) {
        for (std::size_t i = first; i < sweep.size(); ++i) {
            const Row& row = sweep[i];
            if (!usable(row) || (row.result.budget_hit != 0) != stopped) continue;
            if (best == nullptr || row.result.*ms < best->result.*ms) best = &row;
        }
        if (best != nullptr) return best;
    }
    return nullptr;
}

}  // namespace

void setRatios(std::vector<Row>& rows) {
    double best = std::numeric_limits<double>::infinity();
    double best_exact = best;
    for (const Row& row : rows) {
        if (!usable(row)) continue;
        best = std::min(best, row.result.median_ms);
        best_exact = std::min(best_exact, row.result.exact_median_ms);
    }
    for (Row& row : rows) {
        if (!usable(row) || !std::isfinite(best)) continue;
        row.ratio = row.result.median_ms / best;
        row.exact_ratio = row.result.exact_median_ms / best_exact;
    }
}

void tunePeers(const TableRun& run, std::vector<Row>& rows, std::vector<Row>& sweep) {
    BenchOptions tuning = run.options;
    tuning.budget_seconds = run.options.budget_seconds > 0
                                ? std::min(run.options.budget_seconds, kTuneBudgetSeconds)
                                : kTuneBudgetSeconds;
    std::vector<std::string> families;
    for (const BenchMethodEntry& m : benchMethods()) {
        if (!m.family.empty() &&
            std::find(families.begin(), families.end(), m.family) == families.end()) {
            families.push_back(m.family);
        }
    }
    for (const std::string& family : families) {
        const std::size_t first = sweep.size();
        int configs = 0;
        std::string skip_reason;
        for (const BenchMethodEntry& m : benchMethods()) {
            if (m.family != family) continue;
            Row row = runMethod(m, run, tuning);
            if (row.skipped) {
                skip_reason = row.skip_reason;
            } else {
                ++configs;
            }
            sweep.push_back(std::move(row));
        }
        const Row* best = fastestConfig(sweep, first, &RunResult::median_ms);
        const Row* best_exact = fastestConfig(sweep, first, &RunResult::exact_median_ms);
        if (best == nullptr) {
            Row row;
            row.method = family;
            row.workload = tableName(run.workload, run.one_shot);
            row.n = run.workload.size();
            row.peer = true;
            row.skipped = true;
            row.skip_reason = configs == 0 ? skip_reason : "no configuration ran cleanly";
            rows.push_back(std::move(row));
            continue;
        }
        const auto appendWinner = [&](const Row& winner, const char* by) {
            Row row = winner;
            row.family = family;
            row.configs = configs;
            row.tuned_by = by;
            rows.push_back(std::move(row));
        };
        appendWinner(*best, best_exact == best ? "median_ms and exact_ms" : "median_ms");
        if (best_exact != best) appendWinner(*best_exact, "exact_ms");
    }
}

}  // namespace app
