// app/lab/bench/bench_broadphase_report.cpp -- the bench's tables and JSON: each row's ratios to the
// best peer under both rules (pairs as held, exact pairs delivered), the fastest cdlab method
// against the best peer, notes on stopped runs and pair caches, and the JSON rows.
#include "bench_broadphase_report.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "bench_broadphase_measure.h"
#include "bench_broadphase_rounds.h"
#include "output_files.h"

namespace app {

namespace {

/// A row whose mean frame time is past this multiple of its median gets a note: its median (the
/// ranking figure) hides the frames that cost most of its run.
constexpr double kSpikyMeanToMedian = 2.0;

nlohmann::json rowJson(const Row& row) {
    auto number = [](double v) -> nlohmann::json {
        if (std::isfinite(v)) return v;
        return nullptr;
    };
    const RunResult& r = row.result;
    nlohmann::json j;
    j["method"] = row.method;
    j["workload"] = row.workload;
    j["n"] = row.n;
    j["peer"] = row.peer;
    if (!row.family.empty()) {
        j["tuned_peer"] = row.family;
        j["configs_swept"] = row.configs;
        j["tuned_by"] = row.tuned_by;
    }
    if (row.skipped) {
        j["skipped"] = row.skip_reason;
        return j;
    }
    j["clock"] = row.clock;
    if (r.failed) {
        j["failed"] = std::string(r.note);
        return j;
    }
    j["insert_ms"] = number(r.insert_ms);
    j["ms_per_frame_median"] = number(r.median_ms);
    j["ms_per_frame_mean"] = number(r.mean_ms);
    j["ms_per_frame_first100_median"] = number(r.first_median_ms);
    j["ms_per_frame_last100_median"] = number(r.last_median_ms);
    j["pairs"] = r.pairs_last;
    if (r.raw_pairs_last >= 0) j["raw_pairs"] = r.raw_pairs_last;
    if (r.potentially_colliding_last >= 0) {
        j["potentially_colliding"] = r.potentially_colliding_last;
    }
    j["ratio_to_best_peer"] = number(row.ratio);
    j["ms_per_frame_median_exact_pairs"] = number(r.exact_median_ms);
    j["ratio_to_best_peer_exact_pairs"] = number(row.exact_ratio);
    j["peak_mb"] = number(r.peak_mb);
    j["frames"] = r.frames_run;
    j["mismatched_frames"] = r.mismatched_frames;
    if (!row.rounds.empty()) {
        nlohmann::json rounds = nlohmann::json::array();
        for (std::size_t k = 0; k < row.rounds.size(); ++k) {
            nlohmann::json round;
            round["ms_per_frame_median"] = number(row.rounds[k].median_ms);
            round["ms_per_frame_median_exact_pairs"] = number(row.rounds[k].exact_median_ms);
            round["insert_ms"] = number(row.rounds[k].insert_ms);
            if (k < row.round_ratios.size()) {
                round["ratio_to_best_peer"] = number(row.round_ratios[k]);
                round["ratio_to_best_peer_exact_pairs"] = number(row.round_exact_ratios[k]);
            }
            rounds.push_back(std::move(round));
        }
        j["rounds"] = std::move(rounds);
    }
    return j;
}

// The usable peer row with the smallest `ms` (a RunResult median), or nullptr.
const Row* bestPeer(const std::vector<Row>& rows, double RunResult::*ms) {
    const Row* best = nullptr;
    for (const Row& row : rows) {
        if (row.peer && usable(row) && (best == nullptr || row.result.*ms < best->result.*ms)) {
            best = &row;
        }
    }
    return best;
}

// "0.43 0.44 0.65x": a row's ratios in each round.
std::string roundRatiosText(const std::vector<double>& ratios) {
    std::string text;
    for (double ratio : ratios) {
        if (!text.empty()) text += ' ';
        text += numberText("%.2f", ratio);
    }
    text += 'x';
    return text;
}

// The fastest cdlab method by `ms` against the best peer by the same figure, as one line (with
// its ratio in each round when the table ran in rounds).
void printFastest(std::ostream& out, const std::vector<Row>& rows, double RunResult::*ms,
                  double Row::*ratio, std::vector<double> Row::*round_ratios, const char* rule) {
    const Row* fastest = nullptr;
    for (const Row& row : rows) {
        if (!row.peer && usable(row) &&
            (fastest == nullptr || row.result.*ms < fastest->result.*ms)) {
            fastest = &row;
        }
    }
    if (fastest == nullptr) return;
    out << rule << ": fastest cdlab: " << fastest->method << " "
        << numberText("%.4f", fastest->result.*ms) << " ms/frame";
    if (const Row* best = bestPeer(rows, ms)) {
        out << "; best peer: " << best->method << " " << numberText("%.4f", best->result.*ms)
            << " ms/frame; ratio " << numberText("%.2f", fastest->*ratio) << "x";
        if (!(fastest->*round_ratios).empty()) {
            out << " (by round: " << roundRatiosText(fastest->*round_ratios) << ")";
        }
    }
    out << '\n';
}


// Each row's figures in each round, when the table ran in rounds.
void printRounds(std::ostream& out, const std::vector<Row>& rows, const BenchOptions& options) {
    if (options.rounds <= 1) return;
    out << "each of the " << options.rounds
        << " rounds (the figures above are their medians): median_ms (vs_peer against that "
           "round's best peer); exact_ms (vs_peer_ex):\n";
    for (const Row& row : rows) {
        if (row.rounds.empty()) continue;
        std::string ms, exact_ms;
        for (const RunResult& r : row.rounds) {
            ms += ' ';
            ms += numberText("%.4f", r.median_ms);
            exact_ms += ' ';
            exact_ms += numberText("%.4f", r.exact_median_ms);
        }
        out << "  " << row.method << (row.peer ? " [peer]" : "") << ":" << ms << " ("
            << roundRatiosText(row.round_ratios) << ");" << exact_ms << " ("
            << roundRatiosText(row.round_exact_ratios) << ")\n";
    }
}

}  // namespace

std::string numberText(const char* fmt, double value) {
    if (!std::isfinite(value)) return "-";
    char buf[64];
    std::snprintf(buf, sizeof(buf), fmt, value);
    return buf;
}

void printTable(std::ostream& out, const std::vector<Row>& rows, int frames) {
    char line[400];
    std::snprintf(line, sizeof(line),
                  "%-34s %10s %10s %10s %10s %10s %10s %10s %10s %10s %8s %9s  %s\n", "method",
                  "insert_ms", "median_ms", "mean_ms", "first100", "last100", "pairs", "vs_peer",
                  "exact_ms", "vs_peer_ex", "peak_MB", "frames", "check");
    out << line;
    for (const Row& row : rows) {
        if (row.skipped) {
            std::snprintf(line, sizeof(line), "%-34s %s\n", row.method.c_str(),
                          row.skip_reason.c_str());
            out << line;
            continue;
        }
        const RunResult& r = row.result;
        if (r.failed) {
            std::snprintf(line, sizeof(line), "%-34s FAILED: %s\n", row.method.c_str(), r.note);
            out << line;
            continue;
        }
        const std::string frames_text =
            std::to_string(r.frames_run) + (r.frames_run < frames ? "*" : "");
        const std::string check = r.mismatched_frames == 0
                                      ? "ok"
                                      : "MISMATCH(" + std::to_string(r.mismatched_frames) + ")";
        const std::string tuned = row.configs > 0 ? "  (best of " + std::to_string(row.configs) +
                                                        " configs by " + row.tuned_by + ")"
                                                  : "";
        const auto times = [](double ratio) {
            return numberText("%.2f", ratio) + (std::isfinite(ratio) ? "x" : "");
        };
        std::snprintf(
            line, sizeof(line),
            "%-34s %10s %10s %10s %10s %10s %10lld %10s %10s %10s %8s %9s  %s%s\n",
            (row.method + (row.peer ? " [peer]" : "")).c_str(), numberText("%.2f", r.insert_ms).c_str(),
            numberText("%.4f", r.median_ms).c_str(), numberText("%.4f", r.mean_ms).c_str(),
            numberText("%.4f", r.first_median_ms).c_str(), numberText("%.4f", r.last_median_ms).c_str(),
            static_cast<long long>(r.pairs_last), times(row.ratio).c_str(),
            numberText("%.4f", r.exact_median_ms).c_str(), times(row.exact_ratio).c_str(),
            numberText("%.1f", r.peak_mb).c_str(), frames_text.c_str(), check.c_str(), tuned.c_str());
        out << line;
    }
}

// fastest cdlab method, and notes on stopped runs and pair caches.
void reportWorkload(std::ostream& out, std::vector<Row>& rows, const BenchOptions& options,
                    int frames) {
    const Row* best = bestPeer(rows, &RunResult::median_ms);
    const Row* best_exact = bestPeer(rows, &RunResult::exact_median_ms);
    for (Row& row : rows) {
        if (!usable(row)) continue;
        if (best != nullptr) row.ratio = row.result.median_ms / best->result.median_ms;
        if (best_exact != nullptr) {
            row.exact_ratio = row.result.exact_median_ms / best_exact->result.exact_median_ms;
        }
    }
    setRoundRatios(rows);
    printTable(out, rows, frames);
    printFastest(out, rows, &RunResult::median_ms, &Row::ratio, &Row::round_ratios,
                 "pairs as held (median_ms, vs_peer)");
    printFastest(out, rows, &RunResult::exact_median_ms, &Row::exact_ratio,
                 &Row::round_exact_ratios, "exact pairs delivered (exact_ms, vs_peer_ex)");
    printRounds(out, rows, options);
    for (const Row& row : rows) {
        const RunResult& r = row.result;
        if (row.skipped || r.failed) continue;
        if (r.mean_ms > kSpikyMeanToMedian * r.median_ms) {
            out << "  " << row.method << ": mean " << numberText("%.4f", r.mean_ms)
                << " ms/frame is " << numberText("%.1f", r.mean_ms / r.median_ms)
                << "x its median: a few frames cost most of the run, which the median does not "
                   "show\n";
        }
        if (r.budget_hit) {
            out << "  * " << row.method << ": stopped after " << r.frames_run
                << " frames (--budget " << options.budget_seconds << " s of frame time)\n";
        }
        if (r.raw_pairs_last >= 0) {
            out << "  " << row.method << ": pair cache held " << r.raw_pairs_last
                << " pairs in the last frame (exact: " << r.pairs_last
                << "; filtered in exact_ms, not in median_ms)\n";
        }
        if (r.potentially_colliding_last >= 0) {
            out << "  " << row.method << ": potentially colliding set held "
                << r.potentially_colliding_last << " of " << row.n
                << " boxes in the last frame (pairs: " << r.pairs_last << ")\n";
        }
        if (row.clock == "process") {
            out << "  " << row.method
                << ": timed by the process's CPU time (every thread's: it renders on llvmpipe's "
                   "threads, which the thread's CPU clock misses)\n";
        }
    }
    out.flush();
}

void printWorkloadHead(std::ostream& out, const MovingBoxes& workload,
                       const std::vector<PairSummary>& reference, const BenchOptions& options,
                       bool one_shot) {
    const int n = workload.size();
    const double per_body_first = double(reference.front().pairs) / n;
    const double per_body_last = double(reference.back().pairs) / n;
    char head[600];
    if (one_shot) {
        std::snprintf(head, sizeof(head),
                      "\n== workload %s one-shot, N = %d: cube [%.0f, %.0f]^3, seed %llu; %lld "
                      "pairs. Each repetition (median of %d) creates the method, inserts every "
                      "box and finds the pairs: insert_ms and median_ms are that whole time\n",
                      std::string(workloadName(workload.kind())).c_str(), n,
                      double(workload.lower()), double(workload.lower() + workload.side()),
                      static_cast<unsigned long long>(options.seed),
                      static_cast<long long>(reference.front().pairs), oneShotRepetitions(options));
    } else {
        std::snprintf(head, sizeof(head),
                      "\n== workload %s, N = %d: cube side %.3f, seed %llu; pairs/body %.3f "
                      "at frame 0, %.3f at frame %d (overlaps/body %.2f, %.2f)\n",
                      std::string(workloadName(workload.kind())).c_str(), n,
                      double(workload.side()), static_cast<unsigned long long>(options.seed),
                      per_body_first, per_body_last, options.frames, 2 * per_body_first,
                      2 * per_body_last);
    }
    out << head;
}

bool writeBenchJson(const std::filesystem::path& file, const BenchOptions& options,
                    const std::vector<Row>& rows, std::ostream& err) {
    nlohmann::json doc;
    doc["frames"] = options.frames;
    doc["seed"] = options.seed;
    doc["clock"] = options.clock;
    doc["peers"] = options.peers;
    doc["rounds"] = options.rounds;
    doc["interleave"] = options.interleave;
    doc["rows"] = nlohmann::json::array();
    for (const Row& row : rows) doc["rows"].push_back(rowJson(row));
    return writeTextReporting(file, doc.dump(2) + "\n", err);
}

}  // namespace app
