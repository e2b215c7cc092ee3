// collision/src/broadphase/sap1.cpp -- single-axis sort and sweep.
// Invariant after findPairs: items_ holds every present proxy once, sorted by (lo, id) on axis_.
#include "broadphase/sap1.h"

#include <algorithm>
#include <string>
#include <vector>

#include "broadphase/interval_diagram.h"
#include "collision/debug_draw.h"

namespace collision {

void SortAndSweep1::insert(ProxyId id, const ProxyVolumes& v) {
    table_.insert(id, v);
    dirty_ = true;
}

void SortAndSweep1::remove(ProxyId id) {
    table_.remove(id);
    dirty_ = true;
}

void SortAndSweep1::move(ProxyId id, const ProxyVolumes& v) {
    table_.move(id, v);
    ++moved_;
}

int SortAndSweep1::chooseAxis() const {
    // Variance of the AABB centres per axis, accumulated about the first centre so that scenes
    // far from the origin do not lose the spread to cancellation.
    Vec3 sum = Vec3::Zero();
    Vec3 sum2 = Vec3::Zero();
    Vec3 origin = Vec3::Zero();
    bool first = true;
    int n = 0;
    for (const Item& it : items_) {
        const Vec3 c = table_.aabb(it.id).center();
        if (first) {
            origin = c;
            first = false;
        }
        const Vec3 d = c - origin;
        sum += d;
        sum2 += d.cwiseProduct(d);
        ++n;
    }
    if (n == 0) return 0;
    const Vec3 var = sum2 / Real(n) - (sum / Real(n)).cwiseProduct(sum / Real(n));
    int axis = 0;
    for (int k = 1; k < 3; ++k) {
        if (var[k] > var[axis]) axis = k;
    }
    return axis;
}

void SortAndSweep1::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    counters.volumes_updated += moved_;
    moved_ = 0;
    if (dirty_) {
        items_.clear();
        for (ProxyId id = 0; id < table_.capacity(); ++id) {
            if (table_.contains(id)) items_.push_back(Item{0, 0, id});
        }
    }
    const int axis = chooseAxis();
    for (Item& it : items_) {
        const Aabb& box = table_.aabb(it.id);
        it.lo = box.min[axis];
        it.hi = box.max[axis];
    }
    if (dirty_ || axis != axis_) {
        std::sort(items_.begin(), items_.end(), before);
    } else {
        // Insertion sort: near-linear when the order barely changed since the last frame.
        for (std::size_t i = 1; i < items_.size(); ++i) {
            const Item x = items_[i];
            std::size_t j = i;
            while (j > 0 && before(x, items_[j - 1])) {
                items_[j] = items_[j - 1];
                --j;
                ++counters.swaps;
            }
            items_[j] = x;
        }
    }
    axis_ = axis;
    dirty_ = false;

    pairs.clear();
    const std::size_t n = items_.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Item& a = items_[i];
        const Aabb& box = table_.aabb(a.id);
        // Closed intervals: a proxy starting exactly where this one ends still overlaps.
        for (std::size_t j = i + 1; j < n && items_[j].lo <= a.hi; ++j) {
            ++counters.volume_tests;
            const ProxyId b = items_[j].id;
            if (box.overlaps(table_.aabb(b))) {
                pairs.push_back(a.id < b ? ProxyPair{a.id, b} : ProxyPair{b, a.id});
            }
        }
    }
    std::sort(pairs.begin(), pairs.end());
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void SortAndSweep1::draw(DebugDraw& draw, const Aabb& bounds) const {
    // The one sorted list as a 1-D interval diagram along an edge of the bounds; the intervals
    // of proxies whose AABBs overlap another's marked (the sweep of findPairs, repeated).
    if (axis_ < 0) return;
    const std::vector<DiagramInterval> intervals = sweptIntervals(
        items_.size(), [&](std::size_t i) { return items_[i].lo; },
        [&](std::size_t i) { return items_[i].hi; },
        [&](std::size_t i, std::size_t j) {
            return table_.aabb(items_[i].id).overlaps(table_.aabb(items_[j].id));
        });
    const char* const axis_names[3] = {"x", "y", "z"};
    drawSweepDiagram(draw, bounds, axis_, intervals,
                     std::string("sap1 intervals on ") + axis_names[axis_] +
                         " (the sort axis), sorted, " + intervalDiagramPlace(axis_),
                     "interval of a proxy in an overlapping pair");
}

std::string SortAndSweep1::validate() const {
    if (dirty_) return {};
    if (items_.size() != static_cast<std::size_t>(table_.count())) return "item count mismatch";
    for (std::size_t i = 1; i < items_.size(); ++i) {
        if (before(items_[i], items_[i - 1])) return "items out of order";
    }
    return {};
}

}  // namespace collision
