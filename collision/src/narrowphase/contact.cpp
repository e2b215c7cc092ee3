// collision/src/narrowphase/contact.cpp -- contact(): the full convex query (depth or distance,
// normal, witness points and features, manifold), dispatched through a [ShapeType][ShapeType]
// table to one routine per pair family (contact_pairs.h): closed forms for the round pairs and
// sphere-box (contact_round.cpp), the box SAT with a clipped manifold for box-box
// (contact_box_box.cpp), GJK with witnesses and EPA for every other convex pair
// (contact_convex.cpp).
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

#include "geometry/shape_measures.h"
#include "narrowphase/contact_pairs.h"
#include "narrowphase/pair_table.h"

namespace collision {

using contact_pairs::Ctx;
using contact_pairs::Local;
using contact_pairs::boxBox;
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

}  // namespace

ContactOutput contact(const Shape& a_in, const Pose& pose_a_in, const Shape& b_in,
                      const Pose& pose_b_in) {
    ContactOutput failed;
    if (!isFinite(a_in, pose_a_in) || !isFinite(b_in, pose_b_in)) return failed;
    // A mesh is its convex hull here.
    Shape a_hull;
    Shape b_hull;
    const Shape* a = &a_in;
    const Shape* b = &b_in;
    if (a_in.type == ShapeType::Mesh) {
        a_hull = Shape::convexHull(a_in.hull);
        a = &a_hull;
    }
    if (b_in.type == ShapeType::Mesh) {
        b_hull = Shape::convexHull(b_in.hull);
        b = &b_hull;
    }
    const bool swap = canonicalLess(*b, pose_b_in, *a, pose_a_in);
    const Shape& first = swap ? *b : *a;
    const Shape& second = swap ? *a : *b;
    const Pose& pose_first = swap ? pose_b_in : pose_a_in;
    const Pose& pose_second = swap ? pose_a_in : pose_b_in;

    const Ctx ctx = pairContext(first, second);
    const RelativePose rel = relativePose(pose_first, pose_second);
    Local local;
    local.state = ContactState::Touching;  // the routine sets Failed when it cannot
    const CollideOutput decided =
        pairEntry(kContactTable, first.type, second.type)(first, second, rel, ctx, local);
    if (local.state != ContactState::Failed) settleSignedDistance(decided, ctx.tolerance, local);
    // The output never carries NaN or a non-unit normal: anything else is Failed.
    if (local.state == ContactState::Failed || !std::isfinite(local.signed_distance) ||
        !local.normal.allFinite() || !(std::abs(local.normal.squaredNorm() - 1) < Real(1e-6)) ||
        !local.point_a.allFinite() || !local.point_b.allFinite()) {
        failed.iterations = local.iterations;
        return failed;
    }
    if (local.state == ContactState::Separated) {
        local.manifold_size = 0;
    } else if (local.manifold_size == 0) {
        const bool polytopes =
            (first.type == ShapeType::Box || first.type == ShapeType::ConvexHull) &&
            (second.type == ShapeType::Box || second.type == ShapeType::ConvexHull);
        if (!polytopes || !polytopeManifold(first, second, rel, ctx, local)) {
            setSingleManifold(local);
        }
    }

    // To world, once; then mirror if the canonical order swapped A and B.
    ContactOutput out = local;
    const Mat3 rot = pose_first.rotation();
    out.normal = rot * local.normal;
    out.point_a = pose_first.apply(local.point_a);
    out.point_b = pose_first.apply(local.point_b);
    for (int i = 0; i < local.manifold_size; ++i) {
        const auto k = static_cast<std::size_t>(i);
        out.manifold[k].point_a = pose_first.apply(local.manifold[k].point_a);
        out.manifold[k].point_b = pose_first.apply(local.manifold[k].point_b);
    }
    if (swap) {
        out.normal = -out.normal;
        std::swap(out.point_a, out.point_b);
        std::swap(out.feature_a, out.feature_b);
        for (int i = 0; i < out.manifold_size; ++i) {
            auto& m = out.manifold[static_cast<std::size_t>(i)];
            std::swap(m.point_a, m.point_b);
        }
    }
    return out;
}

}  // namespace collision
