// collision/src/broadphase/sap.cpp -- sweep-and-prune (I-COLLIDE).
// Invariant between calls: each axis list holds the two endpoints of every present proxy in
// `before` order, and pairs_ holds exactly the pairs whose AABBs overlap (closed intervals).
// Why the incremental update is exact: insertion sort swaps each inverted pair of endpoints
// exactly once, and two intervals change between overlapping and not on an axis exactly when a
// min of one crosses a max of the other. A pair that overlaps now but did not before changed on
// some axis from apart to overlapping, so a "begin" swap tested it with the current boxes; a pair
// that stopped overlapping changed on some axis the other way and got an "end" swap.
#include "broadphase/sap.h"

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "broadphase/interval_diagram.h"
#include "broadphase/radix_sort.h"
#include "collision/debug_draw.h"

namespace collision {

std::uint64_t SweepAndPrune::key(ProxyId a, ProxyId b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
           static_cast<std::uint32_t>(b);
}

void SweepAndPrune::insert(ProxyId id, const ProxyVolumes& v) {
    table_.insert(id, v);
    dirty_ = true;
}

void SweepAndPrune::remove(ProxyId id) {
    table_.remove(id);
    dirty_ = true;
}

void SweepAndPrune::move(ProxyId id, const ProxyVolumes& v) {
    table_.move(id, v);
    ++moved_;
}

void SweepAndPrune::refreshValues() {
    for (int axis = 0; axis < 3; ++axis) {
        for (Endpoint& e : axes_[axis]) {
            const Aabb& box = table_.aabb(e.id);
            e.value = e.is_max ? box.max[axis] : box.min[axis];
        }
    }
}

void SweepAndPrune::rebuild(BroadPhaseCounters& counters) {
    for (int axis = 0; axis < 3; ++axis) {
        std::vector<Endpoint>& list = axes_[axis];
        list.clear();
        for (ProxyId id = 0; id < table_.capacity(); ++id) {
            if (!table_.contains(id)) continue;
            const Aabb& box = table_.aabb(id);
            list.push_back(Endpoint{box.min[axis], id, false});
            list.push_back(Endpoint{box.max[axis], id, true});
        }
        std::sort(list.begin(), list.end(), before);
    }
    // One sort-and-sweep along x finds every overlapping pair (Baraff 1992; I-COLLIDE §5.2).
    pairs_.clear();
    active_.clear();
    for (const Endpoint& e : axes_[0]) {
        if (e.is_max) {
            const auto it = std::find(active_.begin(), active_.end(), e.id);
            *it = active_.back();
            active_.pop_back();
            continue;
        }
        const Aabb& box = table_.aabb(e.id);
        for (ProxyId other : active_) {
            ++counters.volume_tests;
            if (box.overlaps(table_.aabb(other))) pairs_.insert(key(e.id, other));
        }
        active_.push_back(e.id);
    }
    dirty_ = false;
}

void SweepAndPrune::insertionSort(int axis, BroadPhaseCounters& counters) {
    std::vector<Endpoint>& list = axes_[axis];
    for (std::size_t i = 1; i < list.size(); ++i) {
        const Endpoint e = list[i];
        std::size_t j = i;
        while (j > 0 && before(e, list[j - 1])) {
            const Endpoint& f = list[j - 1];
            if (e.id != f.id) {
                if (!e.is_max && f.is_max) {
                    // e's min passes f's max going down: the intervals begin to overlap here.
                    ++counters.volume_tests;
                    if (table_.aabb(e.id).overlaps(table_.aabb(f.id))) {
                        pairs_.insert(key(e.id, f.id));
                    }
                } else if (e.is_max && !f.is_max) {
                    // e's max passes f's min going down: they stop overlapping on this axis.
                    pairs_.erase(key(e.id, f.id));
                }
            }
            list[j] = f;
            --j;
            ++counters.swaps;
        }
        list[j] = e;
    }
}

void SweepAndPrune::findPairs(std::vector<ProxyPair>& pairs, BroadPhaseCounters& counters) {
    counters.volumes_updated += moved_;
    moved_ = 0;
    if (dirty_) {
        rebuild(counters);
    } else {
        refreshValues();
        for (int axis = 0; axis < 3; ++axis) insertionSort(axis, counters);
    }
    // (a, b) order: repack the keys into 2 x (bits of the largest id) and radix sort them.
    const int shift = radix::bitsFor(static_cast<std::uint64_t>(table_.capacity()));
    keys_.clear();
    pairs_.forEach([&](std::uint64_t k) { keys_.push_back(((k >> 32) << shift) | (k & 0xFFFFFFFFu)); });
    radix::keysToSortedPairs(keys_, scratch_, shift, pairs);
    counters.pairs_flagged += static_cast<std::int64_t>(pairs.size());
}

void SweepAndPrune::draw(DebugDraw& draw, const Aabb& bounds) const {
    // Each axis's sorted list as a 1-D interval diagram along an edge of the bounds; the
    // intervals of the proxies in an active pair (overlapping on all three axes) marked.
    std::vector<char> active(static_cast<std::size_t>(std::max<ProxyId>(table_.capacity(), 0)), 0);
    pairs_.forEach([&](std::uint64_t k) {
        active[static_cast<std::size_t>(k >> 32)] = 1;
        active[static_cast<std::size_t>(k & 0xFFFFFFFFu)] = 1;
    });
    const Color& marked = kStructurePalette[1];
    const char* const axis_names[3] = {"x", "y", "z"};
    const int axis_colors[3] = {0, 2, 3};  // cyan, violet, pink
    std::vector<DiagramInterval> intervals;
    std::vector<std::size_t> slot(active.size(), 0);
    for (int axis = 0; axis < 3; ++axis) {
        // The list is in `before` order, so intervals come out sorted by their min.
        intervals.clear();
        for (const Endpoint& e : axes_[axis]) {
            const auto id = static_cast<std::size_t>(e.id);
            if (!e.is_max) {
                slot[id] = intervals.size();
                intervals.push_back(DiagramInterval{e.value, e.value, active[id] != 0});
            } else {
                intervals[slot[id]].hi = e.value;
            }
        }
        const Color& color = kStructurePalette[axis_colors[axis]];
        drawIntervalDiagram(draw, bounds, axis, intervals, color, marked);
        draw.legend(std::string("SAP ") + axis_names[axis] + " intervals, sorted, " +
                        intervalDiagramPlace(axis),
                    color);
    }
    draw.legend("interval of a proxy in an active pair (overlap on x, y and z)", marked);
}

std::string SweepAndPrune::validate() const {
    std::ostringstream out;
    if (dirty_) return {};
    for (int axis = 0; axis < 3; ++axis) {
        const std::vector<Endpoint>& list = axes_[axis];
        if (list.size() != static_cast<std::size_t>(2 * table_.count())) {
            out << "axis " << axis << " holds " << list.size() << " endpoints for "
                << table_.count() << " proxies; ";
        }
        for (std::size_t i = 1; i < list.size(); ++i) {
            if (before(list[i], list[i - 1])) {
                out << "axis " << axis << " out of order at " << i << "; ";
                break;
            }
        }
    }
    pairs_.forEach([&](std::uint64_t k) {
        const ProxyId a = static_cast<ProxyId>(k >> 32);
        const ProxyId b = static_cast<ProxyId>(k & 0xFFFFFFFFu);
        if (!table_.contains(a) || !table_.contains(b)) {
            out << "pair (" << a << "," << b << ") names an absent proxy; ";
        } else if (!table_.aabb(a).overlaps(table_.aabb(b))) {
            out << "pair (" << a << "," << b << ") does not overlap; ";
        }
    });
    return out.str();
}

}  // namespace collision
