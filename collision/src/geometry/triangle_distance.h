// collision/src/geometry/triangle_distance.h -- closest points between two triangles (private): the
// leaf test of the mesh-mesh distance query.
#pragma once

#include "collision/math.h"

namespace collision {

/// Closest points of two triangles and their distance.
struct TriangleDistance {
    Real distance = 0;
    Vec3 point_on_1 = Vec3::Zero();
    Vec3 point_on_2 = Vec3::Zero();
};

/// Distance between the closed triangles (p1, q1, r1) and (p2, q2, r2) (RTCD 5.1.10): 0 when
/// they intersect (exact test, triangle_triangle.h), with witnesses a rounding apart (where an
/// edge pierces the other triangle, or the closest candidate pair); otherwise the minimum of
/// the 6 vertex-triangle (RTCD 5.1.5) and 9 edge-edge (RTCD 5.1.9) closest-point pairs, one of
/// which realises the distance of disjoint triangles. Approximate: rounding of the projections,
/// a few ulps of the coordinates' magnitude. Degenerate triangles are handled as their
/// segments or points.
TriangleDistance distanceTriangleTriangle(const Vec3& p1, const Vec3& q1, const Vec3& r1,
                                          const Vec3& p2, const Vec3& q2, const Vec3& r2);

}  // namespace collision
