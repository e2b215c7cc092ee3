// collision/src/bvh/level.cpp -- a level of a mesh hierarchy marked by contact state, and the
// detail of confirmed contacts: triangles, witnesses, depth (read-only use of the hierarchy and
// the narrow phase). Invariant: a level's nodes partition the mesh's triangles (MeshBvh::levelNodes), so
// every confirmed triangle marks exactly one node, and states only rise, so the marks of a body's
// pairs commute: the result does not depend on pair order.
#include "collision/bvh/bvh_level.h"

#include <algorithm>
#include <array>
#include <memory>

#include "collision/assert.h"
#include "collision/narrowphase/contact.h"
#include "collision/narrowphase/narrow_phase.h"
#include "geometry/triangle_distance.h"
#include "narrowphase/gjk.h"

namespace collision {

namespace {

// A triangle whose doubled area is below this fraction of its squared edge lengths has no
// normal (rounding of the cross product).
constexpr Real kDegenerateAreaFraction = Real(64) * kEpsilon;

void raise(BvhLevel& level, std::size_t i, BvhNodeState state) {
    if (i < level.states.size() && level.states[i] < state) level.states[i] = state;
}

// Node of `level` holding each triangle (mesh index), -1 for none.
std::vector<std::int32_t> triangleOwners(const BvhLevel& level) {
    std::int32_t max_id = -1;
    for (const BvhLevelNode& n : level.nodes) {
        if (!n.triangles.empty()) max_id = std::max(max_id, n.triangles.back());
    }
    std::vector<std::int32_t> owner(static_cast<std::size_t>(max_id + 1), -1);
    for (std::size_t i = 0; i < level.nodes.size(); ++i) {
        for (const std::int32_t t : level.nodes[i].triangles) {
            owner[static_cast<std::size_t>(t)] = static_cast<std::int32_t>(i);
        }
    }
    return owner;
}

void confirm(BvhLevel& level, const std::vector<std::int32_t>& owner, std::int32_t triangle) {
    if (triangle < 0 || static_cast<std::size_t>(triangle) >= owner.size()) return;
    const std::int32_t node = owner[static_cast<std::size_t>(triangle)];
    if (node >= 0) raise(level, static_cast<std::size_t>(node), BvhNodeState::Confirmed);
}

Vec3 toWorld(const Pose& pose, const Vec3& local) {
    return pose.orientation * local + pose.position;
}

// Unit normal of triangle (p, q, r) by the right-hand rule, zero when it is degenerate.
Vec3 faceNormal(const Vec3& p, const Vec3& q, const Vec3& r) {
    const Vec3 n = (q - p).cross(r - p);
    const Real len = n.norm();
    const Real ref = (q - p).squaredNorm() + (r - p).squaredNorm();
    return len > kDegenerateAreaFraction * ref ? Vec3(n / len) : Vec3(Vec3::Zero());
}

std::array<Vec3, 3> corners(const TriangleMesh& mesh, std::int32_t t) {
    const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
    return {mesh.vertices[static_cast<std::size_t>(tri[0])],
            mesh.vertices[static_cast<std::size_t>(tri[1])],
            mesh.vertices[static_cast<std::size_t>(tri[2])]};
}

void meshMeshWitnesses(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                       std::span<const TrianglePair> pairs, std::vector<ContactWitness>& out) {
    // In A's frame (B moved by the relative pose), then to world once: no precision lost to a
    // far-away origin.
    const RelativePose b_in_a = relativePose(pose_a, pose_b);
    for (const TrianglePair& pair : pairs) {
        const std::array<Vec3, 3> ta = corners(*a.mesh, pair.a);
        std::array<Vec3, 3> tb = corners(*b.mesh, pair.b);
        for (Vec3& v : tb) v = b_in_a.rotation * v + b_in_a.position;
        const TriangleDistance d =
            distanceTriangleTriangle(ta[0], ta[1], ta[2], tb[0], tb[1], tb[2]);
        ContactWitness w;
        w.point_a = toWorld(pose_a, d.point_on_1);
        w.point_b = toWorld(pose_a, d.point_on_2);
        w.normal = pose_a.orientation * faceNormal(ta[0], ta[1], ta[2]);
        out.push_back(w);
    }
}

// `mesh` is A of the output.
void meshConvexWitnesses(const Shape& mesh, const Pose& pose_mesh, const Shape& convex,
                         const Pose& pose_convex, std::span<const std::int32_t> triangles,
                         std::vector<ContactWitness>& out) {
    for (const std::int32_t t : triangles) {
        const std::array<Vec3, 3> c = corners(*mesh.mesh, t);
        auto flat = std::make_shared<ConvexPolytope>();
        flat->vertices = {c[0], c[1], c[2]};
        flat->faces = {{0, 1, 2}, {0, 2, 1}};  // both sides of a flat hull
        const ContactOutput res =
            contact(Shape::convexHull(std::move(flat)), pose_mesh, convex, pose_convex);
        if (res.state == ContactState::Failed) continue;
        out.push_back({res.point_a, res.point_b, res.normal});
    }
}

}  // namespace

BvhLevel makeBvhLevel(const MeshBvh& tree, int depth) {
    BvhLevel level;
    level.depth = depth;
    level.nodes = tree.levelNodes(depth);
    level.states.assign(level.nodes.size(), BvhNodeState::Apart);
    return level;
}

void markBvhLevels(BvhLevel& level_a, const MeshBvh& tree_a, const Pose& pose_a, BvhLevel& level_b,
                   const MeshBvh& tree_b, const Pose& pose_b,
                   std::span<const TrianglePair> confirmed) {
    CDLAB_ASSERT(tree_a.sameVolumeType(tree_b), "levels of different volume types");
    CDLAB_ASSERT(level_a.depth == level_b.depth, "levels of different depths");
    if (!tree_a.sameVolumeType(tree_b)) return;
    const RelativePose b_in_a = relativePose(pose_a, pose_b);
    for (const BvhLevelPair& p :
         tree_a.levelOverlaps(level_a.depth, tree_b, b_in_a.rotation, b_in_a.position)) {
        raise(level_a, static_cast<std::size_t>(p.a), BvhNodeState::Overlapping);
        raise(level_b, static_cast<std::size_t>(p.b), BvhNodeState::Overlapping);
    }
    if (confirmed.empty()) return;
    const std::vector<std::int32_t> owner_a = triangleOwners(level_a);
    const std::vector<std::int32_t> owner_b = triangleOwners(level_b);
    for (const TrianglePair& p : confirmed) {
        confirm(level_a, owner_a, p.a);
        confirm(level_b, owner_b, p.b);
    }
}

void markBvhLevel(BvhLevel& level, const MeshBvh& tree, const Pose& pose, const Shape& convex,
                  const Pose& pose_convex, std::span<const std::int32_t> confirmed) {
    // The convex shape's box in its own frame from its support points (radius included), grown
    // by the touching tolerance relative to its size, as the narrow phase's cull grows its box.
    Vec3 lo;
    Vec3 hi;
    for (int k = 0; k < 3; ++k) {
        hi[k] = supportPoint(convex, Vec3::Unit(k))[k];
        lo[k] = supportPoint(convex, -Vec3::Unit(k))[k];
    }
    const Real size = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff());
    lo.array() -= kTouchRelativeTolerance * size;
    hi.array() += kTouchRelativeTolerance * size;
    const RelativePose b_in_a = relativePose(pose, pose_convex);
    for (const std::int32_t i :
         tree.levelOverlapsBox(level.depth, lo, hi, b_in_a.rotation, b_in_a.position)) {
        raise(level, static_cast<std::size_t>(i), BvhNodeState::Overlapping);
    }
    if (confirmed.empty()) return;
    const std::vector<std::int32_t> owner = triangleOwners(level);
    for (const std::int32_t t : confirmed) confirm(level, owner, t);
}

void drawBvhLevelNode(DebugDraw& draw, const BvhLevelNode& node, const Pose& pose,
                      const Color& color) {
    if (node.is_sphere) {
        draw.drawSphere(transformSphere(node.sphere, pose), color);
    } else {
        draw.drawObb(transformObb(node.box, pose), color);
    }
}

PairContacts pairContacts(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b) {
    PairContacts out;
    const bool mesh_a = a.type == ShapeType::Mesh && a.mesh;
    const bool mesh_b = b.type == ShapeType::Mesh && b.mesh;
    if (mesh_a && mesh_b) {
        out.triangle_pairs = collidingTrianglePairs(a, pose_a, b, pose_b);
        meshMeshWitnesses(a, pose_a, b, pose_b, out.triangle_pairs, out.witnesses);
    } else if (mesh_a) {
        out.triangles = collidingTriangles(a, pose_a, b, pose_b);
        meshConvexWitnesses(a, pose_a, b, pose_b, out.triangles, out.witnesses);
    } else if (mesh_b) {
        out.triangles = collidingTriangles(b, pose_b, a, pose_a);
        meshConvexWitnesses(b, pose_b, a, pose_a, out.triangles, out.witnesses);
        for (ContactWitness& w : out.witnesses) {  // mirror: A is the convex shape
            std::swap(w.point_a, w.point_b);
            w.normal = -w.normal;
        }
    } else {
        const ContactOutput res = contact(a, pose_a, b, pose_b);
        if (isColliding(res.state)) out.witnesses.push_back({res.point_a, res.point_b, res.normal});
        if (res.state == ContactState::Penetrating && a.isConvex() && b.isConvex()) {
            out.penetration = -res.signed_distance;
        }
    }
    return out;
}

std::vector<ContactWitness> contactWitnesses(const Shape& a, const Pose& pose_a, const Shape& b,
                                             const Pose& pose_b) {
    return pairContacts(a, pose_a, b, pose_b).witnesses;
}

}  // namespace collision
