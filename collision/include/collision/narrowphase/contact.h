// collision/narrowphase/contact.h -- the full convex query: state, separation distance or
// penetration depth, unit normal, witness points and witness features, and (for contact
// response) a contact manifold of up to four points. The engine's impulse solver reads the
// manifold; `cdlab query` and the tests read the witnesses. Implemented in
// collision/src/narrowphase/contact.cpp.
#pragma once

#include <array>
#include <cstdint>

#include "collision/geometry/shape.h"
#include "collision/math.h"
#include "collision/narrowphase/narrow_phase.h"

namespace collision {

/// Which part of a shape a witness point lies on. Indices refer to the shape's own numbering:
/// box vertices 0..7 (bit k of the index set = +half_extents[k]), box edges 0..11, box faces
/// 0..5 (2k = -axis k, 2k+1 = +axis k); hull vertices/faces index ConvexPolytope::vertices/faces
/// (hull edges: the index of the face whose edge it is times 3 plus the edge within the face);
/// capsule: Vertex 0/1 = bottom/top cap centre's spherical cap, Edge 0 = the cylinder; sphere:
/// Face 0. `index < 0` when unknown.
enum class FeatureType : std::uint8_t { Vertex, Edge, Face, Unknown };

struct Feature {
    FeatureType type = FeatureType::Unknown;
    std::int32_t index = -1;
};

/// One point of a contact manifold, world frame.
struct ManifoldPoint {
    Vec3 point_a = Vec3::Zero();  ///< on A's surface
    Vec3 point_b = Vec3::Zero();  ///< on B's surface
    Real depth = 0;               ///< >= 0 penetration along the normal (0 when touching)
};

/// Touching convention (the one of collide(), narrow_phase.h, for every pair and every path:
/// closed forms, SAT, GJK, EPA): with tol = kTouchRelativeTolerance * scale, scale the larger
/// bounding radius of the two shapes (sphere: radius; box: |half_extents|; capsule:
/// half_height + radius; hull: farthest vertex from its origin),
///   Separated    iff signed distance >  tol,
///   Touching     iff |signed distance| <= tol  (a gap or an overlap of rounding size),
///   Penetrating  iff signed distance < -tol.
struct ContactOutput {
    ContactState state = ContactState::Failed;
    /// Separated: the distance (> tol). Penetrating: minus the penetration depth (< -tol).
    /// Touching: in [-tol, tol], either sign. Failed: 0.
    Real signed_distance = 0;
    /// Unit, world frame, pointing from A towards B: moving B by -signed_distance * normal
    /// (penetrating) separates the shapes; for separated shapes (point_b - point_a) / distance.
    /// Zero only when Failed.
    Vec3 normal = Vec3::Zero();
    /// Witness points, world frame: the closest points (Separated) or the deepest points of each
    /// shape inside the other along the normal (Touching/Penetrating).
    Vec3 point_a = Vec3::Zero();
    Vec3 point_b = Vec3::Zero();
    Feature feature_a;
    Feature feature_b;
    /// Contact points for response, only when Touching/Penetrating: one for round shapes, up to
    /// four for face contacts (box-box: clipped incident face, RTCD 5.x / Gottschalk SAT axes).
    std::array<ManifoldPoint, 4> manifold{};
    std::int32_t manifold_size = 0;
    std::int32_t iterations = 0;  ///< GJK + EPA iterations, when they ran
};

/// Conventions of the implementation (collision/src/narrowphase/contact.cpp):
/// - Box edge k*4 + s_i + 2*s_j is the edge parallel to axis k whose other two coordinates (axes
///   i < j) are +half_extents where s = 1 and -half_extents where s = 0.
/// - point_b - point_a = signed_distance * normal up to rounding (~1e-9 of the size), in every
///   state; manifold points obey the same with their own depth and lie on the two surfaces.
/// - Undefined directions get a fixed normal in the frame of the canonically first shape
///   (order: sphere < box < capsule < hull, a mesh counting as a hull; same types by pose and
///   dimensions): coincident sphere centres -> that sphere's local +x; a sphere centre on a
///   capsule's axis -> the capsule's local +x; crossing capsule axes -> their common
///   perpendicular towards B's centre (parallel, coaxial: the first capsule's local +x); other
///   pairs -> EPA's deterministic answer. contact(b, a) mirrors it, except for identical inputs
///   (same shape and pose), where both calls are the same call.
/// - Accuracy: closed forms to rounding; GJK distance to kGjkRelativeTolerance (gjk.h) or
///   rounding; EPA depth to 1e-11 * size; box-box SAT exact up to rounding, except that a face
///   axis is preferred over an edge axis less than 1e-9 * size deeper (stable manifolds).
/// - GJK/EPA pairs within 1e-8 * size of touching: the normal comes from EPA on the pair shifted
///   4e-8 * size into contact when that normal is stable under the shift (face contacts), else
///   from GJK's closest points (separated) or EPA (overlapping), whose direction is then only as
///   good as rounding allows (~1e-16 * size / gap radians, worse when GJK stalls).
/// - State: collide()'s, by construction: each pair family decides with collide()'s own routine
///   (the same closed form, or the same decision on the same GJK run and box SAT measure), and
///   the signed distance is then settled into that state's range (when Separated, never below
///   collide()'s distance; a rounding-sized move). For meshes the state is that of their hulls
///   (collide() tests triangles, so the states may differ).
/// Full convex query of `a` at `pose_a` against `b` at `pose_b`. Convex shapes only (a Mesh
/// is treated as its convex hull here; triangle-level mesh contact goes through the BVH).
/// Guarantees: never NaN, never hangs (iteration caps -> Failed); the touching convention above
/// (ContactOutput), and `contact(a, b).state == collide(a, b).state`; swapping A and B mirrors
/// the answer (same state and signed distance, normal negated, points, features and manifold
/// sides swapped).
ContactOutput contact(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b);

}  // namespace collision
