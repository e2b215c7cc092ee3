// collision/src/geometry/predicates.h -- orientation predicates whose sign is exact (narrow phase,
// private). Used by the triangle-triangle test, where a wrong sign would flip a touching case.
#pragma once

#include "collision/math.h"

namespace collision {

/// Sign (+1, 0, -1) of det[b - a, c - a, d - a] = ((b - a) x (c - a)) . (d - a): positive when d
/// lies on the side the counter-clockwise normal of triangle (a, b, c) points to.
/// Guarantee: the sign is exact for the double values given (Real is widened to double), by a
/// floating-point filter (Shewchuk 1997 error bound) with an exact expansion-arithmetic fallback.
/// Exactness assumes no intermediate underflow/overflow (|coordinates| within about 1e-70..1e70,
/// or exactly zero).
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Sign of det[a - c, b - c] in 2D: positive when (a, b, c) turn counter-clockwise. Same
/// guarantee as orient3d.
int orient2d(double ax, double ay, double bx, double by, double cx, double cy);

}  // namespace collision
