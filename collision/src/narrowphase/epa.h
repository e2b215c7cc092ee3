// collision/src/narrowphase/epa.h -- the one EPA (van den Bergen 2001; RTCD 9.5) on the ConvexCore
// support mappings of gjk.h, started from GJK's final simplex: the penetration depth with normal
// and witness points (contact()), or the bounded decision whether the depth exceeds a threshold
// (collide(), through decideConvexCores). Private to collision.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

#include "collision/math.h"
#include "narrowphase/gjk.h"

namespace collision {

enum class EpaState : std::uint8_t { Converged, Failed };

struct EpaOutput {
    EpaState state = EpaState::Failed;
    /// Penetration depth of the cores (radii ignored), >= 0 up to rounding when `start` holds
    /// the origin: translating B by depth * normal makes the cores touch. From a simplex without
    /// the origin (GJK stopped Separated) it can be negative, with the normal and witnesses of a
    /// face the origin lies outside of: not the closest points; use GJK's answer then.
    Real depth = 0;
    Vec3 normal = Vec3::UnitX();  ///< unit, A's frame, from A towards B
    Vec3 point_a = Vec3::Zero();  ///< deepest point of core A along normal, A's frame
    Vec3 point_b = Vec3::Zero();  ///< deepest point of core B along -normal, A's frame
    std::int32_t iterations = 0;
    /// When `start` was a tetrahedron: the distance from the origin of its nearest face, as the
    /// first iteration found it; NaN otherwise (and when every face is degenerate). For
    /// decideConvexCores (gjk.h).
    Real start_closest = std::numeric_limits<Real>::quiet_NaN();
};

/// EPA iteration cap (expansions of the polytope).
inline constexpr int kEpaMaxIterations = 256;
/// EPA stops when the support distance h(n) and the face distance differ by at most
/// kEpaRelativeTolerance * scale: the depth is then accurate to that absolute error (the face
/// distance is a lower bound on the depth, h(n) an upper bound; van den Bergen 2001 §4).
inline constexpr Real kEpaRelativeTolerance = std::max(Real(1e-11), Real(64) * kEpsilon);

/// Penetration depth, normal and witness points of two overlapping cores, starting from GJK's
/// final simplex `start` (any size 1..4; it is blown up to a tetrahedron). A flat configuration
/// space obstacle gives depth 0 along its plane normal. Failed when the cap is reached or the
/// polytope degenerates; never NaN for finite input.
EpaOutput epaPenetration(const ConvexCore& a, const ConvexCore& b, const RelativePose& b_in_a,
                         const WitnessSimplex& start, Real scale);

/// The bounded EPA: whether the penetration depth of two overlapping cores exceeds `threshold`
/// (Penetrating) or not (Touching), from GJK's final simplex `start` (points of A - B). It stops
/// as soon as the bounds decide: the nearest face's distance is a lower bound on the depth, the
/// support along any direction an upper bound (van den Bergen 2001 §4); converged or degenerate
/// at depth ~ threshold is Touching. Failed at kGjkMaxIterations or when the polytope is full.
/// `iterations` is increased by the iterations run.
ContactState epaDecide(const MinkowskiDifference& cso, const GjkSimplex<Vec3>& start,
                       Real threshold, Real scale, std::int32_t& iterations);

}  // namespace collision
