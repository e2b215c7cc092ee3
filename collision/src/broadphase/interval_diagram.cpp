// collision/src/broadphase/interval_diagram.cpp -- see interval_diagram.h.
// The layout is the textbook picture of sweep and prune (Cohen et al., I-COLLIDE, I3D 1995,
// fig. 3): each axis's intervals projected onto that axis, in rows so overlaps stay visible.
#include "broadphase/interval_diagram.h"

#include <algorithm>
#include <vector>

namespace collision {

namespace {

/// A diagram's baseline: the point of the edge at coordinate t on the axis, and the unit
/// direction rows stack in (away from the box).
struct Edge {
    Vec3 base;  ///< the edge's point at coordinate 0 on the axis (that coordinate is replaced)
    Vec3 out;
};

Edge edgeFor(const Aabb& b, int axis) {
    switch (axis) {
        case 0:
            return {Vec3(0, b.min.y(), b.max.z()), -Vec3::UnitY()};
        case 1:
            return {Vec3(b.min.x(), 0, b.max.z()), -Vec3::UnitX()};
        default:
            return {Vec3(b.max.x(), b.min.y(), 0), Vec3::UnitX()};
    }
}

/// Rows by greedy interval partitioning over intervals sorted by lo (first row that is free).
std::vector<int> assignRows(std::span<const DiagramInterval> intervals, int& row_count) {
    std::vector<Real> row_end;
    std::vector<int> rows;
    rows.reserve(intervals.size());
    for (const DiagramInterval& iv : intervals) {
        std::size_t r = 0;
        while (r < row_end.size() && !(row_end[r] < iv.lo)) ++r;
        if (r == row_end.size()) row_end.push_back(iv.hi);
        row_end[r] = iv.hi;
        rows.push_back(int(r));
    }
    row_count = int(row_end.size());
    return rows;
}

}  // namespace

std::string intervalDiagramPlace(int axis) {
    switch (axis) {
        case 0:
            return "below the front bottom edge";
        case 1:
            return "left of the front left edge";
        default:
            return "right of the bottom right edge";
    }
}

void drawIntervalDiagram(DebugDraw& draw, const Aabb& bounds, int axis,
                         std::span<const DiagramInterval> intervals, const Color& color,
                         const Color& marked_color) {
    const Real size = bounds.extents().maxCoeff();
    if (!bounds.min.allFinite() || !bounds.max.allFinite() || !(size > 0)) return;
    int row_count = 0;
    const std::vector<int> rows = assignRows(intervals, row_count);
    // Rows 2 % of the box apart, closer when there are many, so the whole diagram stays within
    // 15 % of the box's size from its edge.
    const Real gap = std::min(Real(0.02) * size, Real(0.15) * size / Real(std::max(row_count, 1)));
    const Edge edge = edgeFor(bounds, axis);
    for (std::size_t i = 0; i < intervals.size(); ++i) {
        const DiagramInterval& iv = intervals[i];
        const Vec3 offset = edge.out * (gap * Real(rows[i] + 1));
        Vec3 lo = edge.base + offset;
        Vec3 hi = lo;
        lo[axis] = iv.lo;
        hi[axis] = iv.hi;
        const Color& c = iv.marked ? marked_color : color;
        const Vec3 tick = edge.out * (Real(0.35) * gap);
        draw.drawLine(lo, hi, c);
        draw.drawLine(lo - tick, lo + tick, c);
        draw.drawLine(hi - tick, hi + tick, c);
    }
}

void drawSweepDiagram(DebugDraw& draw, const Aabb& bounds, int axis,
                      std::span<const DiagramInterval> intervals, const std::string& what,
                      const std::string& marked_what) {
    drawIntervalDiagram(draw, bounds, axis, intervals, kStructurePalette[0], kStructurePalette[1]);
    draw.legend(what, kStructurePalette[0]);
    draw.legend(marked_what, kStructurePalette[1]);
}

}  // namespace collision
