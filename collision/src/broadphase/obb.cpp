// collision/src/broadphase/obb.cpp -- OBB broad phase.
#include "broadphase/obb.h"

#include <algorithm>
#include <vector>

#include "broadphase/interval_diagram.h"
#include "collision/debug_draw.h"

namespace collision {

void ObbBroadPhase::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    countMoves(counters);
    items_.clear();
    for (ProxyId id = 0; id < table_.capacity(); ++id) {
        if (!table_.contains(id)) continue;
        const Obb& o = table_.obb(id);
        // The OBB's enclosing AABB, grown by more than the SAT's own tolerance
        // (Obb::overlaps accepts a gap of up to 16 eps x size), so the stage never drops a pair
        // the SAT would accept.
        const Vec3 e = o.axes.cwiseAbs() * o.half_extents;
        const Real slack =
            64 * kEpsilon * (3 * o.half_extents.maxCoeff() + o.center.cwiseAbs().maxCoeff());
        const Vec3 grow = e + Vec3::Constant(slack);
        items_.push_back(Item{Aabb{o.center - grow, o.center + grow}, id});
    }
    std::sort(items_.begin(), items_.end(), [](const Item& x, const Item& y) {
        return x.box.min.x() != y.box.min.x() ? x.box.min.x() < y.box.min.x() : x.id < y.id;
    });
    pairs.clear();
    for (std::size_t i = 0; i < items_.size(); ++i) {
        const Item& a = items_[i];
        for (std::size_t j = i + 1; j < items_.size() && items_[j].box.min.x() <= a.box.max.x();
             ++j) {
            const Item& b = items_[j];
            ++counters.volume_tests;
            if (!a.box.overlaps(b.box)) continue;
            ++counters.volume_tests;
            if (table_.obb(a.id).overlaps(table_.obb(b.id))) {
                pairs.push_back(a.id < b.id ? ProxyPair{a.id, b.id} : ProxyPair{b.id, a.id});
            }
        }
    }
    std::sort(pairs.begin(), pairs.end());
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void ObbBroadPhase::draw(DebugDraw& draw, const Aabb& bounds) const {
    // The enclosing boxes' x-intervals findPairs swept; marked where the separating-axis test
    // accepts a pair.
    const std::vector<DiagramInterval> intervals = sweptIntervals(
        items_.size(), [&](std::size_t i) { return items_[i].box.min.x(); },
        [&](std::size_t i) { return items_[i].box.max.x(); },
        [&](std::size_t i, std::size_t j) {
            const Item& a = items_[i];
            const Item& b = items_[j];
            return a.box.overlaps(b.box) && table_.obb(a.id).overlaps(table_.obb(b.id));
        });
    drawSweepDiagram(draw, bounds, 0, intervals,
                     "obb: OBBs' x-extents, sorted and swept, " + intervalDiagramPlace(0),
                     "interval of an OBB that overlaps another");
}

}  // namespace collision
