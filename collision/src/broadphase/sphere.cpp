// collision/src/broadphase/sphere.cpp -- bounding-sphere broad phase.
#include "broadphase/sphere.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "broadphase/interval_diagram.h"
#include "collision/debug_draw.h"

namespace collision {

void SphereBroadPhase::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    countMoves(counters);
    items_.clear();
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (!table_.contains(id)) continue;
        const BoundingSphere& s = table_.sphere(id);
        // The sweep must never prune a pair that BoundingSphere::overlaps accepts. That test
        // rounds |c_a - c_b|^2 and (r_a + r_b)^2 (a few ulps of each), while cx +- r rounds
        // differently: spheres touching along x were pruned in ~2% of random cases. Widening
        // every interval by a few ulps of its magnitude makes the sweep conservative; the exact
        // sphere test below still decides, so the pair set equals sphere-brute's.
        const Real slack = 16 * kEpsilon * (std::abs(s.center.x()) + s.radius);
        items_.push_back(
            Item{s.center.x() - s.radius - slack, s.center.x() + s.radius + slack, id});
    }
    std::sort(items_.begin(), items_.end(), [](const Item& x, const Item& y) {
        return x.lo != y.lo ? x.lo < y.lo : x.id < y.id;
    });
    pairs.clear();
    for (std::size_t i = 0; i < items_.size(); ++i) {
        const BoundingSphere& si = table_.sphere(items_[i].id);
        // Closed intervals: a sphere starting exactly where this one ends is still tested.
        for (std::size_t j = i + 1; j < items_.size() && items_[j].lo <= items_[i].hi; ++j) {
            ++counters.volume_tests;
            if (si.overlaps(table_.sphere(items_[j].id))) {
                const ProxyId a = items_[i].id;
                const ProxyId b = items_[j].id;
                pairs.push_back(a < b ? ProxyPair{a, b} : ProxyPair{b, a});
            }
        }
    }
    std::sort(pairs.begin(), pairs.end());
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void SphereBroadPhase::draw(DebugDraw& draw, const Aabb& bounds) const {
    // The intervals findPairs swept, in its order; marked where the sphere test accepts a pair.
    const std::vector<DiagramInterval> intervals = sweptIntervals(
        items_.size(), [&](std::size_t i) { return items_[i].lo; },
        [&](std::size_t i) { return items_[i].hi; },
        [&](std::size_t i, std::size_t j) {
            return table_.sphere(items_[i].id).overlaps(table_.sphere(items_[j].id));
        });
    drawSweepDiagram(draw, bounds, 0, intervals,
                     "sphere x-intervals, sorted and swept, " + intervalDiagramPlace(0),
                     "interval of a sphere that overlaps another");
}

}  // namespace collision
