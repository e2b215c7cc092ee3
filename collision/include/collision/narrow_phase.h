// collision/narrow_phase.h -- confirms or rejects a candidate pair: do the two shapes touch?
// Dispatch is a [ShapeType][ShapeType] table of free functions, each pair written once with a
// swapped flag; GJK covers every convex pair and closed forms override it where they exist.
#pragma once

#include <cstdint>

#include "collision/math.h"
#include "collision/shape.h"

namespace collision {

enum class ContactState : std::uint8_t { Separated, Touching, Penetrating, Failed };

/// Result of a boolean-plus query. `distance` is >= 0 when Separated (exact for closed forms,
/// GJK-accurate otherwise; for meshes only an upper bound is not computed and distance is 0).
struct CollideOutput {
    ContactState state = ContactState::Failed;
    Real distance = 0;          ///< separation when Separated, else 0
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

inline bool isColliding(ContactState s) {
    return s == ContactState::Touching || s == ContactState::Penetrating;
}

}  // namespace collision
