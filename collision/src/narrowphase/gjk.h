// collision/src/narrowphase/gjk.h -- the one GJK (van den Bergen 1999; RTCD 9.5) between convex
// cores, as a distance (gjkDistance: collide() and conservative advancement) or with witness
// points (gjkWitness: contact()), and the state decision both queries take from a GJK run
// (decideConvexCores; the bounded EPA of epa.h when the cores overlap). Private to collision.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "collision/geometry/shape.h"
#include "collision/math.h"
#include "collision/narrowphase/narrow_phase.h"

namespace collision {

/// A convex set given by its support mapping, optionally inflated by `radius`: spheres are a point
/// and capsules a segment plus radius, which keeps GJK exact on their round parts.
struct ConvexCore {
    enum class Kind : std::uint8_t { Point, Segment, Triangle, Box, Points };
    Kind kind = Kind::Point;
    std::array<Vec3, 3> v{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};  ///< point/segment/triangle
    Vec3 half_extents = Vec3::Zero();                                 ///< box
    const Vec3* points = nullptr;  ///< point cloud (hull vertices), not owned
    std::int32_t point_count = 0;
    Real radius = 0;  ///< inflation, >= 0

    /// The core of a convex shape in its local frame (a mesh gives its convex hull). The core
    /// borrows the shape's hull vertices: the shape must outlive it.
    static ConvexCore fromShape(const Shape& shape);
    static ConvexCore triangle(const Vec3& a, const Vec3& b, const Vec3& c);

    /// Support point of the core (without radius) in direction `dir` (any length, may be zero).
    Vec3 support(const Vec3& dir) const;
    /// Largest distance of the inflated set from the local origin.
    Real boundingRadius() const;
};

/// B's placement in A's frame: point_in_a = rotation * point_in_b + position.
struct RelativePose {
    Mat3 rotation = Mat3::Identity();
    Vec3 position = Vec3::Zero();
};

/// A point of A's frame in B's frame.
inline Vec3 toB(const RelativePose& b_in_a, const Vec3& p_in_a) {
    return b_in_a.rotation.transpose() * (p_in_a - b_in_a.position);
}

/// pose_a^-1 * pose_b, subtracting positions first so that far-from-origin poses lose nothing
/// to the translation (metamorphic tests translate scenes by 1e6).
/// Flattened: GCC otherwise calls Eigen's quaternion rotation and matrix out of line on every
/// contact() (inlining changes no operation, so no bit).
[[gnu::always_inline, gnu::flatten]] inline RelativePose relativePose(const Pose& pose_a,
                                                                      const Pose& pose_b) {
    const Quat inv_a = pose_a.orientation.conjugate();
    RelativePose rel;
    rel.rotation = (inv_a * pose_b.orientation).toRotationMatrix();
    rel.position = inv_a * (pose_b.position - pose_a.position);
    return rel;
}

enum class GjkState : std::uint8_t { Separated, Overlapping, Failed };

/// What every GJK run reports (gjkDistance, gjkWitness).
struct GjkSummary {
    GjkState state = GjkState::Failed;
    /// Between the cores (radii ignored) when Separated: an upper bound; |v| of the last iterate
    /// when Failed; 0 when Overlapping.
    Real distance = 0;
    /// Lower bound on the core distance from GJK's separating planes (may be <= 0; 0 when
    /// Overlapping). gjkDistance and gjkWitness run one loop whose iterates (w, v, simplex) are
    /// bit-identical (gjkWitness only keeps a and b beside w); gjkWitness evaluates this bound
    /// only when Failed (-inf otherwise, Overlapping aside), where it is the same as gjkDistance's.
    Real lower_bound = 0;
    std::int32_t iterations = 0;
    /// The point of the final simplex nearest the origin (GJK's v), A's frame: the closest
    /// point of A - B when Separated (a - b of the closest pair).
    Vec3 closest = Vec3::Zero();
};

struct GjkOutput : GjkSummary {
    std::int32_t simplex_count = 0;  ///< final simplex, for the EPA decision
    std::array<Vec3, 4> simplex{};   ///< vertices of A - B, in A's frame
};

/// A support point closer than kDuplicateRelative times its size to a vertex already held (by
/// GJK's simplex or an EPA polytope) is that vertex again: it cannot make progress, and rounding
/// decides the rest.
inline constexpr Real kDuplicateRelative = Real(8) * kEpsilon;

/// Iteration cap of GJK and of the EPA decision.
inline constexpr int kGjkMaxIterations = 64;
/// GJK stops when |v|^2 - v.w <= kGjkRelativeTolerance * |v|^2, which bounds the relative error of
/// the distance |v| by kGjkRelativeTolerance (van den Bergen 1999 §4). Near contact rounding stops
/// it earlier (no progress or a repeated support point), with the error then set by rounding.
inline constexpr Real kGjkRelativeTolerance = Real(1e-12);

/// Distance between the cores of `a` (in its frame) and `b` placed by `b_in_a`. Overlapping when
/// the origin is enclosed by the simplex up to rounding (relative to `scale`). Failed only when
/// the iteration cap is hit; never NaN for finite input.
GjkOutput gjkDistance(const ConvexCore& a, const ConvexCore& b, const RelativePose& b_in_a,
                      Real scale);

/// A vertex of the configuration-space obstacle A - B with the support points that made it,
/// all in A's frame: w = a - b. No default member values (EPA keeps arrays of them and must not
/// pay for zeroing); value-initialise (`{}`) where zeros are needed.
struct SupportVertex {
    Vec3 w;
    Vec3 a;
    Vec3 b;
};

/// A GJK simplex of up to four support vertices.
template <class Vertex>
struct GjkSimplex {
    std::array<Vertex, 4> v{};
    std::int32_t n = 0;
};
using WitnessSimplex = GjkSimplex<SupportVertex>;

/// The point of A - B of a GJK vertex of either kind.
inline const Vec3& pointOf(const Vec3& v) { return v; }
inline const Vec3& pointOf(const SupportVertex& v) { return v.w; }

// Support mapping of the configuration-space obstacle A - B, in A's frame. A GJK vertex is the
// point w = a - b alone (Vec3), or with the support points a and b that made it (SupportVertex)
// when witness points are wanted.
struct MinkowskiDifference {
    const ConvexCore& a;
    const ConvexCore& b;
    const RelativePose& b_in_a;

    Vec3 support(const Vec3& dir) const { return supportVertex<Vec3>(dir); }

    template <class Vertex>
    Vertex supportVertex(const Vec3& dir) const {
        const Vec3 dir_in_b = b_in_a.rotation.transpose() * (-dir);
        const Vec3 on_b = b_in_a.rotation * b.support(dir_in_b) + b_in_a.position;
        const Vec3 on_a = a.support(dir);
        if constexpr (std::is_same_v<Vertex, Vec3>) {
            return on_a - on_b;
        } else {
            return SupportVertex{on_a - on_b, on_a, on_b};
        }
    }
};

struct GjkWitnessOutput : GjkSummary {
    /// Closest points of the cores, A's frame: the same barycentric combination of the simplex's
    /// support points (van den Bergen 1999 §3). Valid when Separated (and as a best guess when
    /// Failed).
    Vec3 point_a = Vec3::Zero();
    Vec3 point_b = Vec3::Zero();
    WitnessSimplex simplex;  ///< final simplex: the EPA start when Overlapping
};

/// GJK distance between the cores of `a` (its frame) and `b` placed by `b_in_a`, with witnesses.
/// Tolerance and guarantee as gjkDistance (gjk.h): relative error of the distance at most
/// kGjkRelativeTolerance or rounding near contact; Overlapping when the origin is in the simplex
/// up to rounding relative to `scale`; Failed after kGjkMaxIterations. Never NaN for finite input.
GjkWitnessOutput gjkWitness(const ConvexCore& a, const ConvexCore& b, const RelativePose& b_in_a,
                            Real scale);

/// The touching convention applied to a signed distance (negative = penetration depth).
CollideOutput classifySignedDistance(Real signed_distance, Real tolerance);

/// The narrow-phase state of two convex cores with radii from a finished GJK run `g` (either
/// query) and its final simplex of A - B points: signed distance = core distance - radii, or the
/// bounded EPA decision when the cores overlap and the radii are below `tolerance`, or what GJK's
/// bounds prove when it hit its cap. Touching when |signed distance| <= tolerance. collide() and
/// contact() both decide convex pairs here, on bit-identical GJK runs, so their states agree by
/// construction. `start_closest`, when the caller has it, is the distance from the origin of the
/// nearest face of the tetrahedron `simplex` closed by EpaPolytope::closeTetrahedron (the full
/// EPA's first iteration, epa.h): the bounded EPA's first iteration computes the same number from
/// the same faces, so the decision is the same and that iteration is skipped.
CollideOutput decideConvexCores(const GjkSummary& g, const Vec3* simplex, int simplex_count,
                                const MinkowskiDifference& cso, Real radii, Real tolerance,
                                Real scale,
                                Real start_closest = std::numeric_limits<Real>::quiet_NaN());

/// gjkDistance, then decideConvexCores.
CollideOutput collideConvexCores(const ConvexCore& a, const ConvexCore& b,
                                 const RelativePose& b_in_a, Real tolerance, Real scale);

}  // namespace collision
