// collision/src/geometry/triangle_triangle.cpp -- exact closed-triangle intersection, Guigue &
// Devillers 2003 ("Fast and Robust Triangle-Triangle Overlap Test Using Orientation Predicates",
// JGT 8(1)).
// Invariant: every branch is decided by exact orient3d/orient2d signs or exact coordinate
// comparisons, so the result is exact for the given doubles; zero signs (touching) count as
// intersecting throughout.
#include "geometry/triangle_triangle.h"

#include <array>
#include <cmath>

#include "geometry/predicates.h"

namespace collision {

namespace {

struct Point2 {
    double x = 0;
    double y = 0;
};

int orient(const Point2& a, const Point2& b, const Point2& c) {
    return orient2d(a.x, a.y, b.x, b.y, c.x, c.y);
}

// Drops coordinate `axis`: injective on any plane whose normal has a non-zero `axis` component.
Point2 project(const Vec3& p, int axis) {
    switch (axis) {
        case 0:
            return Point2{double(p.y()), double(p.z())};
        case 1:
            return Point2{double(p.z()), double(p.x())};
        default:
            return Point2{double(p.x()), double(p.y())};
    }
}

// c within the axis-aligned box of segment ab (exact comparisons); with orient == 0 it is on ab.
bool inBox(const Point2& a, const Point2& b, const Point2& c) {
    return std::fmin(a.x, b.x) <= c.x && c.x <= std::fmax(a.x, b.x) && std::fmin(a.y, b.y) <= c.y &&
           c.y <= std::fmax(a.y, b.y);
}

// Closed segments ab and cd (either may be a point) share a point. RTCD 5.1.9.1, exact signs.
bool segmentsIntersect2d(const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
    const int o1 = orient(a, b, c);
    const int o2 = orient(a, b, d);
    const int o3 = orient(c, d, a);
    const int o4 = orient(c, d, b);
    if (o1 * o2 < 0 && o3 * o4 < 0) return true;
    if (o1 == 0 && inBox(a, b, c)) return true;
    if (o2 == 0 && inBox(a, b, d)) return true;
    if (o3 == 0 && inBox(c, d, a)) return true;
    if (o4 == 0 && inBox(c, d, b)) return true;
    return false;
}

// p in the closed, non-degenerate triangle abc (either winding).
bool pointInTriangle2d(const Point2& p, const Point2& a, const Point2& b, const Point2& c) {
    const int s0 = orient(a, b, p);
    const int s1 = orient(b, c, p);
    const int s2 = orient(c, a, p);
    return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

// Coplanar, non-degenerate triangles: they meet iff two edges cross or one triangle holds a
// vertex of the other. This replaces Guigue-Devillers' 2-D decision tree by the plain definition
// (9 + 2 exact tests); the coplanar case is rare, so clarity wins.
bool coplanarTrianglesIntersect(const std::array<Point2, 3>& t1, const std::array<Point2, 3>& t2) {
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            if (segmentsIntersect2d(t1[i], t1[(i + 1) % 3], t2[j], t2[(j + 1) % 3])) return true;
        }
    }
    return pointInTriangle2d(t1[0], t2[0], t2[1], t2[2]) ||
           pointInTriangle2d(t2[0], t1[0], t1[1], t1[2]);
}

// The coordinate to drop so that triangle (a, b, c) projects non-degenerately, or -1 when the
// triangle is degenerate (collinear corners: all three projections degenerate, exactly).
// Prefers the dominant normal component, the best-conditioned projection.
int projectionAxis(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = (b - a).cross(c - a).cwiseAbs();
    std::array<int, 3> order{0, 1, 2};
    if (n[order[1]] > n[order[0]]) std::swap(order[0], order[1]);
    if (n[order[2]] > n[order[1]]) std::swap(order[1], order[2]);
    if (n[order[1]] > n[order[0]]) std::swap(order[0], order[1]);
    for (const int axis : order) {
        if (orient(project(a, axis), project(b, axis), project(c, axis)) != 0) return axis;
    }
    return -1;
}

bool coplanarIntersect(const Vec3& p1, const Vec3& q1, const Vec3& r1, const Vec3& p2,
                       const Vec3& q2, const Vec3& r2, int axis) {
    const std::array<Point2, 3> t1{project(p1, axis), project(q1, axis), project(r1, axis)};
    const std::array<Point2, 3> t2{project(p2, axis), project(q2, axis), project(r2, axis)};
    return coplanarTrianglesIntersect(t1, t2);
}

// Guigue-Devillers §3 final step: with p1 alone on the positive side of triangle 2 and p2 alone
// on the positive side of triangle 1 (after the caller's permutations), the intervals on the
// line of intersection overlap iff these two orientations are non-positive.
bool checkMinMax(const Vec3& p1, const Vec3& q1, const Vec3& r1, const Vec3& p2, const Vec3& q2,
                 const Vec3& r2) {
    // ((p2 - q1) x (p1 - q1)) . (q2 - q1) > 0 → separated.
    if (orient3d(q1, p2, p1, q2) > 0) return false;
    // ((p2 - p1) x (r1 - p1)) . (r2 - p1) > 0 → separated.
    if (orient3d(p1, p2, r1, r2) > 0) return false;
    return true;
}

// Permutes triangle 2 so that p2 is alone on its side of triangle 1 (Guigue-Devillers TRI_TRI_3D).
// Returns 1/0 for a decision, -1 for "coplanar".
int triTri3d(const Vec3& p1, const Vec3& q1, const Vec3& r1, const Vec3& p2, const Vec3& q2,
             const Vec3& r2, int dp2, int dq2, int dr2) {
    if (dp2 > 0) {
        if (dq2 > 0) return checkMinMax(p1, r1, q1, r2, p2, q2);
        if (dr2 > 0) return checkMinMax(p1, r1, q1, q2, r2, p2);
        return checkMinMax(p1, q1, r1, p2, q2, r2);
    }
    if (dp2 < 0) {
        if (dq2 < 0) return checkMinMax(p1, q1, r1, r2, p2, q2);
        if (dr2 < 0) return checkMinMax(p1, q1, r1, q2, r2, p2);
        return checkMinMax(p1, r1, q1, p2, q2, r2);
    }
    if (dq2 < 0) {
        if (dr2 >= 0) return checkMinMax(p1, r1, q1, q2, r2, p2);
        return checkMinMax(p1, q1, r1, p2, q2, r2);
    }
    if (dq2 > 0) {
        if (dr2 > 0) return checkMinMax(p1, r1, q1, p2, q2, r2);
        return checkMinMax(p1, q1, r1, q2, r2, p2);
    }
    if (dr2 > 0) return checkMinMax(p1, q1, r1, r2, p2, q2);
    if (dr2 < 0) return checkMinMax(p1, r1, q1, r2, p2, q2);
    return -1;
}

// Closed segment st against the closed, non-degenerate triangle abc (projection `axis` valid
// for abc).
bool segmentTriangle(const Vec3& s, const Vec3& t, const Vec3& a, const Vec3& b, const Vec3& c,
                     int axis) {
    const int os = orient3d(a, b, c, s);
    const int ot = orient3d(a, b, c, t);
    if (os * ot > 0) return false;
    if (os == 0 && ot == 0) {
        const Point2 s2 = project(s, axis);
        const Point2 t2 = project(t, axis);
        const Point2 a2 = project(a, axis);
        const Point2 b2 = project(b, axis);
        const Point2 c2 = project(c, axis);
        return pointInTriangle2d(s2, a2, b2, c2) || segmentsIntersect2d(s2, t2, a2, b2) ||
               segmentsIntersect2d(s2, t2, b2, c2) || segmentsIntersect2d(s2, t2, c2, a2);
    }
    // The segment reaches the plane; the line st pierces the closed triangle iff it passes on the
    // same side of all three edges (RTCD 5.3.4, signs exact).
    const int e0 = orient3d(s, t, a, b);
    const int e1 = orient3d(s, t, b, c);
    const int e2 = orient3d(s, t, c, a);
    return (e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0);
}

// The extreme points of collinear a, b, c along their widest coordinate (exact comparisons).
void collinearExtent(const Vec3& a, const Vec3& b, const Vec3& c, Vec3& lo, Vec3& hi) {
    const Vec3 lo_c = a.cwiseMin(b).cwiseMin(c);
    const Vec3 hi_c = a.cwiseMax(b).cwiseMax(c);
    int axis = 0;
    (hi_c - lo_c).maxCoeff(&axis);
    const std::array<const Vec3*, 3> pts{&a, &b, &c};
    lo = a;
    hi = a;
    for (const Vec3* p : pts) {
        if ((*p)[axis] < lo[axis]) lo = *p;
        if ((*p)[axis] > hi[axis]) hi = *p;
    }
}

// Two closed segments in 3-D: coplanar (exact) and meeting in every coordinate projection. For
// coplanar segments some projection is injective on their plane (or line), so this is exact.
bool segmentsIntersect3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    if (orient3d(a, b, c, d) != 0) return false;
    for (int axis = 0; axis < 3; ++axis) {
        if (!segmentsIntersect2d(project(a, axis), project(b, axis), project(c, axis),
                                 project(d, axis))) {
            return false;
        }
    }
    return true;
}

}  // namespace

bool testTriangleTriangle(const Vec3& p1, const Vec3& q1, const Vec3& r1, const Vec3& p2,
                          const Vec3& q2, const Vec3& r2) {
    const int axis1 = projectionAxis(p1, q1, r1);
    const int axis2 = projectionAxis(p2, q2, r2);
    if (axis1 < 0 || axis2 < 0) {
        // Degenerate input: test the segments (or points) the triangles really are.
        if (axis1 < 0 && axis2 < 0) {
            Vec3 s1, t1, s2, t2;
            collinearExtent(p1, q1, r1, s1, t1);
            collinearExtent(p2, q2, r2, s2, t2);
            return segmentsIntersect3d(s1, t1, s2, t2);
        }
        Vec3 s, t;
        if (axis1 < 0) {
            collinearExtent(p1, q1, r1, s, t);
            return segmentTriangle(s, t, p2, q2, r2, axis2);
        }
        collinearExtent(p2, q2, r2, s, t);
        return segmentTriangle(s, t, p1, q1, r1, axis1);
    }

    // Guigue-Devillers §3: reject when a triangle lies strictly on one side of the other's plane.
    const int dp1 = orient3d(p2, q2, r2, p1);
    const int dq1 = orient3d(p2, q2, r2, q1);
    const int dr1 = orient3d(p2, q2, r2, r1);
    if (dp1 * dq1 > 0 && dp1 * dr1 > 0) return false;
    const int dp2 = orient3d(p1, q1, r1, p2);
    const int dq2 = orient3d(p1, q1, r1, q2);
    const int dr2 = orient3d(p1, q1, r1, r2);
    if (dp2 * dq2 > 0 && dp2 * dr2 > 0) return false;

    // Permute triangle 1 so that p1 is alone on its side of triangle 2 (and triangle 2's
    // orientation flips with it), then decide on the line of intersection.
    int result = -1;
    if (dp1 > 0) {
        if (dq1 > 0) {
            result = triTri3d(r1, p1, q1, p2, r2, q2, dp2, dr2, dq2);
        } else if (dr1 > 0) {
            result = triTri3d(q1, r1, p1, p2, r2, q2, dp2, dr2, dq2);
        } else {
            result = triTri3d(p1, q1, r1, p2, q2, r2, dp2, dq2, dr2);
        }
    } else if (dp1 < 0) {
        if (dq1 < 0) {
            result = triTri3d(r1, p1, q1, p2, q2, r2, dp2, dq2, dr2);
        } else if (dr1 < 0) {
            result = triTri3d(q1, r1, p1, p2, q2, r2, dp2, dq2, dr2);
        } else {
            result = triTri3d(p1, q1, r1, p2, r2, q2, dp2, dr2, dq2);
        }
    } else if (dq1 < 0) {
        if (dr1 >= 0) {
            result = triTri3d(q1, r1, p1, p2, r2, q2, dp2, dr2, dq2);
        } else {
            result = triTri3d(p1, q1, r1, p2, q2, r2, dp2, dq2, dr2);
        }
    } else if (dq1 > 0) {
        if (dr1 > 0) {
            result = triTri3d(p1, q1, r1, p2, r2, q2, dp2, dr2, dq2);
        } else {
            result = triTri3d(q1, r1, p1, p2, q2, r2, dp2, dq2, dr2);
        }
    } else if (dr1 > 0) {
        result = triTri3d(r1, p1, q1, p2, q2, r2, dp2, dq2, dr2);
    } else if (dr1 < 0) {
        result = triTri3d(r1, p1, q1, p2, r2, q2, dp2, dr2, dq2);
    }
    if (result >= 0) return result == 1;
    return coplanarIntersect(p1, q1, r1, p2, q2, r2, axis1);
}

}  // namespace collision
