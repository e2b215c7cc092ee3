// collision/src/geometry/closest_points.h -- closest points between segments (RTCD 5.1.9), the
// one implementation behind capsule-capsule (collide and contact) and the triangle-triangle
// distance. Private to collision; inline because every caller sits in a hot loop.
#pragma once

#include <algorithm>

#include "collision/math.h"

namespace collision {

/// Parameters of the closest points p1 + s (q1 - p1) and p2 + t (q2 - p2), s, t in [0, 1].
struct SegmentParameters {
    Real s = 0;
    Real t = 0;
};

/// Closest points of segments p1q1 and p2q2 (RTCD 5.1.9). A segment whose squared length is at
/// most `length_epsilon`^2 is taken as its first point (0 treats only exact points so).
/// Near-parallel segments (a e - b^2 = a e sin^2 below 16 eps a e) take s = 0 and clamp from
/// there, which still gives a closest pair. Approximate: the parameters carry the rounding of a
/// few dot products; never NaN for finite input.
inline SegmentParameters closestSegmentSegment(const Vec3& p1, const Vec3& q1, const Vec3& p2,
                                               const Vec3& q2, Real length_epsilon) {
    const Vec3 d1 = q1 - p1;
    const Vec3 d2 = q2 - p2;
    const Vec3 r = p1 - p2;
    const Real a = d1.squaredNorm();
    const Real e = d2.squaredNorm();
    const Real f = d2.dot(r);
    const Real eps2 = length_epsilon * length_epsilon;
    SegmentParameters out;
    Real& s = out.s;
    Real& t = out.t;
    if (a <= eps2 && e <= eps2) return out;
    if (a <= eps2) {
        t = std::clamp(f / e, Real(0), Real(1));
        return out;
    }
    const Real c = d1.dot(r);
    if (e <= eps2) {
        s = std::clamp(-c / a, Real(0), Real(1));
        return out;
    }
    const Real b = d1.dot(d2);
    const Real denom = a * e - b * b;
    if (denom > Real(16) * kEpsilon * a * e) {
        s = std::clamp((b * f - c * e) / denom, Real(0), Real(1));
    }
    t = (b * s + f) / e;
    if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, Real(0), Real(1));
    } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, Real(0), Real(1));
    }
    return out;
}

}  // namespace collision
