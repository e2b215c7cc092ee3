// collision/geometry/convex_hull.h -- 3-D convex hull of a point set (quickhull, Barber et al.
// 1996).
#pragma once

#include <string>
#include <vector>

#include "collision/geometry/shape.h"

namespace collision {

struct ConvexHullOutput {
    bool ok = false;
    std::string error;     ///< why not ok: too few points, all coplanar, NaN/Inf in input
    ConvexPolytope hull;   ///< outward CCW triangles; vertices are the hull's extreme points only
};

/// Quickhull with a tolerance relative to the point set's extent. Fails (ok = false) on fewer than
/// 4 points, on coplanar or collinear sets, and on non-finite coordinates.
ConvexHullOutput computeConvexHull(const std::vector<Vec3>& points);

}  // namespace collision
