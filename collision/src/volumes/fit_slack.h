// collision/src/volumes/fit_slack.h -- the relative enlargement of the bodies' fitted point-set
// volumes (bounding_volumes.cpp, obb_fit.cpp). Private to collision.
#pragma once

#include "collision/math.h"

namespace collision {

/// A few ulps of the set's size: every input point tests inside a fitted sphere or box even after
/// the rounding of the circumsphere or projection maths (and of the caller's containment test).
inline constexpr Real kFitSlack = Real(16) * kEpsilon;

}  // namespace collision
