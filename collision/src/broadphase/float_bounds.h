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

/// The largest float <= x (x finite; NaN stays NaN). Doubles beyond the float range go to
/// -/+infinity or -/+FLT_MAX first: converting them would be undefined. The step down is chosen
/// by masks, not a branch: for coordinates that are not floats, rounding to nearest lands above
/// x about half the time, and a branch on it was mispredicted as often.
inline float roundDown(double x) {
    if (x > double(kFloatMax)) return kFloatMax;
    if (x < -double(kFloatMax)) return -kInf;
    const float f = static_cast<float>(x);
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(f);
    // nextDown(f): one unit towards -infinity, -denorm_min below a zero.
    const std::uint32_t zero = 0u - std::uint32_t((bits << 1) == 0);
    const std::uint32_t below = ((bits + (bits >> 31) * 2 - 1) & ~zero) | (0x80000001u & zero);
    const std::uint32_t down = 0u - std::uint32_t(double(f) > x);
    return std::bit_cast<float>((bits & ~down) | (below & down));
}

/// The smallest float >= x (x finite).
inline float roundUp(double x) { return -roundDown(-x); }

}  // namespace collision::float_bounds
