// collision/ccd/ccd.h -- continuous collision detection queries over one step of linear motion:
// sphere-sphere time of impact, and vertex-face / edge-edge CCD for moving triangle meshes.
// The engine's CCD policy calls these; every query returns never a time later than first contact.
#pragma once

#include <array>
#include <limits>

#include "collision/math.h"

namespace collision {

/// Outcome of a CCD query.
/// - Hit: contact (or, for the conservative primitive queries, a contact within the stated
///   tolerance) at or after `t`; `t` is never later than the true first contact.
/// - Separated: no contact during the step.
/// - Overlapped: spheres already interpenetrating at t = 0 (primitive queries never return it:
///   a point and a triangle have no volume; touching at t = 0 is a Hit at t = 0).
/// - Failed: the query gave up (iteration cap, non-finite input); `t` is still a safe time to
///   advance to (no contact before it), and the caller must treat the pair as colliding.
enum class CcdState { Separated, Hit, Overlapped, Failed };

/// Result of every CCD query. Times are fractions of the step, in [0, 1].
struct CcdOutput {
    CcdState state = CcdState::Failed;
    /// Hit: first contact time (conservative: <= true first contact). Failed: safe time.
    Real t = 0.0;
    /// Hit from the conservative queries: the contact lies in [t, t_upper]. Otherwise == t.
    Real t_upper = 0.0;
    /// Witness parameters at the hit. Vertex-face: barycentric weights of face vertices 1 and 2
    /// (the contact point is (1-u-v) f0 + u f1 + v f2). Edge-edge: u along edge a, v along
    /// edge b. Conservative queries give the centre of the accepted parameter box.
    Real u = 0.0;
    Real v = 0.0;
    /// Spheres, Hit: unit contact normal from A towards B at time t (world frame).
    Vec3 normal = Vec3::Zero();
    /// Work done: parameter boxes examined (conservative) or cubic roots tested (naive).
    int iterations = 0;
};

/// Time of impact of two spheres moving linearly over the step: centre of A from `c0a` (t = 0)
/// to `c1a` (t = 1), radius `ra`; likewise B. Solves |d0 + t*dv| = ra + rb with d0 = c0b - c0a,
/// dv the relative displacement, in the cancellation-free form q = -(b' + sign(b') sqrt(D')),
/// roots c/q and q/a (Numerical Recipes 3rd ed. §5.6; Goldberg 1991), exact to rounding of
/// the relative quantities, so a 1e6 offset of both spheres does not change the answer.
/// Conventions: centre distance < ra + rb at t = 0 -> Overlapped (t = 0). Exactly touching at
/// t = 0 -> Hit at t = 0 if approaching, Separated otherwise. Grazing (distance reaches R only
/// at one instant, D' = 0) -> Hit. Zero relative motion -> Separated (or Overlapped).
/// Radii must be >= 0; non-finite input -> Failed. O(1).
CcdOutput timeOfImpactSpheres(const Vec3& c0a, const Vec3& c1a, Real ra, const Vec3& c0b,
                              const Vec3& c1b, Real rb);

/// A vertex and a triangle moving linearly: index 0 the vertex, 1..3 the face's vertices,
/// `t0` positions at the start of the step and `t1` at the end (the CSV row order of the
/// Wang et al. 2021 sample queries).
struct VertexFaceCcdInput {
    std::array<Vec3, 4> t0;
    std::array<Vec3, 4> t1;
};

/// Two edges moving linearly: indices 0, 1 the endpoints of edge a, 2, 3 those of edge b.
struct EdgeEdgeCcdInput {
    std::array<Vec3, 4> t0;
    std::array<Vec3, 4> t1;
};

/// Parameters of the conservative (inclusion-based) queries.
struct CcdSettings {
    /// Report contact when the primitives come within this max-norm (L-infinity) distance, in
    /// scene units. 0: actual contact. Conservative for a Euclidean gap too (L-inf <= L2).
    Real min_separation = 0.0;
    /// Acceptance width, relative to the query's size (largest extent of the bounding box of
    /// its 8 points): a parameter box whose image is this narrow on every axis and still
    /// touches the origin is reported as a Hit. False positives are therefore confined to
    /// near misses closer than about tolerance * size (+ min_separation). Never below the
    /// floating-point error bound of the inclusion function.
    Real tolerance = 1e-6;
    /// With min_separation > 0 a Hit may be closed by bracketing: the first contact is proven
    /// to lie in [t, t_upper] with t_upper - t <= time_tolerance (fraction of the step).
    Real time_tolerance = 1e-6;
    /// Cap on parameter boxes examined; reaching it returns Failed with a safe t.
    int max_boxes = 1'000'000;
};

/// Conservative vertex-face CCD: never misses a contact of the exact (double) input, and the
/// returned t is never later than the first contact. Method: Tight-Inclusion-style interval
/// subdivision of (t, u, v) with a rigorous floating-point error bound (Wang, Ferguson,
/// Schneider, Jiang, Attene, Panozzo, "A Large-scale Benchmark and an Inclusion-based
/// Algorithm for Continuous Collision Detection", ACM TOG 2021); see ccd/inclusion.cpp for why
/// this method and the guarantee. Cost: one box for most queries, up to a few hundred on the
/// sample queries' spikes and cracks (a box is excluded by projections of F on the axes, the
/// primitives' plane normal and the mean corner value); bounded by `max_boxes`.
CcdOutput vertexFaceCcd(const VertexFaceCcdInput& input, const CcdSettings& settings = {});

/// Conservative edge-edge CCD; same method and guarantee as vertexFaceCcd.
CcdOutput edgeEdgeCcd(const EdgeEdgeCcdInput& input, const CcdSettings& settings = {});

/// Naive floating-point baseline: roots in [0, 1] of the coplanarity cubic solved in double
/// (Cardano / trigonometric form, no error bounds), then an exact-zero-tolerance inside test
/// at each root. Misses contacts (false negatives) on degenerate and near-degenerate motion;
/// kept only to show why the conservative method matters. Never NaN, never loops.
CcdOutput vertexFaceCcdNaive(const VertexFaceCcdInput& input);

/// Naive floating-point edge-edge baseline; see vertexFaceCcdNaive.
CcdOutput edgeEdgeCcdNaive(const EdgeEdgeCcdInput& input);

// ---- Rigid convex bodies with rotation: conservative advancement (ccd/advancement.cpp). ----

struct Shape;

/// Motion of a body over one step, t in [0, 1]: its local origin moves linearly by
/// `translation`; the body turns at constant rate about the fixed world axis of `rotation` and,
/// at the same time, about the body-fixed axis of `spin` (both rotation vectors: unit axis *
/// angle in rad, any angle, through the local origin). Pose at t:
/// position = start.position + t translation, orientation = R(t rotation) start.q R(t spin).
/// (A torque-free symmetric body moves exactly so: precession about L, spin about its axis.)
struct Sweep {
    Pose start;
    Vec3 translation = Vec3::Zero();  ///< m, world frame, over the whole step
    Vec3 rotation = Vec3::Zero();     ///< rad, world frame, over the whole step
    Vec3 spin = Vec3::Zero();         ///< rad, body (local) frame, over the whole step

    /// The pose at step fraction `t` (any real t; [0, 1] is the step).
    Pose at(Real t) const;
};

/// Default acceptance tolerance of timeOfImpact, relative to the smaller shape's bounding radius.
inline constexpr Real kToiRelativeTolerance = Real(1e-3);

/// What a time-of-impact query asks, whatever the shapes: the motions and the acceptance.
struct ToiQuery {
    Sweep sweep_a;
    Sweep sweep_b;
    Real t_max = 1;       ///< search [0, t_max] of the step, t_max in [0, 1]
    Real target_gap = 0;  ///< m, >= 0: report the time the gap first closes to this distance
    /// m, >= 0: a Hit is accepted once the gap is within target_gap + tolerance. 0 picks
    /// relative_tolerance times the smaller bounding radius of the two shapes.
    Real tolerance = 0;
    /// Dimensionless, >= 0: the tolerance when `tolerance` is 0, as a fraction of the smaller
    /// bounding radius of the two shapes. Every advance is conservative whatever its value, so a
    /// looser tolerance stops at an earlier iterate of the same sequence (never later than the
    /// tighter one, never later than first contact) after fewer iterations; the pair is then
    /// left up to target_gap + tolerance apart. 0: the gap must reach target_gap itself,
    /// which the advancement approaches only step by step unless the motion is a pure
    /// translation (then Failed at the iteration cap).
    Real relative_tolerance = kToiRelativeTolerance;
    int max_iterations = 64;  ///< cap on distance queries (per triangle pair for meshes)
    /// m per unit t, >= 0: a bound on how fast any point of shape A (B) moves relative to its
    /// body frame (a deforming body; 0 for a rigid one). The shapes given are those at t = 0;
    /// at t every point of the moving shape lies within deform_speed * t of its point on the
    /// given one. Honoured by timeOfImpact; timeOfImpactMeshes and the sphere entries assume
    /// rigid shapes.
    Real deform_speed_a = 0;
    Real deform_speed_b = 0;
};

/// Input of timeOfImpact.
struct ToiInput : ToiQuery {
    const Shape* a = nullptr;  ///< convex shapes (a Mesh stands for its convex hull: conservative)
    const Shape* b = nullptr;
};

/// Result of the rigid-body time-of-impact queries, world frame.
struct ToiOutput {
    /// Hit: the gap reaches target_gap (+ tolerance) at `t`, never after the true time the gap
    /// first closes to target_gap. Separated: the gap stays above target_gap on [0, t_max].
    /// Overlapped: penetrating at t = 0 (t = 0). Failed: iteration cap or bad input; the gap
    /// stays above target_gap on [0, t] (a safe time), the caller must treat the pair as hit.
    CcdState state = CcdState::Failed;
    Real t = 0;         ///< fraction of the step
    Real distance = 0;  ///< lower bound on the gap at t (m); 0 when Overlapped or Failed early
    Vec3 normal = Vec3::Zero();  ///< unit, from A towards B at t (Hit, Failed after 1 query)
    /// Witnesses at t, world: the support point of one shape along the normal and the point of
    /// the other shape closest to it (exact closest points for sphere/box/capsule vertex or
    /// round contacts; for face-face contact one corner of the contact region).
    Vec3 point_a = Vec3::Zero();
    Vec3 point_b = Vec3::Zero();
    int iterations = 0;  ///< distance queries made
};

/// Conservative advancement (Mirtich 1996, "Impulse-based dynamic simulation of rigid body
/// systems", PhD thesis, UC Berkeley; directional motion bound as in Zhang, Lee, Kim,
/// "Interactive continuous collision detection for non-convex polyhedra", Vis. Comput. 2006):
/// at the current t, GJK gives a direction n; the gap along n (a rigorous lower bound on the
/// distance, from the support functions) cannot shrink faster than
/// mu = (dA - dB).n + |rotA x n| rA + |rotB x n| rB + |spinA| sA + |spinB| sB per unit t
/// (r = bounding radius about the local origin, s = largest distance from the spin axis), so
/// t advances by (gap - target_gap) / mu, which never passes the first time
/// the gap reaches target_gap. A deforming shape (deform_speed D > 0) adds
/// D (1 + |rot| + |spin|) to mu and its displacement D t is taken off the gap measured on the
/// t = 0 shape, so the bound holds for the moving surface too. Guarantee: conservative (never
/// later than first contact), up to
/// floating-point rounding of the gap (relative, positions are subtracted first). Cost: one
/// GJK per iteration; pure translation converges in 1-2 iterations, fast rotation near
/// grazing contact may need many: capped by max_iterations -> Failed with a safe t.
ToiOutput timeOfImpact(const ToiInput& input);

/// Exact time of impact of two spheres (input.a, input.b both ShapeType::Sphere, centred at
/// their local origins) under the sweeps' motion: a sphere's geometry ignores its rotation and
/// its centre moves linearly (Sweep::at), so the gap is |d0 + t dv| - ra - rb exactly and
/// timeOfImpactSpheres solves |d0 + t dv| = ra + rb + target_gap in closed form (one
/// quadratic, iterations = 1). Guarantee: exact up to the rounding of the relative quantities,
/// and never after the first contact: the root is moved earlier by a few ulps of the step
/// (kSphereToiSlack), which covers the quadratic's own rounding, and any target_gap > 0 keeps
/// the pair that far apart. tolerance/relative_tolerance are not needed and ignored.
/// Failure mode: only on non-finite input or non-sphere shapes -> Failed at t = 0 (safe).
/// Already within target_gap at t = 0 but not overlapping -> Hit at t = 0 with the present gap
/// in `distance` (as timeOfImpact reports it); overlapping -> Overlapped.
ToiOutput timeOfImpactSphereSweeps(const ToiInput& input);

/// The amount (fraction of the step) by which timeOfImpactSphereSweeps moves its root earlier.
inline constexpr Real kSphereToiSlack = Real(64) * std::numeric_limits<Real>::epsilon();

// ---- Continuous OBB test with interval arithmetic (ccd/obb.cpp). ----

struct Obb;

/// Can two moving OBBs overlap at some time of [t0, t1] (fractions of the step)? `box_a` is an
/// OBB in the local frame of a body moving by `sweep_a` (so its world box at t is the local box
/// placed at sweep_a.at(t)); likewise B. Redon, Kheddar, Coquillart, "Fast continuous collision
/// detection between rigid bodies", Eurographics 2002: the 15 separating-axis inequalities of
/// RTCD 4.4.1 evaluated in interval arithmetic over the time interval (sin/cos of the turning
/// angles enclosed on their interval). Guarantee: conservative -- false only when the boxes are
/// proven separated for every t in [t0, t1] (with a relative slack of 1e-9 of the pair's size
/// for the rounding of the non-directed interval operations); true may be a false alarm, more
/// often on long intervals (callers bisect). O(1). Non-finite input or t0 > t1 -> true.
bool testObbSweep(const Obb& box_a, const Sweep& sweep_a, const Obb& box_b, const Sweep& sweep_b,
                  Real t0, Real t1);

// ---- Meshes: conservative advancement on triangle pairs, culled by the continuous OBB test
// (ccd/mesh.cpp). ----

template <class BV>
class Bvh;

/// Input of timeOfImpactMeshes: two OBB trees (Gottschalk's OBBTree, bvh.h) in their meshes'
/// local frames, each moving by its sweep.
struct MeshToiInput : ToiQuery {
    const Bvh<Obb>* a = nullptr;
    const Bvh<Obb>* b = nullptr;
};

/// Result of timeOfImpactMeshes, with its witness features and cost counters.
struct MeshToiOutput {
    ToiOutput toi;                 ///< the earliest triangle-pair result (state, t, normal, points)
    std::int32_t triangle_a = -1;  ///< witness: mesh index of A's triangle (Hit, Overlapped)
    std::int32_t triangle_b = -1;  ///< witness: mesh index of B's triangle
    std::int64_t node_tests = 0;   ///< continuous OBB tests (testObbSweep)
    std::int64_t triangle_queries = 0;  ///< conservative advancements on triangle pairs
};

/// Time of impact of two moving triangle meshes (surfaces): the tandem traversal of the two OBB
/// trees drops every node pair that the continuous OBB test (Redon et al. 2002, testObbSweep)
/// proves apart on [0, t_best], t_best the earliest time found so far, and runs conservative
/// advancement (timeOfImpact) on each surviving triangle pair, each triangle a flat convex set.
/// Guarantee: conservative, as timeOfImpact: never later than the first time any triangle pair
/// comes within target_gap (the culling is conservative, every triangle pair's advancement is).
/// Separated: no pair comes within target_gap on [0, t_max] (t = t_max). Overlapped: some
/// triangle pair penetrates at t = 0. Failed: a triangle pair hit its iteration cap; t is still
/// safe. Unlike timeOfImpact on the meshes' convex hulls, a body passing through a hole of the
/// other is not stopped. Null trees -> Failed.
MeshToiOutput timeOfImpactMeshes(const MeshToiInput& input);

}  // namespace collision
