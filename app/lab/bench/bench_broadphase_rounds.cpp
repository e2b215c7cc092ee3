// app/lab/bench/bench_broadphase_rounds.cpp -- interleaved rounds of a table's rows. The machine this
// bench runs on can run a process 1.4x slower for seconds to minutes at a time; run once, in
// sequence, such a stretch lands on whole rows and moves their ratios. Run R times with the order
// alternating (A B C, C B A, A B C, ...), each stretch costs each row at most a round or two, and
// the median over the rounds sets it aside.
#include "bench_broadphase_rounds.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>
#include <string>
#include <utility>

#include "bench_broadphase_measure.h"

namespace app {

namespace {

double medianOver(const std::vector<RunResult>& rounds, double RunResult::*figure) {
    std::vector<double> values;
    values.reserve(rounds.size());
    for (const RunResult& r : rounds) values.push_back(r.*figure);
    return median(std::move(values));
}

// The row's figures as the medians over its rounds.
void combineRounds(Row& row) {
    RunResult& out = row.result;
    for (double RunResult::*figure :
         {&RunResult::insert_ms, &RunResult::median_ms, &RunResult::mean_ms,
          &RunResult::exact_median_ms, &RunResult::first_median_ms, &RunResult::last_median_ms}) {
        out.*figure = medianOver(row.rounds, figure);
    }
    for (const RunResult& r : row.rounds) {
        out.frames_run = std::min(out.frames_run, r.frames_run);
        out.budget_hit = std::max(out.budget_hit, r.budget_hit);
        if (std::isfinite(r.peak_mb)) {
            out.peak_mb = std::isfinite(out.peak_mb) ? std::max(out.peak_mb, r.peak_mb) : r.peak_mb;
        }
    }
}

// A row whose method is not in the registry any more: failed rather than given a figure of
// another round.
void failUnregistered(const TableRun& run, Row& row) {
    row.result.failed = 1;
    std::snprintf(row.result.note, sizeof(row.result.note), "no method named %s to run again",
                  row.method.c_str());
    run.failed = true;
}

// The rows' results over their rounds, or their rounds dropped when they did not run them all.
void combineAll(std::vector<Row>& rows, int rounds) {
    for (Row& row : rows) {
        if (usable(row) && static_cast<int>(row.rounds.size()) == rounds) {
            combineRounds(row);
        } else {
            row.rounds.clear();
        }
    }
}

// --interleave: the usable rows timed `rounds` times, measured together each time; these rounds
// replace the first pass's figures. A row that fails or disagrees in a round keeps that round's
// result and sits out the rest.
void runTogether(const TableRun& run, std::vector<Row>& rows) {
    const int rounds = run.options.rounds;
    std::vector<std::size_t> ids;
    std::vector<const BenchMethodEntry*> entries;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        if (!usable(rows[i])) continue;
        const BenchMethodEntry* entry = findBenchMethod(rows[i].method);
        if (entry == nullptr) {
            failUnregistered(run, rows[i]);
            continue;
        }
        ids.push_back(i);
        entries.push_back(entry);
        rows[i].rounds.clear();
    }
    if (entries.empty()) return;
    for (int round = 1; round <= rounds; ++round) {
        run.err << "[" << tableName(run.workload, run.one_shot) << " N=" << run.workload.size()
                << "] round " << round << " of " << rounds << ", " << entries.size()
                << " rows measured together\n";
        const std::vector<RunResult> results =
            measureTogether(entries, run, run.options.interleave);
        std::vector<std::size_t> kept_ids;
        std::vector<const BenchMethodEntry*> kept_entries;
        for (std::size_t j = 0; j < entries.size(); ++j) {
            Row& row = rows[ids[j]];
            Row again = row;
            again.result = results[j];
            reportRun(again, *entries[j], run);
            if (!usable(again)) {
                row.result = again.result;
                row.rounds.clear();
                continue;
            }
            row.rounds.push_back(results[j]);
            kept_ids.push_back(ids[j]);
            kept_entries.push_back(entries[j]);
        }
        ids = std::move(kept_ids);
        entries = std::move(kept_entries);
        if (entries.empty()) break;
    }
    combineAll(rows, rounds);
}

}  // namespace

void runRounds(const TableRun& run, std::vector<Row>& rows) {
    if (run.options.interleave > 0) {
        runTogether(run, rows);
        return;
    }
    const int rounds = run.options.rounds;
    if (rounds <= 1) return;
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        if (usable(rows[i])) {
            order.push_back(i);
            rows[i].rounds = {rows[i].result};
        }
    }
    for (int round = 2; round <= rounds; ++round) {
        run.err << "[" << tableName(run.workload, run.one_shot) << " N=" << run.workload.size()
                << "] round " << round << " of " << rounds << '\n';
        std::reverse(order.begin(), order.end());
        for (const std::size_t i : order) {
            Row& row = rows[i];
            if (!usable(row)) continue;
            const BenchMethodEntry* entry = findBenchMethod(row.method);
            if (entry == nullptr) {
                failUnregistered(run, row);
                continue;
            }
            const Row again = runMethod(*entry, run, run.options);
            if (!usable(again)) {
                row.result = again.result;
                row.rounds.clear();
                continue;
            }
            row.rounds.push_back(again.result);
        }
    }
    combineAll(rows, rounds);
}

void setRoundRatios(std::vector<Row>& rows) {
    std::size_t rounds = 0;
    for (const Row& row : rows) rounds = std::max(rounds, row.rounds.size());
    for (Row& row : rows) {
        row.round_ratios.clear();
        row.round_exact_ratios.clear();
    }
    for (std::size_t k = 0; k < rounds; ++k) {
        double best = std::numeric_limits<double>::infinity();
        double best_exact = best;
        for (const Row& row : rows) {
            if (!row.peer || !usable(row) || row.rounds.size() <= k) continue;
            best = std::min(best, row.rounds[k].median_ms);
            best_exact = std::min(best_exact, row.rounds[k].exact_median_ms);
        }
        for (Row& row : rows) {
            if (!usable(row) || row.rounds.size() <= k) continue;
            const bool any_peer = best < std::numeric_limits<double>::infinity();
            row.round_ratios.push_back(any_peer ? row.rounds[k].median_ms / best
                                                : std::numeric_limits<double>::quiet_NaN());
            row.round_exact_ratios.push_back(any_peer ? row.rounds[k].exact_median_ms / best_exact
                                                      : std::numeric_limits<double>::quiet_NaN());
        }
    }
}

}  // namespace app
