// tests/bench/obb_fit_bench.cpp -- cost of the bodies' OBB fits (obb_fit.cpp): the tight fit
// (candidate axes, exact 2-D rectangles) against the covariance fit alone, on a 2,000-triangle
// torus and on 10,000 points on a sphere (all of them hull vertices, ~20,000 hull faces) and in
// a ball. The hull is built once, outside the timed loop: the fit alone is timed.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "collision/geometry/convex_hull.h"
#include "collision/test_meshes.h"
#include "collision/volumes/bounding_volumes.h"

namespace {

using collision::ConvexPolytope;
using collision::Vec3;

ConvexPolytope hullOf(const std::vector<Vec3>& points) {
    return collision::computeConvexHull(points).hull;
}

std::vector<Vec3> randomPoints(int n, bool on_sphere) {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> normal;
    std::uniform_real_distribution<double> unit(0, 1);
    std::vector<Vec3> pts;
    for (int i = 0; i < n; ++i) {
        const Vec3 d = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
        pts.push_back(on_sphere ? d : Vec3(d * std::cbrt(unit(rng))));
    }
    return pts;
}

const ConvexPolytope& shapeHull(int which) {
    static const ConvexPolytope torus = hullOf(cdlab_test::makeTorusMesh(1, 0.3, 50, 20).vertices);
    static const ConvexPolytope sphere = hullOf(randomPoints(10000, true));
    static const ConvexPolytope ball = hullOf(randomPoints(10000, false));
    return which == 0 ? torus : which == 1 ? sphere : ball;
}

void setLabel(benchmark::State& state, const ConvexPolytope& hull) {
    state.counters["hull_vertices"] = static_cast<double>(hull.vertices.size());
    state.counters["hull_faces"] = static_cast<double>(hull.faces.size());
}

void BM_FitObbTight(benchmark::State& state) {
    const ConvexPolytope& hull = shapeHull(static_cast<int>(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(collision::fitObbTight(hull));
    setLabel(state, hull);
}

void BM_FitObbPrincipal(benchmark::State& state) {
    const ConvexPolytope& hull = shapeHull(static_cast<int>(state.range(0)));
    for (auto _ : state) benchmark::DoNotOptimize(collision::fitObbPrincipal(hull));
    setLabel(state, hull);
}

// Argument: 0 torus 2k triangles, 1 10k points on a sphere, 2 10k points in a ball.
BENCHMARK(BM_FitObbTight)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitObbPrincipal)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
