// app/lab/bench_broadphase_measure.cpp -- timing one broad-phase method on a workload: the
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
                     ? measureIsolated(m, run.workload, run.reference, options, run.one_shot)
                     : measure(m, run.workload, run.reference, options, run.one_shot);
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
    return row;
}

}  // namespace app
