// app/lab/bench/bench_broadphase_measure.cpp -- timing one broad-phase method on a workload: the
// frame loop (moveAll + findPairs timed, then deliverExact, then the check outside the timer),
// the one-shot repetitions, the forked child that gives per-method peak memory, and one table
// row per method. Fairness invariants: bench_broadphase.cpp's header.
#include "bench_broadphase_measure.h"

#include <fcntl.h>
#include <malloc.h>
#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "bench_broadphase_report.h"
#include "bench_method.h"
#include "bench_workload.h"

namespace app {

namespace {

constexpr int kMaxOneShotRepetitions = 100;

double clockSeconds(clockid_t clock) {
    timespec ts{};
    clock_gettime(clock, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
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

void setNote(RunResult& r, const std::string& text) {
    std::snprintf(r.note, sizeof(r.note), "%s", text.c_str());
}

/// A row's timed frames (one-shot: repetitions), ms: the pairs as held (`held`), and with the
/// exact pairs delivered (`exact`); and the figures made from them.
struct FrameTimes {
    std::vector<double> held, exact;
    double total_s = 0;  ///< with the exact pairs, s: what the budget counts

    /// One frame timed from `start`: pairs found at `found`, exact pairs delivered at `end` (s).
    void add(double start, double found, double end) {
        held.push_back(1e3 * (found - start));
        exact.push_back(1e3 * (end - start));
        total_s += end - start;
    }
    int count() const { return static_cast<int>(held.size()); }
    bool overBudget(const BenchOptions& options) const {
        return options.budget_seconds > 0 && total_s > options.budget_seconds;
    }
    /// frames_run, the medians, the mean, and the first and last kEdgeFrames' medians.
    void fill(RunResult& r) const {
        r.frames_run = count();
        r.median_ms = median(held);
        r.exact_median_ms = median(exact);
        r.mean_ms = held.empty() ? 0
                                 : std::accumulate(held.begin(), held.end(), 0.0) /
                                       static_cast<double>(held.size());
        const std::size_t edge = std::min<std::size_t>(kEdgeFrames, held.size());
        r.first_median_ms = median(std::vector<double>(held.begin(), held.begin() + edge));
        r.last_median_ms = median(std::vector<double>(held.end() - edge, held.end()));
    }
};

/// One method's moving run on a private copy of the workload, a frame at a time: create, insert
/// and the first query (insert_ms), then each frame moveAll + findPairs (median_ms) and
/// deliverExact (exact_ms) timed, its pairs checked against the reference untimed. measure()
/// runs one to the end alone; measureTogether() advances several in turns.
class MovingRun {
public:
    MovingRun(const BenchMethodEntry& entry, const MovingBoxes& initial,
              const std::vector<PairSummary>& reference, const BenchOptions& options)
        : entry_(entry),
          boxes_(initial),
          reference_(reference),
          options_(options),
          clock_(frameClock(options, entry)) {
        boxes_.volumes(volumes_);
        times_.held.reserve(static_cast<std::size_t>(options.frames));
        times_.exact.reserve(static_cast<std::size_t>(options.frames));
    }

    void start() {
        const double t0 = clockSeconds(clock_);
        method_ = entry_.create();
        method_->insertAll(boxes_, volumes_);
        method_->findPairs();
        r_.insert_ms = 1e3 * (clockSeconds(clock_) - t0);
        check(0);
    }

    /// Every frame run, or stopped by the budget.
    bool done() const { return frame_ >= options_.frames || r_.budget_hit != 0; }

    void frame() {
        ++frame_;
        boxes_.step();
        boxes_.volumes(volumes_);
        const double start = clockSeconds(clock_);
        method_->moveAll(boxes_, volumes_);
        method_->findPairs();
        const double found = clockSeconds(clock_);
        method_->deliverExact(boxes_);
        times_.add(start, found, clockSeconds(clock_));
        check(frame_);
        if (times_.overBudget(options_) && frame_ < options_.frames) {
            r_.budget_hit = 1;
        }
    }

    /// The figures; the method is destroyed.
    RunResult finish() {
        r_.raw_pairs_last = method_->rawPairs();
        r_.potentially_colliding_last = method_->potentiallyColliding();
        method_.reset();
        times_.fill(r_);
        return r_;
    }

private:
    void check(int frame) {
        const PairSummary got = method_->summary(boxes_);
        r_.pairs_last = got.pairs;
        if (got == reference_[static_cast<std::size_t>(frame)]) return;
        if (r_.mismatched_frames++ == 0) {
            r_.first_mismatch_frame = frame;
            r_.expected_pairs = reference_[static_cast<std::size_t>(frame)].pairs;
            r_.got_pairs = got.pairs;
        }
    }

    const BenchMethodEntry& entry_;
    MovingBoxes boxes_;
    const std::vector<PairSummary>& reference_;
    const BenchOptions& options_;
    clockid_t clock_;
    std::vector<collision::ProxyVolumes> volumes_;
    std::unique_ptr<BenchMethod> method_;
    FrameTimes times_;
    int frame_ = 0;
    RunResult r_;
};

/// One method's one-shot run: every repetition creates the method, inserts every box and finds
/// the pairs of frame 0, all timed; destroying it is not. No state survives between
/// repetitions.
class OneShotRun {
public:
    OneShotRun(const BenchMethodEntry& entry, const MovingBoxes& boxes,
               const std::vector<PairSummary>& reference, const BenchOptions& options)
        : entry_(entry),
          boxes_(boxes),
          reference_(reference),
          options_(options),
          clock_(frameClock(options, entry)),
          repetitions_(oneShotRepetitions(options)) {
        boxes.volumes(volumes_);
    }

    bool done() const { return times_.count() >= repetitions_ || r_.budget_hit != 0; }

    void repetition() {
        const double start = clockSeconds(clock_);
        std::unique_ptr<BenchMethod> method = entry_.create();
        method->insertAll(boxes_, volumes_);
        method->findPairs();
        const double found = clockSeconds(clock_);
        method->deliverExact(boxes_);
        times_.add(start, found, clockSeconds(clock_));
        const PairSummary got = method->summary(boxes_);
        r_.pairs_last = got.pairs;
        r_.raw_pairs_last = method->rawPairs();
        r_.potentially_colliding_last = method->potentiallyColliding();
        if (!(got == reference_[0]) && r_.mismatched_frames++ == 0) {
            r_.first_mismatch_frame = 0;
            r_.expected_pairs = reference_[0].pairs;
            r_.got_pairs = got.pairs;
        }
        method.reset();
        if (times_.overBudget(options_) && times_.count() < repetitions_) {
            r_.budget_hit = 1;
        }
    }

    RunResult finish() {
        r_.insert_ms = times_.held.front();
        times_.fill(r_);
        return r_;
    }

private:
    const BenchMethodEntry& entry_;
    const MovingBoxes& boxes_;
    const std::vector<PairSummary>& reference_;
    const BenchOptions& options_;
    clockid_t clock_;
    int repetitions_;
    std::vector<collision::ProxyVolumes> volumes_;
    FrameTimes times_;
    RunResult r_;
};

RunResult measure(const BenchMethodEntry& entry, const MovingBoxes& initial,
                  const std::vector<PairSummary>& reference, const BenchOptions& options,
                  bool one_shot) {
    if (one_shot) {
        OneShotRun run(entry, initial, reference, options);
        while (!run.done()) run.repetition();
        return run.finish();
    }
    MovingRun run(entry, initial, reference, options);
    const bool peak_reset = options.isolate && resetPeakRss();
    const long rss_before = peak_reset ? statusKb("VmRSS:") : statusKb("VmHWM:");
    run.start();
    while (!run.done()) run.frame();
    const long rss_after = statusKb("VmHWM:");
    RunResult r = run.finish();
    if (options.isolate && rss_before >= 0 && rss_after >= 0) {
        r.peak_mb = static_cast<double>(std::max(0L, rss_after - rss_before)) / 1024.0;
    }
    return r;
}

/// Several methods measured in turns (measureTogether's body): the moving runs are created and
/// started in the entries' order, then advance `turn_frames` frames each per turn, the order
/// reversed every turn; one-shot runs take one repetition per turn. Results in the entries'
/// order.
std::vector<RunResult> measureInTurns(const std::vector<const BenchMethodEntry*>& entries,
                                      const MovingBoxes& initial,
                                      const std::vector<PairSummary>& reference,
                                      const BenchOptions& options, bool one_shot, int turn_frames) {
    std::vector<std::size_t> order(entries.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::vector<RunResult> results;
    auto turns = [&order](auto& runs, auto&& advance) {
        for (bool any = true; any;) {
            any = false;
            for (const std::size_t i : order) {
                if (runs[i].done()) continue;
                advance(runs[i]);
                any = true;
            }
            std::reverse(order.begin(), order.end());
        }
    };
    if (one_shot) {
        std::vector<OneShotRun> runs;
        runs.reserve(entries.size());
        for (const BenchMethodEntry* e : entries) {
            runs.emplace_back(*e, initial, reference, options);
        }
        turns(runs, [](OneShotRun& run) { run.repetition(); });
        for (OneShotRun& run : runs) results.push_back(run.finish());
        return results;
    }
    std::vector<MovingRun> runs;
    runs.reserve(entries.size());
    for (const BenchMethodEntry* e : entries) runs.emplace_back(*e, initial, reference, options);
    for (MovingRun& run : runs) run.start();
    turns(runs, [turn_frames](MovingRun& run) {
        for (int k = 0; k < turn_frames && !run.done(); ++k) run.frame();
    });
    for (MovingRun& run : runs) results.push_back(run.finish());
    return results;
}

/// `count` results made by `produce` in a forked child, so that a method's peak memory is its
/// own and a crash is a failed row, not the end of the run. Each result is failed with the
/// reason when the child could not run or did not report.
template <class Produce>
std::vector<RunResult> inChild(std::size_t count, const BenchOptions& options, Produce&& produce) {
    std::vector<RunResult> results(count);
    auto failAll = [&results](const std::string& why) {
        for (RunResult& r : results) {
            r = RunResult{};
            r.failed = 1;
            setNote(r, why);
        }
        return results;
    };
    int fds[2];
    if (::pipe(fds) != 0) return failAll(std::string("pipe: ") + std::strerror(errno));
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
        return failAll(std::string("fork: ") + std::strerror(errno));
    }
    if (pid == 0) {
        ::close(fds[0]);
        // A stuck method ends with SIGALRM instead of stalling the run.
        if (options.budget_seconds > 0) {
            ::alarm(static_cast<unsigned>(options.budget_seconds * 10 * static_cast<double>(count) +
                                          600));
        }
        std::vector<RunResult> child(count);
        try {
            child = produce();
        } catch (const std::exception& e) {
            for (RunResult& r : child) {
                r.failed = 1;
                setNote(r, std::string("exception: ") + e.what());
            }
        }
        const char* p = reinterpret_cast<const char*>(child.data());
        std::size_t left = sizeof(RunResult) * count;
        while (left > 0) {
            const ssize_t w = ::write(fds[1], p, left);
            if (w <= 0) break;
            p += w;
            left -= static_cast<std::size_t>(w);
        }
        ::_exit(left == 0 ? 0 : 1);
    }
    ::close(fds[1]);
    char* p = reinterpret_cast<char*>(results.data());
    const std::size_t size = sizeof(RunResult) * count;
    std::size_t got = 0;
    while (got < size) {
        const ssize_t n = ::read(fds[0], p + got, size - got);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        got += static_cast<std::size_t>(n);
    }
    ::close(fds[0]);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (got != size) {
        if (WIFSIGNALED(status)) {
            return failAll("child killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
                           strsignal(WTERMSIG(status)) + ")");
        }
        return failAll("child exited with status " + std::to_string(WEXITSTATUS(status)));
    }
    return results;
}

}  // namespace

double median(std::vector<double> v) {
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    const std::size_t mid = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
    const double hi = v[mid];
    if (v.size() % 2 == 1) return hi;
    return (*std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)) + hi) / 2;
}

double threadCpuSeconds() { return clockSeconds(CLOCK_THREAD_CPUTIME_ID); }

int oneShotRepetitions(const BenchOptions& options) {
    return std::min(options.frames, kMaxOneShotRepetitions);
}

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
                     ? inChild(1, options,
                               [&] {
                                   return std::vector<RunResult>{measure(
                                       m, run.workload, run.reference, options, run.one_shot)};
                               })
                           .front()
                     : measure(m, run.workload, run.reference, options, run.one_shot);
    reportRun(row, m, run);
    return row;
}

std::vector<RunResult> measureTogether(const std::vector<const BenchMethodEntry*>& entries,
                                       const TableRun& run, int turn_frames) {
    auto produce = [&] {
        return measureInTurns(entries, run.workload, run.reference, run.options, run.one_shot,
                              turn_frames);
    };
    return run.options.isolate ? inChild(entries.size(), run.options, produce) : produce();
}

void reportRun(const Row& row, const BenchMethodEntry& m, const TableRun& run) {
    const int n = run.workload.size();
    const RunResult& r = row.result;
    run.err << "[" << row.workload << " N=" << n << "] " << m.name << ": ";
    if (r.failed) {
        run.err << "FAILED: " << r.note << '\n';
        run.failed = true;
    } else {
        run.err << numberText("%.4f", r.median_ms) << " ms median, " << r.frames_run
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
}

}  // namespace app
