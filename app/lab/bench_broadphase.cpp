// app/lab/bench_broadphase.cpp -- `cdlab bench broadphase`: runs every method on the same
// moving-box sequence and tabulates per-frame thread CPU time, build time and peak memory. Fairness
// invariants: every method sees bit-identical boxes in the same order (each child process rebuilds
// the workload from the same state and steps it with the same code); the timed part of a frame is
// exactly moveAll() + findPairs() (today's rule), and that plus deliverExact() (the exact-pairs
// rule: a peer's filtering of its loose pair cache to exact pairs is charged to it, as cdlab's
// methods are charged for delivering exact pairs); anything a method needs only to prove its answer
// (hashing the pair set) runs outside the timer. Every frame's pair set (count and
// order-independent hash) is compared with an independent reference sweep.
#include "bench_broadphase.h"

#include <fcntl.h>
#include <malloc.h>
#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "bench_method.h"
#include "bench_peer_tuning.h"
#include "bench_rows.h"
#include "bench_workload.h"
#include "exit_codes.h"
#include "output_files.h"
#include "render/output_file.h"

namespace app {

namespace fs = std::filesystem;

namespace {

constexpr int kEdgeFrames = 100;  // frames in the "first" and "last" medians
constexpr int kMaxOneShotRepetitions = 100;
double clockSeconds(clockid_t clock) {
    timespec ts{};
    clock_gettime(clock, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double threadCpuSeconds() { return clockSeconds(CLOCK_THREAD_CPUTIME_ID); }

int oneShotRepetitions(const BenchOptions& options) {
    return std::min(options.frames, kMaxOneShotRepetitions);
}

/// The clock a method's frames are timed by: --clock wall, else the thread's CPU time, or the
/// process's for a method that puts work on threads it does not own (BenchMethodEntry).
clockid_t frameClock(const BenchOptions& options, const BenchMethodEntry& entry) {
    if (options.clock == "wall") return CLOCK_MONOTONIC;
    return entry.foreign_threads ? CLOCK_PROCESS_CPUTIME_ID : CLOCK_THREAD_CPUTIME_ID;
}

/// frameClock's name: "wall", "thread" or "process".
std::string clockName(const BenchOptions& options, const BenchMethodEntry& entry) {
    if (options.clock == "wall") return "wall";
    return entry.foreign_threads ? "process" : "thread";
}

/// A "Vm...:" field of /proc/self/status in kB, or -1.
long statusKb(const char* field) {
    std::ifstream status("/proc/self/status");
    std::string line;
    const std::size_t len = std::strlen(field);
    while (std::getline(status, line)) {
        if (line.compare(0, len, field) == 0) return std::strtol(line.c_str() + len, nullptr, 10);
    }
    return -1;
}

/// Resets VmHWM to the current RSS (Linux >= 4.0: "5" > clear_refs); false when not allowed.
bool resetPeakRss() {
    const int fd = ::open("/proc/self/clear_refs", O_WRONLY);
    if (fd < 0) return false;
    const bool ok = ::write(fd, "5", 1) == 1;
    ::close(fd);
    return ok;
}

double median(std::vector<double> v) {
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    const std::size_t mid = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
    const double hi = v[mid];
    if (v.size() % 2 == 1) return hi;
    return (*std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)) + hi) / 2;
}

void setNote(RunResult& r, const std::string& text) {
    std::snprintf(r.note, sizeof(r.note), "%s", text.c_str());
}

/// Runs one method on a private copy of the workload: insert + first query, then the frames.
RunResult measureOneShot(const BenchMethodEntry& entry, const MovingBoxes& boxes,
                         const std::vector<PairSummary>& reference, const BenchOptions& options);

RunResult measure(const BenchMethodEntry& entry, const MovingBoxes& initial,
                  const std::vector<PairSummary>& reference, const BenchOptions& options,
                  bool one_shot) {
    if (one_shot) return measureOneShot(entry, initial, reference, options);
    RunResult r;
    MovingBoxes boxes = initial;
    std::vector<collision::ProxyVolumes> volumes;
    boxes.volumes(volumes);
    std::vector<double> times, exact_times;
    times.reserve(static_cast<std::size_t>(options.frames));
    exact_times.reserve(static_cast<std::size_t>(options.frames));
    auto check = [&](BenchMethod& method, int frame) {
        const PairSummary got = method.summary(boxes);
        r.pairs_last = got.pairs;
        if (got == reference[static_cast<std::size_t>(frame)]) return;
        if (r.mismatched_frames++ == 0) {
            r.first_mismatch_frame = frame;
            r.expected_pairs = reference[static_cast<std::size_t>(frame)].pairs;
            r.got_pairs = got.pairs;
        }
    };

    const bool peak_reset = options.isolate && resetPeakRss();
    const long rss_before = peak_reset ? statusKb("VmRSS:") : statusKb("VmHWM:");

    const clockid_t clock = frameClock(options, entry);
    const double t0 = clockSeconds(clock);
    std::unique_ptr<BenchMethod> method = entry.create();
    method->insertAll(boxes, volumes);
    method->findPairs();
    r.insert_ms = 1e3 * (clockSeconds(clock) - t0);
    check(*method, 0);

    double total = 0;
    for (int frame = 1; frame <= options.frames; ++frame) {
        boxes.step();
        boxes.volumes(volumes);
        const double start = clockSeconds(clock);
        method->moveAll(boxes, volumes);
        method->findPairs();
        const double found = clockSeconds(clock);
        method->deliverExact(boxes);
        const double dt = clockSeconds(clock) - start;
        times.push_back(1e3 * (found - start));
        exact_times.push_back(1e3 * dt);
        total += dt;
        check(*method, frame);
        if (options.budget_seconds > 0 && total > options.budget_seconds &&
            frame < options.frames) {
            r.budget_hit = 1;
            break;
        }
    }
    r.raw_pairs_last = method->rawPairs();
    r.potentially_colliding_last = method->potentiallyColliding();
    const long rss_after = statusKb("VmHWM:");
    method.reset();

    r.frames_run = static_cast<int>(times.size());
    r.median_ms = median(times);
    r.exact_median_ms = median(exact_times);
    r.mean_ms = times.empty() ? 0
                              : std::accumulate(times.begin(), times.end(), 0.0) /
                                    static_cast<double>(times.size());
    const std::size_t edge = std::min<std::size_t>(kEdgeFrames, times.size());
    r.first_median_ms = median(std::vector<double>(times.begin(), times.begin() + edge));
    r.last_median_ms = median(std::vector<double>(times.end() - edge, times.end()));
    if (options.isolate && rss_before >= 0 && rss_after >= 0) {
        r.peak_mb = static_cast<double>(std::max(0L, rss_after - rss_before)) / 1024.0;
    }
    return r;
}

/// One-shot: every repetition creates the method, inserts every box and finds the pairs of frame 0,
/// all timed; destroying it is not. No state survives between repetitions.
RunResult measureOneShot(const BenchMethodEntry& entry, const MovingBoxes& boxes,
                         const std::vector<PairSummary>& reference, const BenchOptions& options) {
    RunResult r;
    std::vector<collision::ProxyVolumes> volumes;
    boxes.volumes(volumes);
    const int repetitions = oneShotRepetitions(options);
    std::vector<double> times, exact_times;
    const clockid_t clock = frameClock(options, entry);
    double total = 0;
    for (int rep = 0; rep < repetitions; ++rep) {
        const double start = clockSeconds(clock);
        std::unique_ptr<BenchMethod> method = entry.create();
        method->insertAll(boxes, volumes);
        method->findPairs();
        const double found = clockSeconds(clock);
        method->deliverExact(boxes);
        const double dt = clockSeconds(clock) - start;
        times.push_back(1e3 * (found - start));
        exact_times.push_back(1e3 * dt);
        total += dt;
        const PairSummary got = method->summary(boxes);
        r.pairs_last = got.pairs;
        r.raw_pairs_last = method->rawPairs();
        r.potentially_colliding_last = method->potentiallyColliding();
        if (!(got == reference[0]) && r.mismatched_frames++ == 0) {
            r.first_mismatch_frame = 0;
            r.expected_pairs = reference[0].pairs;
            r.got_pairs = got.pairs;
        }
        method.reset();
        if (options.budget_seconds > 0 && total > options.budget_seconds && rep + 1 < repetitions) {
            r.budget_hit = 1;
            break;
        }
    }
    r.insert_ms = times.front();
    r.frames_run = static_cast<int>(times.size());
    r.median_ms = median(times);
    r.exact_median_ms = median(exact_times);
    r.mean_ms = std::accumulate(times.begin(), times.end(), 0.0) / double(times.size());
    const std::size_t edge = std::min<std::size_t>(kEdgeFrames, times.size());
    r.first_median_ms = median(std::vector<double>(times.begin(), times.begin() + edge));
    r.last_median_ms = median(std::vector<double>(times.end() - edge, times.end()));
    return r;
}

/// measure() in a forked child: per-method peak memory, and a crash is a row, not the end.
RunResult measureIsolated(const BenchMethodEntry& entry, const MovingBoxes& initial,
                          const std::vector<PairSummary>& reference, const BenchOptions& options,
                          bool one_shot) {
    RunResult r;
    int fds[2];
    if (::pipe(fds) != 0) {
        r.failed = 1;
        setNote(r, std::string("pipe: ") + std::strerror(errno));
        return r;
    }
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    // Heap the parent freed but kept mapped would be reused by the child without raising its
    // RSS (a copy-on-write fault swaps a shared page for a private one), hiding the method's
    // memory: hand it back to the kernel first.
    ::malloc_trim(0);
    const pid_t pid = ::fork();
    if (pid < 0) {
        ::close(fds[0]);
        ::close(fds[1]);
        r.failed = 1;
        setNote(r, std::string("fork: ") + std::strerror(errno));
        return r;
    }
    if (pid == 0) {
        ::close(fds[0]);
        // A stuck method ends with SIGALRM instead of stalling the run.
        if (options.budget_seconds > 0)
            ::alarm(static_cast<unsigned>(options.budget_seconds * 10 + 600));
        RunResult child;
        try {
            child = measure(entry, initial, reference, options, one_shot);
        } catch (const std::exception& e) {
            child.failed = 1;
            setNote(child, std::string("exception: ") + e.what());
        }
        const char* p = reinterpret_cast<const char*>(&child);
        std::size_t left = sizeof(child);
        while (left > 0) {
            const ssize_t w = ::write(fds[1], p, left);
            if (w <= 0) break;
            p += w;
            left -= static_cast<std::size_t>(w);
        }
        ::_exit(left == 0 ? 0 : 1);
    }
    ::close(fds[1]);
    char* p = reinterpret_cast<char*>(&r);
    std::size_t got = 0;
    while (got < sizeof(r)) {
        const ssize_t n = ::read(fds[0], p + got, sizeof(r) - got);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        got += static_cast<std::size_t>(n);
    }
    ::close(fds[0]);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (got != sizeof(r)) {
        r = RunResult{};
        r.failed = 1;
        if (WIFSIGNALED(status)) {
            setNote(r, "child killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
                           strsignal(WTERMSIG(status)) + ")");
        } else {
            setNote(r, "child exited with status " + std::to_string(WEXITSTATUS(status)));
        }
    }
    return r;
}

std::string format(const char* fmt, double value) {
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
            return format("%.2f", ratio) + (std::isfinite(ratio) ? "x" : "");
        };
        std::snprintf(
            line, sizeof(line),
            "%-34s %10s %10s %10s %10s %10s %10lld %10s %10s %10s %8s %9s  %s%s\n",
            (row.method + (row.peer ? " [peer]" : "")).c_str(), format("%.2f", r.insert_ms).c_str(),
            format("%.4f", r.median_ms).c_str(), format("%.4f", r.mean_ms).c_str(),
            format("%.4f", r.first_median_ms).c_str(), format("%.4f", r.last_median_ms).c_str(),
            static_cast<long long>(r.pairs_last), times(row.ratio).c_str(),
            format("%.4f", r.exact_median_ms).c_str(), times(row.exact_ratio).c_str(),
            format("%.1f", r.peak_mb).c_str(), frames_text.c_str(), check.c_str(), tuned.c_str());
        out << line;
    }
}

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
    return j;
}

bool writeJsonAtomically(const fs::path& file, const nlohmann::json& doc, std::ostream& err) {
    return writeTextReporting(file, doc.dump(2) + "\n", err);
}

std::string methodList() {
    std::string out;
    for (const BenchMethodEntry& m : benchMethods()) {
        if (!out.empty()) out += ", ";
        out += m.name;
    }
    return out;
}

// The workloads and methods the options ask for; an error message and false when any option is
// bad (checked before any work).
bool resolveBenchOptions(const BenchOptions& options, std::ostream& err,
                         std::vector<WorkloadKind>& kinds,
                         std::vector<const BenchMethodEntry*>& methods) {
    if (options.workload == "both") {
        kinds = {WorkloadKind::Uniform, WorkloadKind::Mixed};
    } else if (const auto kind = parseWorkloadKind(options.workload)) {
        kinds = {*kind};
    } else {
        err << "--workload: '" << options.workload
            << "' is not uniform, mixed, both, wide or boxpruning\n";
        return false;
    }
    if (options.peers != "tuned" && options.peers != "all" && options.peers != "default") {
        err << "--peers: '" << options.peers << "' is not tuned, all or default\n";
        return false;
    }
    if (options.sizes.empty()) {
        err << "--sizes: no sizes given\n";
        return false;
    }
    // Past 10^7 boxes the workload alone needs gigabytes (2e9 ended in an uncaught bad_alloc).
    constexpr int kMaxBenchBoxes = 10000000;
    for (int n : options.sizes) {
        if (n < 2 || n > kMaxBenchBoxes) {
            err << "--sizes: " << n << " boxes; need at least 2 and at most " << kMaxBenchBoxes
                << "\n";
            return false;
        }
    }
    if (options.frames < 1) {
        err << "--frames: " << options.frames << "; need at least 1\n";
        return false;
    }
    if (options.clock != "thread" && options.clock != "wall") {
        err << "--clock: '" << options.clock << "' is not thread or wall\n";
        return false;
    }
    if (options.methods.empty()) {
        // Tuned peers replace the peers' default configurations (their grids hold them).
        const bool tune = options.peers != "default";
        for (const BenchMethodEntry& m : benchMethods()) {
            if (m.default_set && !(tune && m.peer)) methods.push_back(&m);
        }
    } else {
        for (const std::string& name : options.methods) {
            const BenchMethodEntry* m = findBenchMethod(name);
            if (m == nullptr) {
                err << "--methods: unknown method '" << name
                    << "' (AABB-based cdlab broad phases and the peers compiled in: "
                    << methodList() << ")\n";
                return false;
            }
            methods.push_back(m);
        }
    }
    if (options.json) {
        // Prove the JSON file writable now rather than after an hour of measuring.
        try {
            render::checkOutputWritable(*options.json);
        } catch (const render::RenderError& e) {
            err << e.what() << '\n';
            return false;
        }
    }
    return true;
}

// Every frame's pair count and hash by an independent sort-and-sweep: what each method must match.
std::vector<PairSummary> referencePairs(const MovingBoxes& workload, int frames) {
    std::vector<PairSummary> reference(static_cast<std::size_t>(frames) + 1);
    MovingBoxes boxes = workload;
    PairReference sweep;
    reference[0] = sweep.count(boxes);
    for (int f = 1; f <= frames; ++f) {
        boxes.step();
        reference[static_cast<std::size_t>(f)] = sweep.count(boxes);
    }
    return reference;
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

// The fastest cdlab method by `ms` against the best peer by the same figure, as one line.
void printFastest(std::ostream& out, const std::vector<Row>& rows, double RunResult::*ms,
                  double Row::*ratio, const char* rule) {
    const Row* fastest = nullptr;
    for (const Row& row : rows) {
        if (!row.peer && usable(row) &&
            (fastest == nullptr || row.result.*ms < fastest->result.*ms)) {
            fastest = &row;
        }
    }
    if (fastest == nullptr) return;
    out << rule << ": fastest cdlab: " << fastest->method << " "
        << format("%.4f", fastest->result.*ms) << " ms/frame";
    if (const Row* best = bestPeer(rows, ms)) {
        out << "; best peer: " << best->method << " " << format("%.4f", best->result.*ms)
            << " ms/frame; ratio " << format("%.2f", fastest->*ratio) << "x";
    }
    out << '\n';
}

// One workload's rows: each method's ratio to the best peer under both rules, the table, the
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
    printTable(out, rows, frames);
    printFastest(out, rows, &RunResult::median_ms, &Row::ratio,
                 "pairs as held (median_ms, vs_peer)");
    printFastest(out, rows, &RunResult::exact_median_ms, &Row::exact_ratio,
                 "exact pairs delivered (exact_ms, vs_peer_ex)");
    for (const Row& row : rows) {
        const RunResult& r = row.result;
        if (row.skipped || r.failed) continue;
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

}  // namespace

Row runMethod(const BenchMethodEntry& m, const TableRun& run, const BenchOptions& options) {
    const int n = run.workload.size();
    Row row;
    row.method = m.name;
    row.workload = tableName(run.workload, run.one_shot);
    row.n = n;
    row.peer = m.peer;
    row.clock = clockName(options, m);
    if (m.threads > 1 && options.clock == "thread") {
        row.skipped = true;
        row.skip_reason = "runs on " + std::to_string(m.threads) +
                          " threads: thread CPU time would count one; use --clock wall";
        return row;
    }
    if (m.hard_max_n > 0 && n >= m.hard_max_n) {
        row.skipped = true;
        row.skip_reason = "skipped: holds fewer than " + std::to_string(m.hard_max_n) + " boxes";
        return row;
    }
    if (run.options.methods.empty() && m.default_max_n > 0 && n > m.default_max_n) {
        row.skipped = true;
        row.skip_reason = m.skip_reason;
        return row;
    }
    row.result = options.isolate
                     ? measureIsolated(m, run.workload, run.reference, options, run.one_shot)
                     : measure(m, run.workload, run.reference, options, run.one_shot);
    const RunResult& r = row.result;
    run.err << "[" << row.workload << " N=" << n << "] " << m.name << ": ";
    if (r.failed) {
        run.err << "FAILED: " << r.note << '\n';
        run.failed = true;
    } else {
        run.err << format("%.4f", r.median_ms) << " ms median, " << r.frames_run
                << (run.one_shot ? " repetitions\n" : " frames\n");
    }
    if (r.mismatched_frames > 0) {
        // A peer's disagreement is the peer's own (FCL's SaP misses pairs of the boxpruning scene),
        // so it is shown and left out of the ratios; one of ours failing its reference fails the
        // run.
        if (!m.peer) run.failed = true;
        std::string msg = "MISMATCH: " + m.name + " (" + row.workload + ", N=";
        msg += std::to_string(n) + ") disagrees with the reference on ";
        msg += std::to_string(r.mismatched_frames) + " frame(s); first at frame ";
        msg += std::to_string(r.first_mismatch_frame) + ": " + std::to_string(r.got_pairs);
        msg += " pairs, expected " + std::to_string(r.expected_pairs);
        msg += m.peer ? " (a peer: left out of the ratios)\n" : "\n";
        run.out << "!!! " << msg;
        run.err << "!!! " << msg;
    }
    return row;
}

namespace {

Row runMethod(const BenchMethodEntry& m, const TableRun& run) {
    return runMethod(m, run, run.options);
}

}  // namespace

BenchOptions smallBenchOptions() {
    BenchOptions o;
    o.sizes = {200};
    o.frames = 20;
    return o;
}

int runBenchBroadphase(const BenchOptions& options, std::ostream& out, std::ostream& err) {
    // Validate everything before any work.
    std::vector<WorkloadKind> kinds;
    std::vector<const BenchMethodEntry*> methods;
    if (!resolveBenchOptions(options, err, kinds, methods)) return kExitBadInput;
    const bool tune = options.methods.empty() && options.peers != "default";

    out << "cdlab bench broadphase: " << options.frames << " frames per method; time = "
        << (options.clock == "wall" ? "elapsed (wall-clock) time" : "thread CPU time")
        << " of (move all proxies + find pairs) per frame, ms"
        << (options.clock == "wall"
                ? ""
                : " (a method rendering on llvmpipe's threads: process CPU time)")
        << ".\n"
        << "insert_ms = create + insert all + first find pairs; first100/last100 = median of the "
           "first/last "
        << kEdgeFrames << " frames; vs_peer = median / best peer's median;\n"
        << "peak_MB = VmHWM growth of the method's own process; check = every frame's pair set "
           "(count + hash) vs an independent sort-and-sweep.\n";
    out << "Two rules: median_ms times the pairs as each method holds them (a peer's loose "
           "pair cache unfiltered); exact_ms adds delivering the exact pairs (the peer filters "
           "its cache with the exact boxes, timed; cdlab's methods already deliver exact, "
           "sorted pairs). vs_peer and vs_peer_ex are against the best peer by each.\n";
    if (tune) {
        out << "Peers tuned: every configuration of each peer's grid runs all frames (stopped "
               "after "
            << kTuneBudgetSeconds
            << " s of frame time; a stopped one is ranked only if none ran in full); the "
               "fastest by its median is the peer row, named peer:configuration, and so is "
               "the fastest by exact_ms when that is another (--peers all prints the "
               "grid).\n";
    }
    if (!options.isolate) out << "(in-process run: peak memory not measured)\n";

    bool failed = false;
    std::vector<Row> all_rows;
    for (WorkloadKind kind : kinds) {
        for (int n : options.sizes) {
            const double t_ref = threadCpuSeconds();
            const MovingBoxes workload(kind, n, options.seed);
            const std::vector<PairSummary> reference = referencePairs(workload, options.frames);
            err << "[" << workloadName(kind) << " N=" << n << "] reference pairs for "
                << options.frames + 1 << " frames in " << format("%.1f", threadCpuSeconds() - t_ref)
                << " s\n";
            const std::vector<bool> modes = kind == WorkloadKind::BoxPruning
                                                ? std::vector<bool>{true, false}
                                                : std::vector<bool>{false};
            for (const bool one_shot : modes) {
                printWorkloadHead(out, workload, reference, options, one_shot);
                TableRun run{workload, reference, options, one_shot, out, err, failed};
                std::vector<Row> rows;
                for (const BenchMethodEntry* m : methods) rows.push_back(runMethod(*m, run));
                std::vector<Row> sweep;
                if (tune) tunePeers(run, rows, sweep);
                reportWorkload(out, rows, options,
                               one_shot ? oneShotRepetitions(options) : options.frames);
                if (options.peers == "all" && !sweep.empty()) {
                    out << "peer configurations swept (stopped after " << kTuneBudgetSeconds
                        << " s each; vs_peer against the best of them):\n";
                    setRatios(sweep);
                    printTable(out, sweep, one_shot ? oneShotRepetitions(options) : options.frames);
                }
                for (Row& row : rows) all_rows.push_back(std::move(row));
                for (Row& row : sweep) {
                    row.workload += " sweep";
                    all_rows.push_back(std::move(row));
                }
            }
        }
    }

    if (options.json) {
        nlohmann::json doc;
        doc["frames"] = options.frames;
        doc["seed"] = options.seed;
        doc["clock"] = options.clock;
        doc["peers"] = options.peers;
        doc["rows"] = nlohmann::json::array();
        for (const Row& row : all_rows) doc["rows"].push_back(rowJson(row));
        if (!writeJsonAtomically(*options.json, doc, err)) return kExitFailure;
    }
    return failed ? kExitFailure : kExitOk;
}

}  // namespace app
