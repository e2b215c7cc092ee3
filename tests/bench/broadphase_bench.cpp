// tests/bench/broadphase_bench.cpp -- Google Benchmark over every AABB broad phase of the registry
// and the default peer configurations (Bullet, FCL, when compiled in), on the moving-box workloads
// of `cdlab bench broadphase` at 1k and 10k boxes. One iteration is one frame: the workload
// advances untimed, then move-all + find-pairs is timed on the thread CPU clock (manual time).
#include <benchmark/benchmark.h>
#include <time.h>

#include <string>
#include <vector>

#include "bench_method.h"
#include "bench_workload.h"

namespace {

double threadCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
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
    for (auto _ : state) {
        boxes.step();
        boxes.volumes(volumes);
        const double start = threadCpuSeconds();
        method->moveAll(boxes, volumes);
        method->findPairs();
        state.SetIterationTime(threadCpuSeconds() - start);
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
            for (int n : {1000, 10000}) {
                const std::string name = "broadphase/" + entry.name + "/" +
                                         std::string(app::workloadName(kind)) + "/" +
                                         std::to_string(n);
                benchmark::RegisterBenchmark(name.c_str(),
                                             [&entry, kind, n](benchmark::State& state) {
                                                 frameBenchmark(state, entry, kind, n);
                                             })
                    ->UseManualTime()
                    ->Unit(benchmark::kMillisecond);
            }
        }
    }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
