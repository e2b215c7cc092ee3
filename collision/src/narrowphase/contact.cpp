// collision/src/narrowphase/contact.cpp -- contact(): the full convex query (depth or distance,
// normal, witness points and features, manifold), dispatched through a [ShapeType][ShapeType]
// table to one routine per pair family (contact_pairs.h): closed forms for the round pairs and
// sphere-box (contact_round.cpp), SAT with a clipped manifold for box-box (contact_box_box.cpp),
// GJK with witnesses and EPA for every other convex pair (contact_convex.cpp).
// Invariants: every routine computes in the canonically-first shape's frame and the world output
// is made once at the end; contact(b, a) runs the same routine on the same arguments as
// contact(a, b) and mirrors it, so the two are exact mirrors; the state is the touching
// convention of narrow_phase.h, and near its thresholds (|signed distance| within
// kReconcileBand * scale of the touching band) the state is taken from collide() itself, so the
// two can never disagree by rounding (the signed distance is then moved into the state's range,
// a change below kReconcileBand * scale).
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
using contact_pairs::kReconcileBand;
using contact_pairs::boxBox;
using contact_pairs::convexConvex;
using contact_pairs::sphereSphere;
using contact_pairs::sphereBox;
using contact_pairs::sphereCapsule;
using contact_pairs::capsuleCapsule;
using contact_pairs::polytopeManifold;
using contact_pairs::setSingleManifold;

namespace {

using ContactFn = void (*)(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                           Local& out);

// Box-box by the SAT, or by GJK when the SAT proves a gap larger than the tolerance.
void boxBoxOrConvex(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx,
                    Local& out) {
    if (!boxBox(a, b, rel, ctx, out)) {
        out = Local{};
        convexConvex(a, b, rel, ctx, out);
    }
}

// Rows: the canonically-first shape's type (canonicalLess orders by type, so the first type is
// never above the second; a mesh is its convex hull here). GJK and EPA wherever no closed form
// exists.
constexpr PairTable<ContactFn> makeContactTable() {
    PairTable<ContactFn> table = filledPairTable<ContactFn>(convexConvex);
    pairEntry(table, ShapeType::Sphere, ShapeType::Sphere) = sphereSphere;
    pairEntry(table, ShapeType::Sphere, ShapeType::Box) = sphereBox;
    pairEntry(table, ShapeType::Sphere, ShapeType::Capsule) = sphereCapsule;
    pairEntry(table, ShapeType::Capsule, ShapeType::Capsule) = capsuleCapsule;
    pairEntry(table, ShapeType::Box, ShapeType::Box) = boxBoxOrConvex;
    return table;
}

constexpr PairTable<ContactFn> kContactTable = makeContactTable();

Local contactLocal(const Shape& a, const Shape& b, const RelativePose& rel, const Ctx& ctx) {
    Local out;
    out.state = ContactState::Touching;  // classified later unless Failed
    pairEntry(kContactTable, a.type, b.type)(a, b, rel, ctx, out);
    return out;
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

    Ctx ctx;
    ctx.scale = std::max(boundingRadius(first), boundingRadius(second));
    ctx.tolerance = kTouchRelativeTolerance * ctx.scale;
    const RelativePose rel = relativePose(pose_first, pose_second);
    Local local = contactLocal(first, second, rel, ctx);

    // The touching convention; near its thresholds collide() decides (see the file header).
    const bool convex = a_in.isConvex() && b_in.isConvex();
    if (local.state != ContactState::Failed) {
        local.state = classifySignedDistance(local.signed_distance, ctx.tolerance).state;
    }
    const Real band = kReconcileBand * ctx.scale;
    if (convex && (local.state == ContactState::Failed ||
                   std::abs(local.signed_distance) <= ctx.tolerance + band)) {
        const CollideOutput c = collide(first, pose_first, second, pose_second);
        if (local.state != ContactState::Failed) {
            switch (c.state) {
                case ContactState::Separated:
                    local.signed_distance = std::max(local.signed_distance, c.distance);
                    break;
                case ContactState::Touching:
                    local.signed_distance =
                        std::clamp(local.signed_distance, -ctx.tolerance, ctx.tolerance);
                    break;
                case ContactState::Penetrating:
                    if (!(local.signed_distance < -ctx.tolerance)) {
                        local.signed_distance =
                            std::nextafter(-ctx.tolerance, -std::numeric_limits<Real>::infinity());
                    }
                    break;
                case ContactState::Failed:
                    break;
            }
            local.state = c.state;
        }
    }
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
