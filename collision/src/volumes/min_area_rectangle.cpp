// collision/src/volumes/min_area_rectangle.cpp -- minimum-area enclosing rectangle of a convex
// polygon by rotating calipers. Invariant: while edge i is the flush side, `right`, `top` and
// `left` index the polygon's extreme vertices along the edge, normal to it and against it; they
// only ever move forward (counter-clockwise), so one revolution costs O(h) in all.
#include "volumes/min_area_rectangle.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "geometry/predicates.h"

namespace collision {

namespace {

int turn(const Point2& a, const Point2& b, const Point2& c) {
    return orient2d(a.x, a.y, b.x, b.y, c.x, c.y);
}

Real dot(const Point2& p, Real ux, Real uy) { return p.x * ux + p.y * uy; }

// Unit direction of edge a -> b; false for a zero-length edge.
bool edgeDirection(const Point2& a, const Point2& b, Real& ux, Real& uy) {
    const Real dx = b.x - a.x;
    const Real dy = b.y - a.y;
    const Real len = std::hypot(dx, dy);
    if (!(len > 0)) return false;
    ux = dx / len;
    uy = dy / len;
    return true;
}

Rectangle2 degenerate(const std::vector<Point2>& hull) {
    Rectangle2 r;
    if (hull.size() == 2) edgeDirection(hull[0], hull[1], r.ux, r.uy);
    return r;
}

}  // namespace

std::vector<Point2> convexHull2(std::vector<Point2> points) {
    std::sort(points.begin(), points.end(), [](const Point2& a, const Point2& b) {
        return a.x < b.x || (a.x == b.x && a.y < b.y);
    });
    points.erase(
        std::unique(points.begin(), points.end(),
                    [](const Point2& a, const Point2& b) { return a.x == b.x && a.y == b.y; }),
        points.end());
    if (points.size() < 3) return points;
    // Andrew 1979: lower chain left to right, upper chain right to left; a vertex stays only
    // on a strict left turn, so collinear points are dropped.
    std::vector<Point2> hull(2 * points.size());
    std::size_t k = 0;
    for (const Point2& p : points) {
        while (k >= 2 && turn(hull[k - 2], hull[k - 1], p) <= 0) --k;
        hull[k++] = p;
    }
    const std::size_t lower = k + 1;
    for (std::size_t i = points.size() - 1; i-- > 0;) {
        while (k >= lower && turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
        hull[k++] = points[i];
    }
    hull.resize(k - 1);  // the last point repeats the first
    return hull;
}

Rectangle2 minAreaRectangle(const std::vector<Point2>& hull) {
    const std::size_t h = hull.size();
    if (h < 3) return degenerate(hull);
    auto next = [h](std::size_t i) { return i + 1 == h ? 0 : i + 1; };
    Rectangle2 best;
    best.area = -1;
    std::size_t right = 0;
    std::size_t top = 0;
    std::size_t left = 0;
    for (std::size_t i = 0; i < h; ++i) {
        Real ux = 0;
        Real uy = 0;
        if (!edgeDirection(hull[i], hull[next(i)], ux, uy)) continue;
        const Real vx = -uy;  // inward normal of a counter-clockwise edge
        const Real vy = ux;
        // Each pointer advances while that improves its extreme; a strict comparison stops on
        // ties, and at most h steps per edge bound the loop even for a non-convex input.
        if (best.area < 0) right = next(i);
        for (std::size_t s = 0; s < h && dot(hull[next(right)], ux, uy) > dot(hull[right], ux, uy);
             ++s) {
            right = next(right);
        }
        if (best.area < 0) top = right;
        for (std::size_t s = 0; s < h && dot(hull[next(top)], vx, vy) > dot(hull[top], vx, vy);
             ++s) {
            top = next(top);
        }
        if (best.area < 0) left = top;
        for (std::size_t s = 0; s < h && dot(hull[next(left)], ux, uy) < dot(hull[left], ux, uy);
             ++s) {
            left = next(left);
        }
        const Real width = dot(hull[right], ux, uy) - dot(hull[left], ux, uy);
        const Real height = dot(hull[top], vx, vy) - dot(hull[i], vx, vy);
        const Real area = width * height;
        if (best.area < 0 || area < best.area) best = Rectangle2{ux, uy, area};
    }
    return best.area < 0 ? degenerate(hull) : best;
}

Rectangle2 minAreaRectangleBruteForce(const std::vector<Point2>& hull) {
    const std::size_t h = hull.size();
    if (h < 3) return degenerate(hull);
    Rectangle2 best;
    best.area = -1;
    for (std::size_t i = 0; i < h; ++i) {
        Real ux = 0;
        Real uy = 0;
        if (!edgeDirection(hull[i], hull[(i + 1) % h], ux, uy)) continue;
        Real lo_u = dot(hull[0], ux, uy);
        Real hi_u = lo_u;
        Real lo_v = dot(hull[0], -uy, ux);
        Real hi_v = lo_v;
        for (const Point2& p : hull) {
            lo_u = std::min(lo_u, dot(p, ux, uy));
            hi_u = std::max(hi_u, dot(p, ux, uy));
            lo_v = std::min(lo_v, dot(p, -uy, ux));
            hi_v = std::max(hi_v, dot(p, -uy, ux));
        }
        const Real area = (hi_u - lo_u) * (hi_v - lo_v);
        if (best.area < 0 || area < best.area) best = Rectangle2{ux, uy, area};
    }
    return best.area < 0 ? degenerate(hull) : best;
}

}  // namespace collision
