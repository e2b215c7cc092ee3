// collision/src/broadphase/interval_diagram.h -- a sort-and-sweep's intervals drawn as a 1-D
// interval diagram per axis along the edges of the world bounds (SAP and sap1 draw with it).
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "collision/debug_draw.h"

namespace collision {

/// One proxy's closed interval [lo, hi] on an axis; `marked` when the proxy is in an overlapping
/// pair (its AABB overlaps another on every axis).
struct DiagramInterval {
    Real lo = 0;
    Real hi = 0;
    bool marked = false;
};

/// Where axis `axis` (0, 1, 2)'s diagram lies, for legends: "below the front bottom edge" (x),
/// "left of the front left edge" (y), "right of the bottom right edge" (z).
std::string intervalDiagramPlace(int axis);

/// Draws `intervals`, sorted by lo, as a diagram outside `bounds` along the edge parallel to
/// `axis` that intervalDiagramPlace names: each interval at its true coordinates on the axis,
/// with end ticks, in rows stacked away from the box. An interval goes into the first row whose
/// intervals all end strictly before it starts (greedy interval partitioning, so touching or
/// overlapping intervals never share a row and there are as many rows as the most intervals over
/// one point). Marked intervals in `marked_color`, the others in `color`. Nothing is drawn when
/// `bounds` is not finite or is empty.
void drawIntervalDiagram(DebugDraw& draw, const Aabb& bounds, int axis,
                         std::span<const DiagramInterval> intervals, const Color& color,
                         const Color& marked_color);

/// The intervals a sorted sweep meets: item i's [lo(i), hi(i)], items in ascending lo; i and
/// each later j whose lo is at most hi(i) are marked when `accepts(i, j)` (the broad phase's own
/// pair test). The same sweep as the broad phase's findPairs, repeated for drawing only.
template <class Lo, class Hi, class Accepts>
std::vector<DiagramInterval> sweptIntervals(std::size_t n, Lo lo, Hi hi, Accepts accepts) {
    std::vector<DiagramInterval> intervals;
    intervals.reserve(n);
    for (std::size_t i = 0; i < n; ++i) intervals.push_back(DiagramInterval{lo(i), hi(i), false});
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n && intervals[j].lo <= intervals[i].hi; ++j) {
            if (accepts(i, j)) intervals[i].marked = intervals[j].marked = true;
        }
    }
    return intervals;
}

/// drawIntervalDiagram in the structure palette's first two colours, with a legend line for
/// each: `what` the intervals are, `marked_what` the marked ones.
void drawSweepDiagram(DebugDraw& draw, const Aabb& bounds, int axis,
                      std::span<const DiagramInterval> intervals, const std::string& what,
                      const std::string& marked_what);

}  // namespace collision
