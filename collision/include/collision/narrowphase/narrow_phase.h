// collision/narrowphase/narrow_phase.h -- confirms or rejects a candidate pair: do the two shapes
// touch? Dispatch is a [ShapeType][ShapeType] table of free functions, each pair written once with
// a swapped flag; GJK covers every convex pair and closed forms override it where they exist.
#pragma once

#include <cstdint>
#include <vector>

#include "collision/bvh/bvh.h"
#include "collision/geometry/shape.h"
#include "collision/math.h"

namespace collision {

enum class ContactState : std::uint8_t { Separated, Touching, Penetrating, Failed };

/// Result of a boolean-plus query. `distance` is >= 0 when Separated (exact for closed forms,
/// GJK-accurate otherwise; for meshes only an upper bound is not computed and distance is 0).
struct CollideOutput {
    ContactState state = ContactState::Failed;
    Real distance = 0;                ///< separation when Separated, else 0
    std::int32_t triangle_tests = 0;  ///< triangle-level tests made (meshes)
    std::int64_t bv_tests = 0;        ///< hierarchy node tests made (meshes with a MeshBvh)
    std::int32_t iterations = 0;      ///< GJK iterations, when GJK ran
};

/// Touching convention, everywhere the same: two shapes whose distance is at most
/// `kTouchRelativeTolerance * scale` (scale = the larger bounding radius of the two) are Touching;
/// closer than that and interpenetrating, Penetrating. Both count as "colliding".
inline constexpr Real kTouchRelativeTolerance = Real(64) * kEpsilon;

/// Tests whether `a` at `pose_a` and `b` at `pose_b` touch or overlap. Never hangs (iteration
/// caps, Failed state), never returns NaN. Symmetric: collide(a,b) and collide(b,a) agree.
/// Meshes are surfaces: a mesh collides with another shape when a triangle touches it.
CollideOutput collide(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b);

/// The triangles of `mesh` (a Mesh shape at `pose_mesh`) that collide()'s own per-triangle test
/// finds touching or penetrating the convex shape `convex`: mesh indices, sorted. Same culling,
/// tolerance and test as collide(mesh, convex), which stops at the first penetrating triangle;
/// this visits them all, so collide() is Touching or Penetrating exactly when this is non-empty
/// (a Failed triangle is in neither). Empty when `mesh` is not a mesh, `convex` is not convex
/// or an input is not finite.
std::vector<std::int32_t> collidingTriangles(const Shape& mesh, const Pose& pose_mesh,
                                             const Shape& convex, const Pose& pose_convex);

/// Every triangle pair (a, b) of two Mesh shapes that touches or crosses, mesh indices, sorted,
/// no duplicates: the pairs the narrow phase's tandem traversal (or, without hierarchies of one
/// volume type, the brute-force loop) finds, under the relative pose of B in A's frame. collide()
/// may run the pair in B's frame (canonical order), so near touching the lists can differ by
/// rounding. Empty when either is not a mesh or an input is not finite.
std::vector<TrianglePair> collidingTrianglePairs(const Shape& a, const Pose& pose_a, const Shape& b,
                                                 const Pose& pose_b);

inline bool isColliding(ContactState s) {
    return s == ContactState::Touching || s == ContactState::Penetrating;
}

}  // namespace collision
