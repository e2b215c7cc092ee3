// collision/src/narrowphase/epa.h -- GJK distance that keeps witness points (van den Bergen 1999)
// and EPA penetration depth with normal and witness points (van den Bergen 2001; RTCD 9.5), both on
// the ConvexCore support mappings of gjk.h. Used by contact() (contact.cpp); private to collision.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

#include "collision/math.h"
#include "narrowphase/gjk.h"

namespace collision {

/// A vertex of the configuration-space obstacle A - B with the support points that made it,
/// all in A's frame: w = a - b. No default member values (EPA keeps arrays of them and must not
/// pay for zeroing); value-initialise (`{}`) where zeros are needed.
struct SupportVertex {
    Vec3 w;
    Vec3 a;
    Vec3 b;
};

/// A GJK simplex of up to four support vertices.
struct WitnessSimplex {
    std::array<SupportVertex, 4> v{};
    std::int32_t n = 0;
};

struct GjkWitnessOutput {
    GjkState state = GjkState::Failed;
    /// Core distance (radii ignored) when Separated; |v| of the last iterate when Failed.
    Real distance = 0;
    /// Closest points of the cores, A's frame: the same barycentric combination of the simplex's
    /// support points (van den Bergen 1999 §3). Valid when Separated (and as a best guess when
    /// Failed).
    Vec3 point_a = Vec3::Zero();
    Vec3 point_b = Vec3::Zero();
    std::int32_t iterations = 0;
    WitnessSimplex simplex;  ///< final simplex: the EPA start when Overlapping
};

/// GJK distance between the cores of `a` (its frame) and `b` placed by `b_in_a`, with witnesses.
/// Tolerance and guarantee as gjkDistance (gjk.h): relative error of the distance at most
/// kGjkRelativeTolerance or rounding near contact; Overlapping when the origin is in the simplex
/// up to rounding relative to `scale`; Failed after kGjkMaxIterations. Never NaN for finite input.
GjkWitnessOutput gjkWitness(const ConvexCore& a, const ConvexCore& b, const RelativePose& b_in_a,
                            Real scale);

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

}  // namespace collision
