// tests/bench/broadphase_bench.cpp -- Google Benchmark over every AABB broad phase of the registry
// and the default peer configurations (Bullet, FCL, when compiled in), on the moving-box workloads
// of `cdlab bench broadphase` at 1k, 10k and 100k boxes. One iteration is one frame: the workload
// advances untimed, then move-all + find-pairs is timed on the thread CPU clock (manual time;
// methods on two threads, hgrid2, on the wall clock).
// At 100k a fixed, small iteration count keeps a run bounded: building the workload and inserting
// 100k boxes happen once per benchmark instead of once per trial run Google Benchmark would make
// to pick an iteration count, and the slowest methods there cost seconds a frame (FCL's SaP
// manager rebuilt each frame grows ~n^1.7: 96 ms at 10k, 313 ms at 20k). The quadratic reference
// (`brute`, ~5e9 box tests a frame) and the peers the app skips at that size (Bullet's
// btAxisSweep3: O(n) per insertion) are left out.
#include <benchmark/benchmark.h>
#include <time.h>

#include <string>
#include <vector>

#include "bench_method.h"
#include "bench_workload.h"

namespace {

constexpr int kLargeN = 100000;
constexpr int kLargeIterations = 5;  // frames timed at kLargeN

double clockSeconds(clockid_t clock) {
    timespec ts{};
    clock_gettime(clock, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void frameBenchmark(benchmark::State& state, const app::BenchMethodEntry& entry,
                    app::WorkloadKind kind, int n) {
    app::MovingBoxes boxes(kind, n, /*seed=*/1);
    std::vector<collision::ProxyVolumes> volumes;
    boxes.volumes(volumes);
    std::unique_ptr<app::BenchMethod> method = entry.create();
    method->insertAll(boxes, volumes);
    method->findPairs();
    // Thread CPU time would count one thread's share of a method on several: those run on the
    // wall clock (their names end in /wall).
    const clockid_t clock = entry.threads > 1 ? CLOCK_MONOTONIC : CLOCK_THREAD_CPUTIME_ID;
    for (auto _ : state) {
        boxes.step();
        boxes.volumes(volumes);
        const double start = clockSeconds(clock);
        method->moveAll(boxes, volumes);
        method->findPairs();
        state.SetIterationTime(clockSeconds(clock) - start);
    }
    state.counters["pairs"] = static_cast<double>(method->summary(boxes).pairs);
    state.counters["boxes"] = n;
}

}  // namespace

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    for (const app::BenchMethodEntry& entry : app::benchMethods()) {
        // The non-default peer configurations are compared by `cdlab bench broadphase --methods`.
        if (!entry.default_set) continue;
        for (app::WorkloadKind kind : {app::WorkloadKind::Uniform, app::WorkloadKind::Mixed}) {
            for (int n : {1000, 10000, kLargeN}) {
                const bool large = n == kLargeN;
                if (large && (entry.name == "brute" ||
                              (entry.default_max_n > 0 && n > entry.default_max_n))) {
                    continue;
                }
                const std::string name = "broadphase/" + entry.name + "/" +
                                         std::string(app::workloadName(kind)) + "/" +
                                         std::to_string(n) + (entry.threads > 1 ? "/wall" : "");
                benchmark::internal::Benchmark* b =
                    benchmark::RegisterBenchmark(name.c_str(),
                                                 [&entry, kind, n](benchmark::State& state) {
                                                     frameBenchmark(state, entry, kind, n);
                                                 })
                        ->UseManualTime()
                        ->Unit(benchmark::kMillisecond);
                if (large) b->Iterations(kLargeIterations);
            }
        }
    }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
