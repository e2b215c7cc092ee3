// app/lab/run_rows.cpp -- see run_rows.h.
#include "run_rows.h"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <span>
#include <vector>

namespace app {

const char* const kStatsHeader =
    "frame,time,broadphase,bodies,flagged,colliding,volume_tests,volumes_updated,swaps,"
    "narrow_tests,triangle_tests,bv_tests,integrate_ms,volumes_ms,broadphase_ms,narrowphase_ms,"
    "ccd_ms,response_ms,step_ms,self_pairs,refit_nodes,refit_ms,refit_node_ns,rebuilds,"
    "toi_queries,toi_iterations,toi_events,response_pairs,response_volume_tests,ccd_pairs,"
    "ccd_volume_tests\n";

std::int64_t selfPairCount(const engine::World& world) {
    std::int64_t n = 0;
    for (std::size_t i = 0; i < world.bodies().size(); ++i) {
        n += static_cast<std::int64_t>(world.selfPairs(static_cast<engine::BodyId>(i)).size());
    }
    return n;
}

std::string statsRow(int frame, const engine::World& world, const FrameStats& f) {
    char line[512];
    std::snprintf(line, sizeof line,
                  "%d,%.9g,%s,%zu,%zu,%zu,%lld,%lld,%lld,%lld,%lld,%lld,%.6f,%.6f,%.6f,%.6f,%.6f,"
                  "%.6f,%.6f,%lld,%lld,%.6f,%.3f,%lld,%lld,%lld,%lld,%lld,%lld,%lld,%lld\n",
                  frame, double(world.time()), std::string(world.broadPhase().name()).c_str(),
                  world.bodies().size(), world.flaggedPairs().size(), world.collidingPairs().size(),
                  (long long)f.broad.volume_tests, (long long)f.broad.volumes_updated,
                  (long long)f.broad.swaps, (long long)f.narrow_tests, (long long)f.triangle_tests,
                  (long long)f.bv_tests, 1e3 * f.integrate_s, 1e3 * f.volumes_s, 1e3 * f.broad_s,
                  1e3 * f.narrow_s, 1e3 * f.ccd_s, 1e3 * f.response_s, 1e3 * f.total_s,
                  (long long)selfPairCount(world), (long long)f.refit_nodes, 1e3 * f.refit_s,
                  f.refit_nodes > 0 ? 1e9 * f.refit_s / double(f.refit_nodes) : 0.0,
                  (long long)f.rebuilds, (long long)f.toi_queries,
                  (long long)f.toi_iterations, (long long)f.toi_events,
                  (long long)f.response_pairs, (long long)f.response_volume_tests,
                  (long long)f.ccd_pairs, (long long)f.ccd_volume_tests);
    return line;
}

std::string traceLine(int frame, const engine::World& world) {
    nlohmann::json line;
    line["frame"] = frame;
    line["time"] = double(world.time());
    nlohmann::json positions = nlohmann::json::array();
    nlohmann::json orientations = nlohmann::json::array();
    for (const engine::Body& b : world.bodies()) {
        positions.push_back(
            {double(b.position.x()), double(b.position.y()), double(b.position.z())});
        const engine::Quat& q = b.orientation;
        orientations.push_back({double(q.w()), double(q.x()), double(q.y()), double(q.z())});
    }
    line["positions"] = std::move(positions);
    line["orientations_wxyz"] = std::move(orientations);
    // Sorted, so that the trace does not depend on the pair order (world.pair_order); by id,
    // and by the bodies' names for a reader who wants to find a pair again.
    const auto& bodies = world.bodies();
    auto pairLists = [&](std::span<const collision::ProxyPair> list, const char* ids,
                         const char* names) {
        std::vector<collision::ProxyPair> sorted(list.begin(), list.end());
        std::sort(sorted.begin(), sorted.end());
        nlohmann::json by_id = nlohmann::json::array();
        nlohmann::json by_name = nlohmann::json::array();
        for (const collision::ProxyPair& p : sorted) {
            by_id.push_back({p.a, p.b});
            by_name.push_back({bodies[p.a].name, bodies[p.b].name});
        }
        line[ids] = std::move(by_id);
        line[names] = std::move(by_name);
    };
    pairLists(world.collidingPairs(), "colliding_pairs", "colliding_names");
    pairLists(world.flaggedPairs(), "flagged_pairs", "flagged_names");
    return line.dump() + "\n";
}

RunPageFrame pageFrame(int frame, const engine::World& world, const FrameStats& f) {
    RunPageFrame row;
    row.frame = frame;
    row.time = double(world.time());
    row.flagged = static_cast<std::int64_t>(world.flaggedPairs().size());
    row.colliding = static_cast<std::int64_t>(world.collidingPairs().size());
    row.integrate_ms = 1e3 * f.integrate_s;
    row.volumes_ms = 1e3 * f.volumes_s;
    row.broadphase_ms = 1e3 * f.broad_s;
    row.narrowphase_ms = 1e3 * f.narrow_s;
    row.ccd_ms = 1e3 * f.ccd_s;
    row.response_ms = 1e3 * f.response_s;
    row.step_ms = 1e3 * f.total_s;
    return row;
}

}  // namespace app
