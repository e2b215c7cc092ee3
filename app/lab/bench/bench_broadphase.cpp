// app/lab/bench/bench_broadphase.cpp -- `cdlab bench broadphase`: runs every method on the same
// moving-box sequence and tabulates per-frame thread CPU time, build time and peak memory. Fairness
// invariants: every method sees bit-identical boxes in the same order (each child process rebuilds
// the workload from the same state and steps it with the same code); the timed part of a frame is
// exactly moveAll() + findPairs() (today's rule), and that plus deliverExact() (the exact-pairs
// rule: a peer's filtering of its loose pair cache to exact pairs is charged to it, as cdlab's
// methods are charged for delivering exact pairs); anything a method needs only to prove its answer
// (hashing the pair set) runs outside the timer. Every frame's pair set (count and
// order-independent hash) is compared with an independent reference sweep.
#include "bench_broadphase.h"

#include <ostream>
#include <string>
#include <vector>

#include "bench_broadphase_measure.h"
#include "bench_broadphase_report.h"
#include "bench_broadphase_rounds.h"
#include "bench_method.h"
#include "bench_peer_tuning.h"
#include "bench_rows.h"
#include "bench_workload.h"
#include "exit_codes.h"
#include "render/output_file.h"

namespace app {

namespace {

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
    if (options.rounds < 1 || options.rounds > kMaxBenchRounds) {
        err << "--rounds: " << options.rounds << "; need 1 to " << kMaxBenchRounds << "\n";
        return false;
    }
    if (options.interleave < 0 || options.interleave > kMaxInterleaveFrames) {
        err << "--interleave: " << options.interleave << "; need 0 to " << kMaxInterleaveFrames
            << " frames per turn\n";
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
           "sorted pairs; sap-packed-loose holds its loose candidates, as the peers' caches). "
           "vs_peer and vs_peer_ex are against the best peer by each.\n";
    if (tune) {
        out << "Peers tuned: every configuration of each peer's grid runs all frames (stopped "
               "after "
            << kTuneBudgetSeconds
            << " s of frame time; a stopped one is ranked only if none ran in full); the "
               "fastest by its median is the peer row, named peer:configuration, and so is "
               "the fastest by exact_ms when that is another (--peers all prints the "
               "grid).\n";
    }
    if (options.interleave > 0) {
        out << "Interleaved: after each table's first pass (every row alone"
            << (tune ? ", the peers' grids swept" : "")
            << (options.isolate ? ", peak memory" : "") << "), its rows are timed "
            << options.rounds << (options.rounds == 1 ? " more time" : " more times")
            << " measured together: all alive at once, " << options.interleave
            << (options.interleave == 1 ? " frame" : " frames")
            << " each per turn (one-shot: one repetition), the order reversed every turn; "
               "each figure is "
            << (options.rounds == 1 ? "that round's" : "the median over those rounds") << ".\n";
    } else if (options.rounds > 1) {
        out << "Rounds: " << options.rounds
            << "; each table's rows run once per round, interleaved (every other round in "
               "reverse order); each figure is the median over the rounds"
            << (tune ? " (the peers' grids are swept in the first round)" : "") << ".\n";
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
                << options.frames + 1 << " frames in " << numberText("%.1f", threadCpuSeconds() - t_ref)
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
                runRounds(run, rows);
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

    if (options.json && !writeBenchJson(*options.json, options, all_rows, err)) {
        return kExitFailure;
    }
    return failed ? kExitFailure : kExitOk;
}

}  // namespace app