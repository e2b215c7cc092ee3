// app/lab/run_rows.h -- the rows `cdlab run` writes of each frame: the --stats CSV row, the
// --trace JSON line and the page's timeline row (run_html.h), from the world at the frame and the
// sums of the counters of the steps that reached it.
#pragma once

#include <cstdint>
#include <string>

#include "engine/world.h"
#include "run_html.h"

namespace app {

/// Per-frame sums of the step counters (--stats, the page).
struct FrameStats {
    collision::BroadPhaseCounters broad;
    std::int64_t narrow_tests = 0;
    std::int64_t triangle_tests = 0;
    std::int64_t bv_tests = 0;
    std::int64_t refit_nodes = 0;
    std::int64_t rebuilds = 0;
    std::int64_t toi_queries = 0;
    std::int64_t toi_iterations = 0;
    std::int64_t toi_events = 0;
    std::int64_t response_pairs = 0, response_volume_tests = 0;
    std::int64_t ccd_pairs = 0, ccd_volume_tests = 0;
    double refit_s = 0;
    double integrate_s = 0, volumes_s = 0, broad_s = 0, narrow_s = 0, ccd_s = 0, response_s = 0,
           total_s = 0;

    void add(const engine::StepStats& s) {
        broad.volume_tests += s.broad.volume_tests;
        broad.pairs_flagged += s.broad.pairs_flagged;
        broad.volumes_updated += s.broad.volumes_updated;
        broad.swaps += s.broad.swaps;
        narrow_tests += s.narrow_tests;
        triangle_tests += s.triangle_tests;
        bv_tests += s.bv_tests;
        refit_nodes += s.refit_nodes;
        rebuilds += s.rebuilds;
        toi_queries += s.toi_queries;
        toi_iterations += s.toi_iterations;
        toi_events += s.toi_events;
        response_pairs += s.response_pairs;
        response_volume_tests += s.response_broad.volume_tests;
        ccd_pairs += s.ccd_pairs;
        ccd_volume_tests += s.ccd_broad.volume_tests;
        refit_s += s.refit_s;
        integrate_s += s.integrate_s;
        volumes_s += s.volumes_s;
        broad_s += s.broad_phase_s;
        narrow_s += s.narrow_phase_s;
        ccd_s += s.ccd_s;
        response_s += s.response_s;
        total_s += s.total_s;
    }
};

/// The --stats CSV's first line.
extern const char* const kStatsHeader;

/// Intersecting triangle pairs within self_collision mesh bodies at the current state.
std::int64_t selfPairCount(const engine::World& world);

/// The --stats row of `frame`: the world's figures and the steps' sums `f`.
std::string statsRow(int frame, const engine::World& world, const FrameStats& f);

/// The --trace line of `frame` (RunOptions::trace): every digit of every double, so two builds
/// compare to the last bit of the narrower one; pairs sorted, by id and by the bodies' names.
std::string traceLine(int frame, const engine::World& world);

/// The page's timeline row of `frame` (index.html), the same figures as statsRow().
RunPageFrame pageFrame(int frame, const engine::World& world, const FrameStats& f);

}  // namespace app
