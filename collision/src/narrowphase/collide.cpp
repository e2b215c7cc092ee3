// collision/src/narrowphase/collide.cpp -- collide(): dispatch through a [ShapeType][ShapeType]
// table of free functions (each pair written once; the swapped flag reorders the arguments), closed
// forms for sphere/box/capsule pairs, GJK (gjk.h) for every other convex pair, and for meshes the
// shape's hierarchy (bvh.h) down to triangle-level tests.
// Invariants: every pair routine computes in the first shape's frame from one RelativePose built
// by subtracting positions first; the touching tolerance is kTouchRelativeTolerance times the
// larger bounding radius of the two shapes, and |signed distance| <= tolerance is Touching in
// every routine; collide(a, b) and collide(b, a) run the same routine on the same arguments
// (pairs of one type are ordered by a canonical key), so they return identical outputs.
#include "collision/narrowphase/narrow_phase.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include "collision/assert.h"
#include "collision/bvh/bvh.h"
#include "geometry/closest_points.h"
#include "geometry/shape_measures.h"
#include "geometry/triangle_triangle.h"
#include "narrowphase/gjk.h"
#include "narrowphase/collide_pairs.h"
#include "narrowphase/pair_table.h"

namespace collision {

namespace collide_pairs {

// Inside the box the depth is the radius plus the distance to the nearest face.
SphereBoxCore sphereBoxCore(const Shape& a, const Shape& b, const RelativePose& b_in_a) {
    SphereBoxCore core;
    const Vec3& h = b.half_extents;
    core.centre = toB(b_in_a, Vec3::Zero());
    core.clamped = core.centre.cwiseMax(-h).cwiseMin(h);
    const Vec3 outside = core.centre - core.clamped;
    core.inside = outside.isZero();
    if (!core.inside) {
        core.signed_distance = outside.norm() - a.radius;
        return core;
    }
    const Vec3 gap = h - core.centre.cwiseAbs();
    gap.minCoeff(&core.face_axis);
    core.signed_distance = -(gap[core.face_axis] + a.radius);
    return core;
}

CollideOutput sphereSphere(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                           const PairContext& ctx) {
    return classifySignedDistance(sphereSphereCores(b_in_a).distance - a.radius - b.radius,
                                  ctx.tolerance);
}

CollideOutput sphereBox(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                        const PairContext& ctx) {
    return classifySignedDistance(sphereBoxCore(a, b, b_in_a).signed_distance, ctx.tolerance);
}

CollideOutput sphereCapsule(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                            const PairContext& ctx) {
    return classifySignedDistance(sphereCapsuleCores(b, b_in_a).distance - a.radius - b.radius,
                                  ctx.tolerance);
}

CollideOutput capsuleCapsule(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                             const PairContext& ctx) {
    return classifySignedDistance(
        capsuleCapsuleCores(a, b, b_in_a, ctx).distance - a.radius - b.radius, ctx.tolerance);
}

// The quick tests decide exactly as the per-axis bounds would: gapHi() <= max_sep + err_bound / 2
// and gapHi() >= max_sep; gapLo() <= max_sep.
std::optional<ContactState> satBoxState(const BoxSatMeasure& sat, Real tolerance) {
    if (sat.max_sep + sat.err_bound < -tolerance) return ContactState::Penetrating;
    if (sat.max_sep > 0) return std::nullopt;
    const Real gap_hi = sat.gapHi();
    if (gap_hi < -tolerance) return ContactState::Penetrating;  // exact depth > tolerance
    if (gap_hi <= 0 && sat.gapLo() >= -tolerance) return ContactState::Touching;
    return std::nullopt;
}

CollideOutput refineBoxState(CollideOutput convex, const BoxSatMeasure& sat, Real tolerance) {
    if (convex.state == ContactState::Separated) {
        // GJK's |v| is accurate to rounding; the axes' gap is a proven lower bound.
        if (sat.max_sep > convex.distance) convex.distance = std::max(convex.distance, sat.gapLo());
    } else if (sat.max_sep > tolerance) {
        const Real gap_lo = sat.gapLo();
        if (gap_lo > tolerance) {
            convex.state = ContactState::Separated;
            convex.distance = gap_lo;
        }
    }
    return convex;
}

}  // namespace collide_pairs

namespace {

using PairFn = CollideOutput (*)(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                                 const PairContext& ctx);

CollideOutput collideConvexGeneric(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                                   const PairContext& ctx) {
    return collideConvexCores(ConvexCore::fromShape(a), ConvexCore::fromShape(b), b_in_a,
                              ctx.tolerance, ctx.scale);
}

// Box-box: the box SAT measure decides where it can (satBoxState), GJK otherwise, refined by the
// axes' proven gap (refineBoxState).
CollideOutput collideBoxBox(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                            const PairContext& ctx) {
    // Clear overlaps (satBoxState's first test) need only the best axes.
    const BoxSatMeasure best =
        measureBoxSatBest(a.half_extents, b_in_a.rotation, b_in_a.position, b.half_extents,
                          -ctx.tolerance);
    if (best.max_sep + best.err_bound < -ctx.tolerance) {
        CollideOutput out;
        out.state = ContactState::Penetrating;
        return out;
    }
    const BoxSatMeasure sat =
        measureBoxSat(a.half_extents, b_in_a.rotation, b_in_a.position, b.half_extents);
    if (const auto state = collide_pairs::satBoxState(sat, ctx.tolerance)) {
        CollideOutput out;
        out.state = *state;
        return out;
    }
    return collide_pairs::refineBoxState(
        collideConvexCores(ConvexCore::fromShape(a), ConvexCore::fromShape(b), b_in_a,
                           ctx.tolerance, ctx.scale),
        sat, ctx.tolerance);
}

// ---- Meshes: surfaces, tested triangle by triangle. ----

struct Box3 {
    Vec3 min = Vec3::Constant(std::numeric_limits<Real>::infinity());
    Vec3 max = Vec3::Constant(-std::numeric_limits<Real>::infinity());
    void add(const Vec3& p) {
        min = min.cwiseMin(p);
        max = max.cwiseMax(p);
    }
    void inflate(Real r) {
        min.array() -= r;
        max.array() += r;
    }
    bool overlaps(const Box3& o) const {
        return (min.array() <= o.max.array()).all() && (o.min.array() <= max.array()).all();
    }
};

Box3 triangleBox(const Vec3& p, const Vec3& q, const Vec3& r) {
    Box3 box;
    box.add(p);
    box.add(q);
    box.add(r);
    return box;
}

// A triangle of the mesh against the convex shape: GJK on the triangle as a 3-point convex set.
// A Penetrating triangle ends the scan; Touching ones do not, so the state (Penetrating over
// Touching) does not depend on triangle order, nor on which triangles the culling lets through
// (culling only drops triangles farther than the tolerance from B).
class MeshConvexScan final : public TriangleVisitor {
public:
    /// With `hits`, every touching or penetrating triangle's mesh index is appended to it and
    /// the scan never stops early (collidingTriangles).
    MeshConvexScan(const ConvexCore& core_b, const RelativePose& b_in_a, const PairContext& ctx,
                   const Box3& box_b, std::vector<std::int32_t>* hits = nullptr)
        : core_b_(core_b), b_in_a_(b_in_a), ctx_(ctx), box_b_(box_b), hits_(hits) {}
    bool visit(std::int32_t id, const std::array<Vec3, 3>& t) override {
        if (!triangleBox(t[0], t[1], t[2]).overlaps(box_b_)) return false;
        ++tests_;
        const CollideOutput res = collideConvexCores(ConvexCore::triangle(t[0], t[1], t[2]),
                                                     core_b_, b_in_a_, ctx_.tolerance, ctx_.scale);
        iterations_ += res.iterations;
        penetrating_ = res.state == ContactState::Penetrating;
        touching_ = touching_ || res.state == ContactState::Touching;
        failed_ = failed_ || res.state == ContactState::Failed;
        if (hits_ != nullptr) {
            if (isColliding(res.state)) hits_->push_back(id);
            return false;
        }
        return penetrating_;
    }
    CollideOutput result() const {
        CollideOutput out;
        out.state = penetrating_ ? ContactState::Penetrating
                    : touching_  ? ContactState::Touching
                    : failed_    ? ContactState::Failed
                                 : ContactState::Separated;
        out.triangle_tests = tests_;
        out.iterations = iterations_;
        return out;
    }

private:
    const ConvexCore& core_b_;
    const RelativePose& b_in_a_;
    const PairContext& ctx_;
    const Box3& box_b_;  // B's grown AABB in A's frame: the last cull before GJK
    std::vector<std::int32_t>* hits_;
    std::int32_t tests_ = 0;
    std::int32_t iterations_ = 0;
    bool penetrating_ = false;
    bool touching_ = false;
    bool failed_ = false;
};

// Mesh against convex. Only triangles whose box overlaps B's exact AABB in A's frame (from B's
// support points along A's axes), grown by B's radius and the touching tolerance, reach GJK.
// With a hierarchy, only the leaves whose node volumes overlap a volume fitted around B's own box
// (support points along B's axes, grown the same way) are looked at; without one (the
// brute-force reference) every triangle is. Both cullings keep every triangle within the
// tolerance of B, so the state is the same.
CollideOutput scanMeshConvex(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                             const PairContext& ctx, std::vector<std::int32_t>* hits) {
    CDLAB_ASSERT(a.mesh, "mesh shape without triangles");
    const TriangleMesh& mesh = *a.mesh;
    const ConvexCore core_b = ConvexCore::fromShape(b);
    const Real grow = core_b.radius + ctx.tolerance;
    Box3 box_b;
    for (int k = 0; k < 3; ++k) {
        const Vec3 axis_in_b = b_in_a.rotation.row(k).transpose();
        const Real hi = b_in_a.position[k] + b_in_a.rotation.row(k).dot(core_b.support(axis_in_b));
        const Real lo = b_in_a.position[k] + b_in_a.rotation.row(k).dot(core_b.support(-axis_in_b));
        box_b.min[k] = lo;
        box_b.max[k] = hi;
    }
    box_b.inflate(grow);
    MeshConvexScan scan(core_b, b_in_a, ctx, box_b, hits);
    if (a.bvh) {
        Vec3 lo;
        Vec3 hi;
        for (int k = 0; k < 3; ++k) {
            hi[k] = core_b.support(Vec3::Unit(k))[k] + grow;
            lo[k] = core_b.support(-Vec3::Unit(k))[k] - grow;
        }
        BvhQueryStats stats;
        a.bvh->visitNearBox(lo, hi, b_in_a.rotation, b_in_a.position, scan, &stats);
        CollideOutput out = scan.result();
        out.bv_tests = stats.bv_tests;
        return out;
    }
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
        const auto& tri = mesh.triangles[i];
        const std::array<Vec3, 3> t{mesh.vertices[static_cast<std::size_t>(tri[0])],
                                    mesh.vertices[static_cast<std::size_t>(tri[1])],
                                    mesh.vertices[static_cast<std::size_t>(tri[2])]};
        if (scan.visit(static_cast<std::int32_t>(i), t)) break;
    }
    return scan.result();
}

CollideOutput collideMeshConvex(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                                const PairContext& ctx) {
    return scanMeshConvex(a, b, b_in_a, ctx, nullptr);
}

// Does triangle (p, q, r) have corners farther than `tolerance` on both sides of the plane of
// (u, v, w)? Two intersecting triangles that each straddle the other's plane cross (Penetrating);
// otherwise they only touch.
bool straddles(const Vec3& p, const Vec3& q, const Vec3& r, const Vec3& u, const Vec3& v,
               const Vec3& w, Real tolerance) {
    const Vec3 n = (v - u).cross(w - u);
    const Real len = n.norm();
    if (!(len > 0)) return false;
    const Vec3 unit = n / len;
    const Real dp = unit.dot(p - u);
    const Real dq = unit.dot(q - u);
    const Real dr = unit.dot(r - u);
    return std::max({dp, dq, dr}) > tolerance && std::min({dp, dq, dr}) < -tolerance;
}

// Intersecting triangle pairs from the tandem traversal: a pair where each triangle straddles the
// other's plane crosses (Penetrating, stop); any other intersecting pair touches. The state does
// not depend on the order the pairs arrive in.
class MeshMeshScan final : public TrianglePairVisitor {
public:
    explicit MeshMeshScan(Real tolerance) : tolerance_(tolerance) {}
    bool visit(std::int32_t, const std::array<Vec3, 3>& ta, std::int32_t,
               const std::array<Vec3, 3>& tb) override {
        if (straddles(ta[0], ta[1], ta[2], tb[0], tb[1], tb[2], tolerance_) &&
            straddles(tb[0], tb[1], tb[2], ta[0], ta[1], ta[2], tolerance_)) {
            penetrating_ = true;
            return true;
        }
        touching_ = true;
        return false;
    }
    ContactState state() const {
        return penetrating_ ? ContactState::Penetrating
               : touching_  ? ContactState::Touching
                            : ContactState::Separated;
    }

private:
    Real tolerance_;
    bool penetrating_ = false;
    bool touching_ = false;
};

// Mesh-mesh. With hierarchies of one volume type: the tandem traversal under the relative pose
// (no mesh is re-transformed; B's corners move to A's frame only at leaf pairs, with the same
// expression as below). Otherwise (the brute-force reference): B's vertices go to A's frame once;
// each mesh's triangles are culled against the other's (tolerance-inflated) AABB, and the
// survivors are tested pairwise with the exact triangle-triangle test. Both give the same state:
// the exact test decides, and both cullings are conservative.
CollideOutput collideMeshMesh(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                              const PairContext& ctx) {
    CDLAB_ASSERT(a.mesh && b.mesh, "mesh shape without triangles");
    if (a.bvh && b.bvh && a.bvh->sameVolumeType(*b.bvh)) {
        MeshMeshScan scan(ctx.tolerance);
        BvhQueryStats stats;
        a.bvh->visitIntersecting(*b.bvh, b_in_a.rotation, b_in_a.position, scan, &stats);
        CollideOutput out;
        out.state = scan.state();
        out.triangle_tests = static_cast<std::int32_t>(
            std::min<std::int64_t>(stats.triangle_tests, std::numeric_limits<std::int32_t>::max()));
        out.bv_tests = stats.bv_tests;
        return out;
    }
    const TriangleMesh& mesh_a = *a.mesh;
    const TriangleMesh& mesh_b = *b.mesh;
    // Scratch reused across calls: no allocation per pair once warm.
    thread_local std::vector<Vec3> vertices_b;
    thread_local std::vector<std::int32_t> survivors_a;
    thread_local std::vector<std::int32_t> survivors_b;
    thread_local std::vector<Box3> boxes_b;
    vertices_b.resize(mesh_b.vertices.size());
    for (std::size_t i = 0; i < mesh_b.vertices.size(); ++i) {
        vertices_b[i] = b_in_a.rotation * mesh_b.vertices[i] + b_in_a.position;
    }
    Box3 box_a;
    for (const Vec3& p : mesh_a.vertices) box_a.add(p);
    Box3 box_b;
    for (const Vec3& p : vertices_b) box_b.add(p);
    box_a.inflate(ctx.tolerance);
    box_b.inflate(ctx.tolerance);

    survivors_a.clear();
    for (std::size_t i = 0; i < mesh_a.triangles.size(); ++i) {
        const auto& tri = mesh_a.triangles[i];
        if (triangleBox(mesh_a.vertices[static_cast<std::size_t>(tri[0])],
                        mesh_a.vertices[static_cast<std::size_t>(tri[1])],
                        mesh_a.vertices[static_cast<std::size_t>(tri[2])])
                .overlaps(box_b)) {
            survivors_a.push_back(static_cast<std::int32_t>(i));
        }
    }
    survivors_b.clear();
    boxes_b.clear();
    for (std::size_t j = 0; j < mesh_b.triangles.size(); ++j) {
        const auto& tri = mesh_b.triangles[j];
        const Box3 box = triangleBox(vertices_b[static_cast<std::size_t>(tri[0])],
                                     vertices_b[static_cast<std::size_t>(tri[1])],
                                     vertices_b[static_cast<std::size_t>(tri[2])]);
        if (box.overlaps(box_a)) {
            survivors_b.push_back(static_cast<std::int32_t>(j));
            boxes_b.push_back(box);
        }
    }

    CollideOutput out;
    out.state = ContactState::Separated;
    bool touching = false;
    for (const std::int32_t i : survivors_a) {
        const auto& ta = mesh_a.triangles[static_cast<std::size_t>(i)];
        const Vec3& p1 = mesh_a.vertices[static_cast<std::size_t>(ta[0])];
        const Vec3& q1 = mesh_a.vertices[static_cast<std::size_t>(ta[1])];
        const Vec3& r1 = mesh_a.vertices[static_cast<std::size_t>(ta[2])];
        Box3 box1 = triangleBox(p1, q1, r1);
        box1.inflate(ctx.tolerance);
        for (std::size_t k = 0; k < survivors_b.size(); ++k) {
            if (!box1.overlaps(boxes_b[k])) continue;
            const auto& tb = mesh_b.triangles[static_cast<std::size_t>(survivors_b[k])];
            const Vec3& p2 = vertices_b[static_cast<std::size_t>(tb[0])];
            const Vec3& q2 = vertices_b[static_cast<std::size_t>(tb[1])];
            const Vec3& r2 = vertices_b[static_cast<std::size_t>(tb[2])];
            ++out.triangle_tests;
            if (!testTriangleTriangle(p1, q1, r1, p2, q2, r2)) continue;
            if (straddles(p1, q1, r1, p2, q2, r2, ctx.tolerance) &&
                straddles(p2, q2, r2, p1, q1, r1, ctx.tolerance)) {
                out.state = ContactState::Penetrating;
                return out;
            }
            touching = true;
        }
    }
    if (touching) out.state = ContactState::Touching;
    return out;
}

// ---- Dispatch. ----

struct PairEntry {
    PairFn fn = nullptr;
    bool swapped = false;  ///< call fn(b, a): the routine is written for (column, row) types
};

constexpr PairTable<PairEntry> makePairTable() {
    PairTable<PairEntry> table{};
    // Each routine is written for one order; the other order calls it swapped.
    auto set = [&table](ShapeType first, ShapeType second, PairFn fn) {
        pairEntry(table, first, second) = PairEntry{fn, false};
        if (first != second) pairEntry(table, second, first) = PairEntry{fn, true};
    };
    constexpr std::array<ShapeType, 4> kConvex{ShapeType::Sphere, ShapeType::Box,
                                               ShapeType::Capsule, ShapeType::ConvexHull};
    // GJK covers every convex pair first; closed forms override it (Jolt, parry). Convex pairs
    // run with the lesser type first, the order canonicalLess and contact() use.
    for (const ShapeType s : kConvex) {
        for (const ShapeType t : kConvex) {
            if (s <= t) set(s, t, collideConvexGeneric);
        }
        set(ShapeType::Mesh, s, collideMeshConvex);
    }
    set(ShapeType::Mesh, ShapeType::Mesh, collideMeshMesh);
    set(ShapeType::Sphere, ShapeType::Sphere, collide_pairs::sphereSphere);
    set(ShapeType::Sphere, ShapeType::Box, collide_pairs::sphereBox);
    set(ShapeType::Sphere, ShapeType::Capsule, collide_pairs::sphereCapsule);
    set(ShapeType::Capsule, ShapeType::Capsule, collide_pairs::capsuleCapsule);
    set(ShapeType::Box, ShapeType::Box, collideBoxBox);
    return table;
}

constexpr PairTable<PairEntry> kPairTable = makePairTable();

}  // namespace

CollideOutput collide(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b) {
    if (!isFinite(a, pose_a) || !isFinite(b, pose_b)) {
        CollideOutput failed;
        failed.state = ContactState::Failed;
        return failed;
    }
    const PairEntry& entry = pairEntry(kPairTable, a.type, b.type);
    CDLAB_ASSERT(entry.fn != nullptr, "pair table hole");
    bool swap = entry.swapped;
    if (a.type == b.type) swap = canonicalLess(b, pose_b, a, pose_a);
    const Shape& first = swap ? b : a;
    const Shape& second = swap ? a : b;
    const Pose& pose_first = swap ? pose_b : pose_a;
    const Pose& pose_second = swap ? pose_a : pose_b;

    const PairContext ctx = pairContext(a, b);
    CollideOutput out = entry.fn(first, second, relativePose(pose_first, pose_second), ctx);
    if (!std::isfinite(out.distance)) {
        out.state = ContactState::Failed;
        out.distance = 0;
    }
    return out;
}

std::vector<std::int32_t> collidingTriangles(const Shape& mesh, const Pose& pose_mesh,
                                             const Shape& convex, const Pose& pose_convex) {
    std::vector<std::int32_t> hits;
    if (mesh.type != ShapeType::Mesh || !mesh.mesh || !convex.isConvex() ||
        !isFinite(mesh, pose_mesh) || !isFinite(convex, pose_convex)) {
        return hits;
    }
    // collide(mesh, convex) runs collideMeshConvex with the mesh first (the table's unswapped
    // entry): the same context and relative pose here.
    scanMeshConvex(mesh, convex, relativePose(pose_mesh, pose_convex), pairContext(mesh, convex),
                   &hits);
    std::sort(hits.begin(), hits.end());
    hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
    return hits;
}

namespace {

class PairCollector final : public TrianglePairVisitor {
public:
    explicit PairCollector(std::vector<TrianglePair>& out) : out_(out) {}
    bool visit(std::int32_t a, const std::array<Vec3, 3>&, std::int32_t b,
               const std::array<Vec3, 3>&) override {
        out_.push_back({a, b});
        return false;
    }

private:
    std::vector<TrianglePair>& out_;
};

}  // namespace

std::vector<TrianglePair> collidingTrianglePairs(const Shape& a, const Pose& pose_a, const Shape& b,
                                                 const Pose& pose_b) {
    std::vector<TrianglePair> pairs;
    if (a.type != ShapeType::Mesh || b.type != ShapeType::Mesh || !a.mesh || !b.mesh ||
        !isFinite(a, pose_a) || !isFinite(b, pose_b)) {
        return pairs;
    }
    const RelativePose b_in_a = relativePose(pose_a, pose_b);
    if (a.bvh && b.bvh && a.bvh->sameVolumeType(*b.bvh)) {
        PairCollector collect(pairs);
        a.bvh->visitIntersecting(*b.bvh, b_in_a.rotation, b_in_a.position, collect);
    } else {
        Pose pose;
        pose.position = b_in_a.position;
        pose.orientation = Quat(b_in_a.rotation);
        return intersectMeshMeshBruteForce(*a.mesh, *b.mesh, pose);
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    return pairs;
}

}  // namespace collision
