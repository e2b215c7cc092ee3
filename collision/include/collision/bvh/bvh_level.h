// collision/bvh/bvh_level.h -- one level of a mesh body's hierarchy, each node coloured by the
// contact state it takes part in, and the witnesses of confirmed contacts: what a renderer draws
// for `draw.bvh_depth` and `draw.contacts` (through DebugDraw, as broad phases draw themselves).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "collision/bvh/bvh.h"
#include "collision/debug_draw.h"
#include "collision/geometry/shape.h"
#include "collision/math.h"

namespace collision {

/// One node of a tree's cut at a depth (levelNodes): read-only, for drawing the
/// hierarchy and inspecting one level of it.
struct BvhLevelNode {
    std::int32_t node = 0;  ///< depth-first index in the tree (root 0)
    int depth = 0;          ///< root 0; less than the cut's depth only for a leaf above it
    std::vector<std::int32_t> triangles;  ///< mesh indices of the subtree's triangles, sorted
    /// What to draw, in the mesh's frame: sphere volumes are `sphere` (is_sphere); every other
    /// type is `box`: exact for aabb and obb, the box of the three axis slabs for k-DOPs (contains
    /// the k-DOP), the rectangle's box grown by the radius on all three axes for rss, and the
    /// capsule's box for lss.
    bool is_sphere = false;
    BoundingSphere sphere;
    Obb box;
};

/// An overlapping pair of nodes of two cuts: indices into the two levelNodes() lists.
struct BvhLevelPair {
    std::int32_t a = 0;
    std::int32_t b = 0;
    auto operator<=>(const BvhLevelPair&) const = default;
};

/// The cut of `tree` at `depth` (root 0): every node at that depth and every leaf above it, in
/// depth-first order, so their subtrees partition the triangles. Empty for depth < 0 or an empty
/// tree; a depth beyond the leaves gives the leaves. O(n).
std::vector<BvhLevelNode> levelNodes(const MeshBvh& tree, int depth);

/// Every pair (i, j) of levelNodes(a, depth) and levelNodes(b, depth) (same volume type,
/// asserted; empty if not) whose volumes overlap with B placed by p_a = rotation p_b +
/// translation: the node-pair test of the tandem traversal, with its slack. Sorted.
/// O(n_a n_b) in the sizes of the cuts (a drawing aid, not a query).
std::vector<BvhLevelPair> levelOverlaps(const MeshBvh& a, int depth, const MeshBvh& b,
                                        const Mat3& rotation, const Vec3& translation);

/// Indices into levelNodes(tree, depth) whose volumes overlap the volume MeshBvh::visitNearBox
/// fits around the box [box_min, box_max] of a frame placed by p_a = rotation p_b + translation,
/// with visitNearBox's test. Sorted.
std::vector<std::int32_t> levelOverlapsBox(const MeshBvh& tree, int depth, const Vec3& box_min,
                                           const Vec3& box_max, const Mat3& rotation,
                                           const Vec3& translation);

/// State of one node of a drawn level: the highest over the pairs it was marked with.
enum class BvhNodeState : std::uint8_t {
    Apart,        ///< its volume overlaps nothing of another body at that level
    Overlapping,  ///< it overlaps a node of the other hierarchy at the same level (or the other
                  ///< convex body's volume), but its subtree holds no triangle of a confirmed pair
    Confirmed,    ///< its subtree holds a triangle of a confirmed triangle pair
};

/// The cut of one mesh body's hierarchy at a depth (levelNodes), a state per node.
struct BvhLevel {
    int depth = -1;
    std::vector<BvhLevelNode> nodes;
    std::vector<BvhNodeState> states;  ///< same size as nodes
};

/// The cut of `tree` at `depth`, every node Apart. Empty for depth < 0.
BvhLevel makeBvhLevel(const MeshBvh& tree, int depth);

/// Marks one mesh-mesh pair: A (tree_a at pose_a, world) and B (tree_b at pose_b), hierarchies
/// of one volume type (asserted; nothing marked if not), levels made from them at one depth.
/// Both nodes of every pair of levelOverlaps (under B's pose in A's frame) become at
/// least Overlapping; every node whose subtree holds triangle a (of A) or b (of B) of a pair of
/// `confirmed` (mesh indices, e.g. collidingTrianglePairs) becomes Confirmed. States only rise,
/// so a body's nodes end at their highest state over all its pairs. O(n_a n_b) in the cut sizes.
void markBvhLevels(BvhLevel& level_a, const MeshBvh& tree_a, const Pose& pose_a, BvhLevel& level_b,
                   const MeshBvh& tree_b, const Pose& pose_b,
                   std::span<const TrianglePair> confirmed);

/// Marks one mesh-convex pair: the mesh (tree at `pose`, its level) against `convex` at
/// `pose_convex`. Nodes whose volumes overlap the volume of the tree's type fitted around the
/// convex shape's box in its own frame (support points along its axes, grown by the narrow
/// phase's touching tolerance: the box the narrow phase's hierarchy cull uses, up to the size of
/// that tolerance) become at least Overlapping (levelOverlapsBox); nodes holding one of
/// `confirmed` (mesh triangle indices, e.g. collidingTriangles) become Confirmed.
void markBvhLevel(BvhLevel& level, const MeshBvh& tree, const Pose& pose, const Shape& convex,
                  const Pose& pose_convex, std::span<const std::int32_t> confirmed);

/// Draws a node of a level in world space (body at `pose`): its sphere as a wire sphere, any
/// other volume as the box BvhLevelNode::box.
void drawBvhLevelNode(DebugDraw& draw, const BvhLevelNode& node, const Pose& pose,
                      const Color& color);

/// A witness of a confirmed contact, world frame.
struct ContactWitness {
    Vec3 point_a = Vec3::Zero();
    Vec3 point_b = Vec3::Zero();
    Vec3 normal = Vec3::Zero();  ///< unit, or zero when undefined
};

/// What the narrow phase confirms of one pair in detail, derived by its own queries: what
/// `draw.contacts` and `draw.bvh_depth` show and what `cdlab sweep` measures as depth. Empty when
/// the pair does not collide.
struct PairContacts {
    /// Mesh-mesh: collidingTrianglePairs(a, b) (mesh indices).
    std::vector<TrianglePair> triangle_pairs;
    /// Mesh-convex (either order): collidingTriangles(mesh, convex), the mesh's triangles.
    std::vector<std::int32_t> triangles;
    /// Witnesses, A to B:
    /// - convex-convex: contact()'s witness points and normal (one);
    /// - mesh-mesh: one per triangle pair: the closest points of distanceTriangleTriangle, which
    ///   for intersecting triangles are a point the two share up to rounding (where an edge of
    ///   one pierces the other); the normal is A's triangle's face normal (right-hand rule on its
    ///   corners: outward for a closed counter-clockwise mesh). Meshes are surfaces, so no
    ///   penetration direction exists; the face normal is the honest direction.
    /// - mesh-convex: one per triangle: contact() of that triangle (as a flat hull, in the mesh's
    ///   pose) against the convex shape: its witness points and normal.
    std::vector<ContactWitness> witnesses;
    /// Convex-convex: contact()'s penetration depth when Penetrating, else 0. 0 for meshes.
    Real penetration = 0;
};

/// The detail of the pair (a at pose_a, b at pose_b), world frame.
PairContacts pairContacts(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b);

/// pairContacts(a, pose_a, b, pose_b).witnesses.
std::vector<ContactWitness> contactWitnesses(const Shape& a, const Pose& pose_a, const Shape& b,
                                             const Pose& pose_b);

}  // namespace collision
