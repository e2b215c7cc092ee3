// collision/src/bvh/level.cpp -- the cut of a hierarchy at a depth, marked by contact state, and
// the detail of confirmed contacts: triangles, witnesses, depth (read-only use of the hierarchy
// and the narrow phase). Invariant: a level's nodes partition the mesh's triangles (levelNodes),
// so every confirmed triangle marks exactly one node, and states only rise, so the marks of a
// body's pairs commute: the result does not depend on pair order.
#include "collision/bvh/bvh_level.h"

#include <algorithm>
#include <array>
#include <memory>
#include <type_traits>

#include "bvh/traversal.h"
#include "bvh/typed.h"
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

// What levelNodes() draws for a node volume (bvh.h, BvhLevelNode): the sphere itself, or a box
// containing the volume.
void setLevelShape(const BoundingSphere& v, BvhLevelNode& out) {
    out.is_sphere = true;
    out.sphere = v;
}
void setLevelShape(const Aabb& v, BvhLevelNode& out) {
    out.box.center = v.center();
    out.box.half_extents = (v.max - v.min) * Real(0.5);
}
void setLevelShape(const Obb& v, BvhLevelNode& out) { out.box = v; }
template <int K>
void setLevelShape(const Kdop<K>& v, BvhLevelNode& out) {
    // Slabs 0..2 are the unit axes (kKdopDirections): their box contains the k-DOP.
    const Vec3 lo(v.min[0], v.min[1], v.min[2]);
    const Vec3 hi(v.max[0], v.max[1], v.max[2]);
    out.box.center = (lo + hi) * Real(0.5);
    out.box.half_extents = (hi - lo) * Real(0.5);
}
void setLevelShape(const Rss& v, BvhLevelNode& out) {
    out.box.center = v.center;
    out.box.axes = v.axes;
    out.box.half_extents =
        Vec3(v.half_lengths[0] + v.radius, v.half_lengths[1] + v.radius, v.radius);
}

void setLevelShape(const Lss& v, BvhLevelNode& out) {
    // The capsule's box: the segment's axis first, any two unit vectors across it.
    const Vec3 u = v.axis.normalized();
    const Vec3 helper = std::abs(u.x()) < Real(0.9) ? Vec3(Vec3::UnitX()) : Vec3(Vec3::UnitY());
    const Vec3 w1 = u.cross(helper).normalized();
    out.box.center = v.center;
    out.box.axes.col(0) = u;
    out.box.axes.col(1) = w1;
    out.box.axes.col(2) = u.cross(w1);
    out.box.half_extents = Vec3(v.half_length + v.radius, v.radius, v.radius);
}

// The cut of `tree` at `depth` (levelNodes), in depth-first order.
template <class BV>
std::vector<BvhLevelNode> levelNodesOf(const Bvh<BV>& tree, int depth) {
    std::vector<BvhLevelNode> out;
    const auto& nodes = tree.nodes();
    if (depth < 0 || nodes.empty()) return out;
    std::vector<std::pair<std::int32_t, int>> stack{{0, 0}};
    std::vector<std::int32_t> subtree;
    while (!stack.empty()) {
        const auto [index, d] = stack.back();
        stack.pop_back();
        const auto& node = nodes[static_cast<std::size_t>(index)];
        if (d < depth && !node.isLeaf()) {
            stack.push_back({node.right, d + 1});  // left (index + 1) pops first
            stack.push_back({index + 1, d + 1});
            continue;
        }
        BvhLevelNode level;
        level.node = index;
        level.depth = d;
        setLevelShape(node.volume, level);
        subtree.assign(1, index);
        while (!subtree.empty()) {
            const std::int32_t i = subtree.back();
            subtree.pop_back();
            const auto& n = nodes[static_cast<std::size_t>(i)];
            if (n.isLeaf()) {
                for (std::int32_t k = n.first; k < n.first + n.count; ++k) {
                    level.triangles.push_back(tree.leafTriangleId(k));
                }
            } else {
                subtree.push_back(i + 1);
                subtree.push_back(n.right);
            }
        }
        std::sort(level.triangles.begin(), level.triangles.end());
        out.push_back(std::move(level));
    }
    return out;
}

// Depth-first indices of the cut (levelNodesOf without the triangle lists).
template <class BV>
std::vector<std::int32_t> levelIndices(const Bvh<BV>& tree, int depth) {
    std::vector<std::int32_t> out;
    const auto& nodes = tree.nodes();
    if (depth < 0 || nodes.empty()) return out;
    std::vector<std::pair<std::int32_t, int>> stack{{0, 0}};
    while (!stack.empty()) {
        const auto [index, d] = stack.back();
        stack.pop_back();
        const auto& node = nodes[static_cast<std::size_t>(index)];
        if (d < depth && !node.isLeaf()) {
            stack.push_back({node.right, d + 1});
            stack.push_back({index + 1, d + 1});
        } else {
            out.push_back(index);
        }
    }
    return out;
}

}  // namespace

std::vector<BvhLevelNode> levelNodes(const MeshBvh& tree, int depth) {
    return withTree(tree, std::vector<BvhLevelNode>{},
                    [&](const auto& typed) { return levelNodesOf(typed, depth); });
}

std::vector<BvhLevelPair> levelOverlaps(const MeshBvh& a, int depth, const MeshBvh& b,
                                        const Mat3& rotation, const Vec3& translation) {
    return withTreePair(a, b, std::vector<BvhLevelPair>{}, [&](const auto& ta, const auto& tb) {
        using BV = std::remove_cvref_t<decltype(ta.nodes()[0].volume)>;
        std::vector<BvhLevelPair> out;
        const BvhTransform x = makeBvhTransform(rotation, translation, ta.scale(), tb.scale());
        const std::vector<std::int32_t> cut_a = levelIndices(ta, depth);
        const std::vector<std::int32_t> cut_b = levelIndices(tb, depth);
        for (std::size_t i = 0; i < cut_a.size(); ++i) {
            const BV& va = ta.nodes()[static_cast<std::size_t>(cut_a[i])].volume;
            for (std::size_t j = 0; j < cut_b.size(); ++j) {
                const BV& vb = tb.nodes()[static_cast<std::size_t>(cut_b[j])].volume;
                if (BvTraits<BV>::overlaps(va, vb, x)) {
                    out.push_back({static_cast<std::int32_t>(i), static_cast<std::int32_t>(j)});
                }
            }
        }
        return out;
    });
}

std::vector<std::int32_t> levelOverlapsBox(const MeshBvh& tree, int depth, const Vec3& box_min,
                                           const Vec3& box_max, const Mat3& rotation,
                                           const Vec3& translation) {
    return withTree(tree, std::vector<std::int32_t>{}, [&](const auto& typed) {
        using BV = std::remove_cvref_t<decltype(typed.nodes()[0].volume)>;
        std::vector<std::int32_t> out;
        if (typed.nodes().empty()) return out;
        // The volume and transform of MeshBvh::visitNearBox.
        const Real box_scale =
            (box_max - box_min).maxCoeff() +
            std::max(box_min.cwiseAbs().maxCoeff(), box_max.cwiseAbs().maxCoeff());
        const BV volume = BvTraits<BV>::fit(boxSurfaceCorners(box_min, box_max));
        const BvhTransform x = makeBvhTransform(rotation, translation, typed.scale(), box_scale);
        const std::vector<std::int32_t> cut = levelIndices(typed, depth);
        for (std::size_t i = 0; i < cut.size(); ++i) {
            const BV& v = typed.nodes()[static_cast<std::size_t>(cut[i])].volume;
            if (BvTraits<BV>::overlaps(v, volume, x)) out.push_back(static_cast<std::int32_t>(i));
        }
        return out;
    });
}

BvhLevel makeBvhLevel(const MeshBvh& tree, int depth) {
    BvhLevel level;
    level.depth = depth;
    level.nodes = levelNodes(tree, depth);
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
         levelOverlaps(tree_a, level_a.depth, tree_b, b_in_a.rotation, b_in_a.position)) {
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
         levelOverlapsBox(tree, level.depth, lo, hi, b_in_a.rotation, b_in_a.position)) {
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
