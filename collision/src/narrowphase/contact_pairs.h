// collision/src/narrowphase/contact_pairs.h -- the pieces of contact() (contact.h), private to
// collision: its tolerances, the witness features, and one routine per pair family, each in its
// own file and each computing in the canonically-first shape's frame. Every routine returns the
// pair's state as collide() decides it (collide_pairs.h) beside the details it writes, so the two
// queries agree by construction. contact.cpp dispatches to them through a [ShapeType][ShapeType]
// table.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#if defined(__SSE2__) && !defined(CDLAB_USE_FLOAT)
#include <emmintrin.h>
#endif

#include "collision/narrowphase/contact.h"
#include "narrowphase/collide_pairs.h"
#include "narrowphase/gjk.h"

namespace collision::contact_pairs {

// Below kNormalRelative * scale a GJK distance is too small for (pb - pa) / d to be a reliable
// direction (its rounding error is ~ kEpsilon * scale / d radians): EPA decides the normal.
inline constexpr Real kNormalRelative = std::max(Real(1e-8), Real(1e3) * kEpsilon);
// A direction shorter than kDirectionRelative * scale is undefined (coincident centres etc.).
inline constexpr Real kDirectionRelative = Real(16) * kEpsilon;
// Witness points within kFeatureRelative * scale of a face plane / edge / vertex lie on it.
inline constexpr Real kFeatureRelative = std::max(Real(1e-9), Real(64) * kEpsilon);
// Capsule axes closer to parallel than sin = kParallelSin have no common perpendicular to use.
inline constexpr Real kParallelSin = Real(1e-6);
// Box SAT (measureBoxSat, box_sat.h): an edge axis must beat the best face axis by
// kEdgeBias * scale to be chosen (faces give stable multi-point manifolds; Box2D / Bullet do the
// same).
inline constexpr Real kEdgeBias = std::max(Real(1e-9), Real(64) * kEpsilon);

// -1 below zero, else +1 (-0 and NaN included). A mask, not a select: the sign is data the branch
// predictor cannot learn, and GCC compiles the select (and 1 - 2 (x < 0)) to a branch.
inline Real signOrPlus(Real x) {
#if defined(__SSE2__) && !defined(CDLAB_USE_FLOAT)
    const __m128d below = _mm_cmplt_sd(_mm_set_sd(x), _mm_setzero_pd());
    return _mm_cvtsd_f64(_mm_add_sd(_mm_set_sd(1.0), _mm_and_pd(below, _mm_set_sd(-2.0))));
#else
    return x < 0 ? Real(-1) : Real(1);
#endif
}

using Ctx = PairContext;

// The contact in A's frame (canonical order); world transform and mirroring happen once.
using Local = ContactOutput;

// ---- Witness features (numbering in contact.h; boxFeature here, the rest in
// contact_features.cpp). ----

// Counted and chosen by selects, not branches: which of the three slabs a witness point lies on
// is data that the branch predictor cannot learn. The same answer as testing the axes in turn:
// the vertex, the edge along the one free axis, the face of the one axis on its plane. Inline,
// since box-box contact() calls it twice per query.
inline Feature boxFeature(const Vec3& half, const Vec3& p, Real tol) {
    const int on0 = static_cast<int>(std::abs(p.x()) >= half.x() - tol);
    const int on1 = static_cast<int>(std::abs(p.y()) >= half.y() - tol);
    const int on2 = static_cast<int>(std::abs(p.z()) >= half.z() - tol);
    const int b0 = static_cast<int>(p.x() > 0);
    const int b1 = static_cast<int>(p.y() > 0);
    const int b2 = static_cast<int>(p.z() > 0);
    const int count = on0 + on1 + on2;
    const int vertex = b0 + 2 * b1 + 4 * b2;
    // The edge along the free axis k: 4k + the sign bits of the other two axes in order.
    const int edge = on2 == 0 ? 8 + b0 + 2 * b1 : on1 == 0 ? 4 + b0 + 2 * b2 : b1 + 2 * b2;
    const int face = on2 != 0 ? 4 + b2 : on1 != 0 ? 2 + b1 : b0;
    constexpr std::array<FeatureType, 4> kTypes{FeatureType::Unknown, FeatureType::Face,
                                                FeatureType::Edge, FeatureType::Vertex};
    const std::array<std::int32_t, 4> indices{-1, face, edge, vertex};
    return {kTypes[static_cast<std::size_t>(count)], indices[static_cast<std::size_t>(count)]};
}

Feature capsuleFeature(Real half_height, const Vec3& core_point, Real tol);
Feature hullFeature(const ConvexPolytope& hull, const Vec3& p, Real tol);
/// The feature of a convex core (ConvexCore of the shape) that holds `core_point`.
Feature coreFeature(const Shape& shape, const Vec3& core_point, Real tol);

/// A one-point manifold at the witness points (round shapes, edge contacts).
inline void setSingleManifold(Local& out) {
    out.manifold_size = 1;
    out.manifold[0] =
        ManifoldPoint{out.point_a, out.point_b, std::max(Real(0), -out.signed_distance)};
}

/// Boxes and hulls that are not box-box: the manifold of their touching faces, clipped
/// (contact_manifold.cpp). False when the contact is not face to face.
bool polytopeManifold(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                      Local& out);

/// Up to 4 of the n manifold points (indices in `chosen`, returns how many): the deepest and
/// those spanning the largest area (contact_box_box.cpp).
int reduceManifold(const Vec3* p, const Real* depth, int n, const Vec3& normal,
                   std::array<int, 4>& chosen);

// ---- The pair routines, in A's frame (canonical order). Each writes the details to `out`
// (state Failed when it cannot) and returns collide()'s decision on the pair. ----

/// Closed forms (RTCD 5.1): sphere-sphere, sphere-capsule, capsule-capsule (inline, in
/// contact_round.h), sphere-box (contact_round.cpp).
CollideOutput sphereBox(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                        Local& out);
/// Box-box: the box SAT measure, with the manifold by clipping where the best axis is within the
/// tolerance, GJK otherwise (contact_box_box.cpp).
CollideOutput boxBox(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                     Local& out);
/// boxBox, also naming the manifold entry whose points the witness points are a copy of
/// (`witness_entry`, -1 when none is), so that the world transform can copy them too.
CollideOutput boxBoxWitness(const Shape& a, const Shape& b, const RelativePose& rel,
                            const Ctx& ctx, Local& out, int& witness_entry);
/// Any convex pair: GJK with witnesses, EPA when the cores overlap (contact_convex.cpp).
CollideOutput convexConvex(const Shape& a, const Shape& b, const RelativePose& rel,
                           const Ctx& ctx, Local& out);

}  // namespace collision::contact_pairs
