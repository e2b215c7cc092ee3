// collision/src/volumes/fit_slack.h -- what the fitted point-set volumes share (the bodies' in
// bounding_volumes.cpp and obb_fit.cpp, the BVH nodes' in bvh_volumes.cpp): the relative
// enlargement that absorbs rounding, and the projection range of a point set on three axes.
// Private to collision.
#pragma once

#include <limits>

#include "collision/math.h"

namespace collision {

/// A few ulps of the set's size: every input point tests inside a fitted sphere or box even after
/// the rounding of the circumsphere or projection maths (and of the caller's containment test).
inline constexpr Real kFitSlack = Real(16) * kEpsilon;

/// One point's step of projectionRange (for callers that visit the points without a container).
inline void extendProjectionRange(const Mat3& axes, const Vec3& p, const Vec3& origin, Vec3& lo,
                                  Vec3& hi) {
    const Vec3 proj = axes.transpose() * (p - origin);
    lo = lo.cwiseMin(proj);
    hi = hi.cwiseMax(proj);
}

/// The range [lo, hi] of the coordinates of `points` in the frame `axes` (columns) about
/// `origin`: lo = min, hi = max of axes^T (p - origin). Exact up to the rounding of the
/// products, which kFitSlack covers. `points` must not be empty.
template <class Points>
void projectionRange(const Mat3& axes, const Points& points, const Vec3& origin, Vec3& lo,
                     Vec3& hi) {
    lo = Vec3::Constant(std::numeric_limits<Real>::max());
    hi = Vec3::Constant(std::numeric_limits<Real>::lowest());
    for (const Vec3& p : points) extendProjectionRange(axes, p, origin, lo, hi);
}

}  // namespace collision
