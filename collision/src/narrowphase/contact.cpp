// collision/src/narrowphase/contact.cpp -- contact(): the full convex query (depth or distance,
// normal, witness points and features, manifold), dispatched through a [ShapeType][ShapeType]
// table to one routine per pair family (contact_pairs.h): closed forms for the round pairs
// (contact_round.h, called directly so that they inline) and sphere-box (contact_round.cpp), the
// box SAT with a clipped manifold for box-box (contact_box_box.cpp), GJK with witnesses and EPA
// for every other convex pair (contact_convex.cpp).
// Invariants: every routine computes in the canonically-first shape's frame and the world output
// is made once at the end; contact(b, a) runs the same routine on the same arguments as
// contact(a, b) and mirrors it, so the two are exact mirrors. The state is collide()'s: each
// routine returns collide()'s decision on the pair (the same closed form, or the same decision
// on the same GJK run and box SAT measure), and the signed distance is settled into that state's
// range (settleSignedDistance), so the two queries agree by construction.
#include "collision/narrowphase/contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#if defined(__SSE2__) && !defined(CDLAB_USE_FLOAT)
#include <emmintrin.h>
#endif

#include "geometry/shape_measures.h"
#include "narrowphase/contact_pairs.h"
#include "narrowphase/contact_round.h"
#include "narrowphase/pair_table.h"

namespace collision {

using contact_pairs::Ctx;
using contact_pairs::Local;
using contact_pairs::boxBox;
using contact_pairs::boxBoxWitness;
using contact_pairs::convexConvex;
using contact_pairs::sphereSphere;
using contact_pairs::sphereBox;
using contact_pairs::sphereCapsule;
using contact_pairs::capsuleCapsule;
using contact_pairs::polytopeManifold;
using contact_pairs::setSingleManifold;

namespace {

using ContactFn = CollideOutput (*)(const Shape& a, const Shape& b, const RelativePose& rel,
                                    const Ctx& ctx, Local& out);

// Rows: the canonically-first shape's type (canonicalLess orders by type, so the first type is
// never above the second; a mesh is its convex hull here). GJK and EPA wherever no closed form
// exists.
constexpr PairTable<ContactFn> makeContactTable() {
    PairTable<ContactFn> table = filledPairTable<ContactFn>(convexConvex);
    pairEntry(table, ShapeType::Sphere, ShapeType::Sphere) = sphereSphere;
    pairEntry(table, ShapeType::Sphere, ShapeType::Box) = sphereBox;
    pairEntry(table, ShapeType::Sphere, ShapeType::Capsule) = sphereCapsule;
    pairEntry(table, ShapeType::Capsule, ShapeType::Capsule) = capsuleCapsule;
    pairEntry(table, ShapeType::Box, ShapeType::Box) = boxBox;
    return table;
}

constexpr PairTable<ContactFn> kContactTable = makeContactTable();

// The details' signed distance moved into the range of collide()'s state: never below collide()'s
// distance when Separated, within the tolerance when Touching, below it when Penetrating. The
// routines compute both from the same numbers, so the move is a rounding-sized one wherever the
// details' own estimate is accurate (a GJK gap against EPA on the pair shifted into contact,
// say).
void settleSignedDistance(const CollideOutput& decided, Real tolerance, Local& local) {
    switch (decided.state) {
        case ContactState::Separated:
            local.signed_distance = std::max(local.signed_distance, decided.distance);
            break;
        case ContactState::Touching:
            local.signed_distance = std::clamp(local.signed_distance, -tolerance, tolerance);
            break;
        case ContactState::Penetrating:
            if (!(local.signed_distance < -tolerance)) {
                local.signed_distance =
                    std::nextafter(-tolerance, -std::numeric_limits<Real>::infinity());
            }
            break;
        case ContactState::Failed:
            break;
    }
    local.state = decided.state;
}

// pose.apply(p) and pose.apply(q) with the same operations in the same order (Eigen's
// quaternion transform: uv = 2 (q.vec x v), v + w uv + q.vec x uv, then + position), the two
// points in the two lanes of SSE2 doubles: the same bits as applying the pose to each. Both are
// read before either result is written, so world_p and world_q may be q and p.
void applyPair(const Pose& pose, const Vec3& p, const Vec3& q, Vec3& world_p, Vec3& world_q) {
#if defined(__SSE2__) && !defined(CDLAB_USE_FLOAT)
    const Quat& o = pose.orientation;
    const __m128d qx = _mm_set1_pd(o.x());
    const __m128d qy = _mm_set1_pd(o.y());
    const __m128d qz = _mm_set1_pd(o.z());
    const __m128d qw = _mm_set1_pd(o.w());
    const __m128d vx = _mm_set_pd(q.x(), p.x());
    const __m128d vy = _mm_set_pd(q.y(), p.y());
    const __m128d vz = _mm_set_pd(q.z(), p.z());
    __m128d ux = _mm_sub_pd(_mm_mul_pd(qy, vz), _mm_mul_pd(qz, vy));
    __m128d uy = _mm_sub_pd(_mm_mul_pd(qz, vx), _mm_mul_pd(qx, vz));
    __m128d uz = _mm_sub_pd(_mm_mul_pd(qx, vy), _mm_mul_pd(qy, vx));
    ux = _mm_add_pd(ux, ux);
    uy = _mm_add_pd(uy, uy);
    uz = _mm_add_pd(uz, uz);
    const __m128d cx = _mm_sub_pd(_mm_mul_pd(qy, uz), _mm_mul_pd(qz, uy));
    const __m128d cy = _mm_sub_pd(_mm_mul_pd(qz, ux), _mm_mul_pd(qx, uz));
    const __m128d cz = _mm_sub_pd(_mm_mul_pd(qx, uy), _mm_mul_pd(qy, ux));
    const __m128d rx = _mm_add_pd(_mm_add_pd(_mm_add_pd(vx, _mm_mul_pd(qw, ux)), cx),
                                  _mm_set1_pd(pose.position.x()));
    const __m128d ry = _mm_add_pd(_mm_add_pd(_mm_add_pd(vy, _mm_mul_pd(qw, uy)), cy),
                                  _mm_set1_pd(pose.position.y()));
    const __m128d rz = _mm_add_pd(_mm_add_pd(_mm_add_pd(vz, _mm_mul_pd(qw, uz)), cz),
                                  _mm_set1_pd(pose.position.z()));
    _mm_storeu_pd(world_p.data(), _mm_unpacklo_pd(rx, ry));
    _mm_store_sd(world_p.data() + 2, rz);
    _mm_storeu_pd(world_q.data(), _mm_unpackhi_pd(rx, ry));
    _mm_store_sd(world_q.data() + 2, _mm_unpackhi_pd(rz, rz));
#else
    // p and q are read before either result is written: the results may go to each other's
    // places.
    const Vec3 moved_p = pose.apply(p);
    const Vec3 moved_q = pose.apply(q);
    world_p = moved_p;
    world_q = moved_q;
#endif
}

// The world output, once: the local contact rotated and moved by the canonically-first shape's
// pose (`rot` its rotation matrix), then mirrored if the canonical order swapped A and B. The
// points are moved two at a time (applyPair), each pair written to its mirrored places
// directly; the witness points, when they are a copy of manifold entry `witness_entry` (-1:
// they are not), are copied from its world points, which are the same bits. Which shape is
// first is data the branch predictor cannot learn: the mirroring picks places and signs by
// index, not by a branch.
void toWorld(const Pose& pose_first, const Mat3& rot, bool swap, int witness_entry,
             ContactOutput& out) {
    const auto s = static_cast<std::size_t>(swap);
    const Vec3 normal = rot * out.normal;
    constexpr std::array<Real, 2> kSign{1, -1};
    out.normal = normal * kSign[s];  // exact: a sign flip
    const std::array<Feature, 2> features{out.feature_a, out.feature_b};
    out.feature_a = features[s];
    out.feature_b = features[1 - s];
    const bool copy_witness = witness_entry >= 0 && witness_entry < out.manifold_size;
    if (!copy_witness) {
        const std::array<Vec3*, 2> points{&out.point_a, &out.point_b};
        applyPair(pose_first, *points[0], *points[1], *points[s], *points[1 - s]);
    }
    for (int i = 0; i < out.manifold_size; ++i) {
        ManifoldPoint& m = out.manifold[static_cast<std::size_t>(i)];
        const std::array<Vec3*, 2> points{&m.point_a, &m.point_b};
        applyPair(pose_first, *points[0], *points[1], *points[s], *points[1 - s]);
    }
    if (copy_witness) {
        const ManifoldPoint& m = out.manifold[static_cast<std::size_t>(witness_entry)];
        out.point_a = m.point_a;  // already mirrored
        out.point_b = m.point_b;
    }
}

// contact() of the pair `first`, `second` (canonical order; `swap` when that swapped A and B)
// with `routine`, written straight into the returned output. `witness_entry` is read after the
// routine ran: the manifold entry its witness points are a copy of, or -1.
template <class Routine>
[[gnu::always_inline]] inline ContactOutput contactPair(Routine&& routine, const Shape& first,
                                                        const Pose& pose_first,
                                                        const Shape& second,
                                                        const Pose& pose_second, bool swap,
                                                        const int& witness_entry) {
    ContactOutput out;
    const Ctx ctx = pairContext(first, second);
    const RelativePose rel = relativePose(pose_first, pose_second);
    // Made before the pair routine, which gives its stores time to retire before the world
    // transform reads the matrix back as vectors.
    const Mat3 rot = pose_first.rotation();
    out.state = ContactState::Touching;  // the routine sets Failed when it cannot
    const CollideOutput decided = routine(first, second, rel, ctx, out);
    if (out.state != ContactState::Failed) settleSignedDistance(decided, ctx.tolerance, out);
    // The output never carries NaN or a non-unit normal: anything else is Failed.
    if (out.state == ContactState::Failed || !std::isfinite(out.signed_distance) ||
        !out.normal.allFinite() || !(std::abs(out.normal.squaredNorm() - 1) < Real(1e-6)) ||
        !out.point_a.allFinite() || !out.point_b.allFinite()) {
        const std::int32_t iterations = out.iterations;
        out = ContactOutput{};
        out.iterations = iterations;
        return out;
    }
    if (out.state == ContactState::Separated) {
        out.manifold_size = 0;
    } else if (out.manifold_size == 0) {
        const bool polytopes =
            (first.type == ShapeType::Box || first.type == ShapeType::ConvexHull) &&
            (second.type == ShapeType::Box || second.type == ShapeType::ConvexHull);
        if (!polytopes || !polytopeManifold(first, second, rel, ctx, out)) {
            setSingleManifold(out);
        }
    }
    toWorld(pose_first, rot, swap, witness_entry, out);
    return out;
}

// contact() of two boxes in canonical order. Box-box names the manifold entry its witness points
// repeat, so they are moved once. A function of its own: inside contactConvex, which holds every
// pair's contactPair, GCC's growth limits left the quaternion-to-matrix conversions and the
// finiteness checks as calls.
[[gnu::noinline]] ContactOutput contactBoxes(const Shape& first, const Pose& pose_first,
                                             const Shape& second, const Pose& pose_second,
                                             bool swap) {
    int witness_entry = -1;
    const auto box_box = [&witness_entry](const Shape& box_a, const Shape& box_b,
                                          const RelativePose& rel, const Ctx& ctx, Local& out) {
        return boxBoxWitness(box_a, box_b, rel, ctx, out, witness_entry);
    };
    return contactPair(box_box, first, pose_first, second, pose_second, swap, witness_entry);
}

// contact() of two convex shapes (no meshes). The round closed forms are called directly, so
// they inline and their answer reaches the world transform in registers; every other pair goes
// through the table.
ContactOutput contactConvex(const Shape& a, const Pose& pose_a, const Shape& b,
                            const Pose& pose_b) {
    const bool swap = canonicalLess(b, pose_b, a, pose_a);
    // Picked by index, not a branch: the canonical order is data.
    const auto s = static_cast<std::size_t>(swap);
    const std::array<const Shape*, 2> shapes{&a, &b};
    const std::array<const Pose*, 2> poses{&pose_a, &pose_b};
    const Shape& first = *shapes[s];
    const Shape& second = *shapes[1 - s];
    const Pose& pose_first = *poses[s];
    const Pose& pose_second = *poses[1 - s];
    constexpr int kNoWitnessEntry = -1;
    if (first.type == ShapeType::Sphere && second.type == ShapeType::Sphere) {
        return contactPair(sphereSphere, first, pose_first, second, pose_second, swap,
                           kNoWitnessEntry);
    }
    if (first.type == ShapeType::Sphere && second.type == ShapeType::Capsule) {
        return contactPair(sphereCapsule, first, pose_first, second, pose_second, swap,
                           kNoWitnessEntry);
    }
    if (first.type == ShapeType::Capsule && second.type == ShapeType::Capsule) {
        return contactPair(capsuleCapsule, first, pose_first, second, pose_second, swap,
                           kNoWitnessEntry);
    }
    if (first.type == ShapeType::Box && second.type == ShapeType::Box) {
        return contactBoxes(first, pose_first, second, pose_second, swap);
    }
    return contactPair(pairEntry(kContactTable, first.type, second.type), first, pose_first,
                       second, pose_second, swap, kNoWitnessEntry);
}

// A mesh is its convex hull here.
[[gnu::noinline]] ContactOutput contactMeshHulls(const Shape& a, const Pose& pose_a,
                                                 const Shape& b, const Pose& pose_b) {
    const Shape a_hull = a.type == ShapeType::Mesh ? Shape::convexHull(a.hull) : a;
    const Shape b_hull = b.type == ShapeType::Mesh ? Shape::convexHull(b.hull) : b;
    return contactConvex(a_hull, pose_a, b_hull, pose_b);
}

}  // namespace

ContactOutput contact(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b) {
    if (!isFinite(a, pose_a) || !isFinite(b, pose_b)) return ContactOutput{};
    if (a.type == ShapeType::Mesh || b.type == ShapeType::Mesh) {
        return contactMeshHulls(a, pose_a, b, pose_b);
    }
    return contactConvex(a, pose_a, b, pose_b);
}

}  // namespace collision
