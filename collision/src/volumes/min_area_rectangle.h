// collision/src/volumes/min_area_rectangle.h -- the minimum-area rectangle around a planar point
// set: the 2-D step of the body OBB fit (obb_fit.cpp), which projects a hull along a candidate
// axis and boxes the projection. Private to collision.
#pragma once

#include <vector>

#include "collision/math.h"

namespace collision {

struct Point2 {
    Real x = 0;
    Real y = 0;
};

/// A rectangle's orientation and area: one side runs along the unit vector (ux, uy).
struct Rectangle2 {
    Real ux = 1;
    Real uy = 0;
    Real area = 0;
};

/// Convex hull of `points` (Andrew's monotone chain), counter-clockwise, without collinear or
/// repeated vertices; the turn test is exact (orient2d). O(n log n). Empty input gives an empty
/// hull; a single distinct point or a collinear set gives one or two points.
std::vector<Point2> convexHull2(std::vector<Point2> points);

/// Minimum-area rectangle enclosing the convex polygon `hull` (counter-clockwise, as from
/// convexHull2). Freeman & Shapira 1975, "Determining the minimum-area encasing rectangle for an
/// arbitrary closed curve": some optimal rectangle has a side collinear with a hull edge, so only
/// the hull's edge directions are tried, each in O(1) amortised by rotating calipers (Toussaint
/// 1983, "Solving geometric problems with the rotating calipers"): O(h). Exact up to the rounding
/// of the areas compared. Fewer than three vertices give area 0 along the segment (or x).
Rectangle2 minAreaRectangle(const std::vector<Point2>& hull);

/// The same by trying every edge against every vertex, O(h^2): the reference for the calipers.
Rectangle2 minAreaRectangleBruteForce(const std::vector<Point2>& hull);

}  // namespace collision
