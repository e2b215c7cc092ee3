// collision/src/geometry/triangle_triangle.h -- exact triangle-triangle intersection test (narrow
// phase, private): the per-pair test of mesh-mesh collision.
#pragma once

#include "collision/math.h"

namespace collision {

/// Do the closed triangles (p1, q1, r1) and (p2, q2, r2) share at least one point?
/// Touching counts: a shared vertex or edge, a vertex on the other triangle, coplanar overlap.
/// Guigue & Devillers 2003 with exact orientation predicates (predicates.h), so the answer is
/// exact for the given double coordinates, coplanar and touching cases included. A degenerate
/// triangle (collinear corners, decided exactly) is tested as the segment or point it is.
bool testTriangleTriangle(const Vec3& p1, const Vec3& q1, const Vec3& r1, const Vec3& p2,
                          const Vec3& q2, const Vec3& r2);

}  // namespace collision
