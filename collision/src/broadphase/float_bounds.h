// collision/src/broadphase/float_bounds.h -- doubles rounded to floats outward, so a float box
// built from a double box contains it (the packed broad phases test floats, then confirm in
// double).
#pragma once

#include <bit>
#include <cstdint>
#include <limits>

namespace collision::float_bounds {

inline constexpr float kFloatMax = std::numeric_limits<float>::max();
inline constexpr float kInf = std::numeric_limits<float>::infinity();

/// The next float towards -infinity (f finite or +infinity).
inline float nextDown(float f) {
    if (f == 0) return -std::numeric_limits<float>::denorm_min();
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(f);
    return std::bit_cast<float>(f > 0 ? bits - 1 : bits + 1);
}

/// The largest float <= x (x finite). Doubles beyond the float range go to -/+infinity or
/// -/+FLT_MAX first: converting them would be undefined.
inline float roundDown(double x) {
    if (x > double(kFloatMax)) return kFloatMax;
    if (x < -double(kFloatMax)) return -kInf;
    const float f = static_cast<float>(x);
    return double(f) > x ? nextDown(f) : f;
}

/// The smallest float >= x (x finite).
inline float roundUp(double x) { return -roundDown(-x); }

}  // namespace collision::float_bounds
