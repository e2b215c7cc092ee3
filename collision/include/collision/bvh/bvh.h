// collision/bvh/bvh.h -- bounding-volume hierarchies over a triangle mesh (narrow phase of mesh
// pairs). One generic tree, Bvh<BV>, templated on the node volume; the volume types form one type
// list (BvhVolumeTypes) so the tree, the lookup by name and the typed tests all pick up a new
// volume. Queries run one tandem traversal of two trees under the relative pose of B in A's frame.
#pragma once

#include <array>
#include <compare>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <vector>

#include "collision/geometry/shape.h"
#include "collision/math.h"
#include "collision/volumes/bounding_volumes.h"

namespace collision {

/// Discrete-orientation polytope with K/2 fixed slab directions (Klosowski et al. 1998), in the
/// mesh's local frame. Directions (unnormalised, integer components): k=6 the three axes; k=14
/// adds the 4 cube diagonals; k=18 adds the 6 face diagonals; k=26 has all 13.
/// Slab i is { p : min[i] <= dot(direction(i), p) <= max[i] }.
template <int K>
struct Kdop {
    static_assert(K == 6 || K == 14 || K == 18 || K == 26, "k-DOP: k must be 6, 14, 18 or 26");
    static constexpr int kSlabs = K / 2;
    std::array<Real, K / 2> min{};
    std::array<Real, K / 2> max{};
};

/// Rectangle swept sphere (Larsen, Gottschalk, Lin, Manocha 2000): the points within `radius` of
/// the rectangle { center + s axes.col(0) + t axes.col(1) : |s| <= half_lengths[0],
/// |t| <= half_lengths[1] }. axes is orthonormal and right-handed; col(2) is the normal.
struct Rss {
    Vec3 center = Vec3::Zero();
    Mat3 axes = Mat3::Identity();
    std::array<Real, 2> half_lengths{0, 0};
    Real radius = 0;
};

/// Line swept sphere (Larsen, Gottschalk, Lin, Manocha 2000): the points within `radius` of the
/// segment { center + s axis : |s| <= half_length } (a capsule). axis is a unit vector; a
/// zero half_length makes it a sphere. Fitted along the node's principal axis, with the radius
/// measured as the largest distance of the node's corners from the segment, so it contains them.
struct Lss {
    Vec3 center = Vec3::Zero();
    Vec3 axis = Vec3::UnitX();
    Real half_length = 0;
    Real radius = 0;
};

/// Every node-volume type of the generic BVH, in display order. Append here (plus its name in
/// kBvhVolumeNames and its traits in collision/src/volumes/bvh_volumes.h) to add a volume type.
using BvhVolumeTypes =
    std::tuple<BoundingSphere, Aabb, Obb, Kdop<6>, Kdop<14>, Kdop<18>, Kdop<26>, Rss, Lss>;

/// The volume types' names as the CLI and scene files spell them, in BvhVolumeTypes order.
inline constexpr std::array<std::string_view, std::tuple_size_v<BvhVolumeTypes>> kBvhVolumeNames{
    "sphere", "aabb", "obb", "kdop6", "kdop14", "kdop18", "kdop26", "rss", "lss"};

namespace bvh_detail {
// Position of T in a std::tuple of types (a type not in it does not compile).
template <class T, class Tuple>
struct TypeIndex;
template <class T, class... Rest>
struct TypeIndex<T, std::tuple<T, Rest...>> : std::integral_constant<std::size_t, 0> {};
template <class T, class First, class... Rest>
struct TypeIndex<T, std::tuple<First, Rest...>>
    : std::integral_constant<std::size_t, 1 + TypeIndex<T, std::tuple<Rest...>>::value> {};
}  // namespace bvh_detail

/// The name of a volume type (BvName<BV>::value), from kBvhVolumeNames.
template <class BV>
struct BvName {
    static constexpr std::string_view value =
        kBvhVolumeNames[bvh_detail::TypeIndex<BV, BvhVolumeTypes>::value];
};

/// How the top-down build splits a node's triangles (along the longest axis of the bounding box
/// of their centroids).
enum class BvhSplit : std::uint8_t {
    Median,  ///< half the triangles on each side (balanced tree, depth ceil(log2 n))
    Mean,    ///< at the mean centroid coordinate; falls back to the median if one side is empty
};

/// How the tree is built.
enum class BvhBuild : std::uint8_t {
    TopDown,   ///< recursive splits (BvhSplit)
    BottomUp,  ///< greedy agglomerative: triangles in Morton order of their centroids, then the
               ///< neighbouring pair of clusters with the smallest merged box area merges first
               ///< (RTCD 6.2.2; the Morton neighbourhood as in Walter et al. 2008)
};

struct BvhBuildOptions {
    BvhSplit split = BvhSplit::Median;  ///< top-down only
    int max_leaf_triangles = 1;  ///< a node with at most this many triangles is a leaf (>= 1)
    BvhBuild build = BvhBuild::TopDown;
};

/// One intersecting pair: triangle `a` of mesh A and triangle `b` of mesh B (indices into the
/// meshes' `triangles`). Ordered by (a, b).
struct TrianglePair {
    std::int32_t a = 0;
    std::int32_t b = 0;
    auto operator<=>(const TrianglePair&) const = default;
};

/// Cost counters of one query (the Nv and Np of F = Nv Cv + Np Cp).
struct BvhQueryStats {
    std::int64_t bv_tests = 0;        ///< Nv: node-pair overlap tests
    std::int64_t triangle_tests = 0;  ///< Np: exact triangle-triangle tests
};

/// A bounding-volume tree over the triangles of one mesh, in the mesh's local frame. Immutable
/// after construction; rigid motion needs no rebuild (queries take the relative pose).
/// Every node volume contains all corners of its triangles (validate() checks it).
template <class BV>
class Bvh {
public:
    struct Node {
        BV volume;
        Real cost = 0;            ///< volume of `volume` (tightness; picks the node to descend)
        std::int32_t right = -1;  ///< internal: right child (left child is this index + 1)
        std::int32_t first = 0;   ///< leaf: first triangle in leaf order
        std::int32_t count = 0;   ///< leaf: number of triangles (> 0); 0 for internal nodes
        bool isLeaf() const { return count > 0; }
    };

    Bvh() = default;
    /// Top-down build. Cost O(n log n) for box-like volumes (expected, with Welzl for spheres).
    /// An empty mesh gives an empty tree (every query: no contact). Triangle indices must be
    /// valid vertex indices (asserted).
    explicit Bvh(const TriangleMesh& mesh, const BvhBuildOptions& options = {});

    const std::vector<Node>& nodes() const { return nodes_; }
    std::int32_t triangleCount() const { return static_cast<std::int32_t>(ids_.size()); }
    /// Corners of the triangle at leaf-order position `i` (copies of the mesh's vertices).
    const std::array<Vec3, 3>& leafTriangle(std::int32_t i) const { return corners_[i]; }
    /// Mesh index of the triangle at leaf-order position `i`.
    std::int32_t leafTriangleId(std::int32_t i) const { return ids_[i]; }
    /// Mesh vertex indices of the triangle at leaf-order position `i` (adjacency for self tests).
    const std::array<std::int32_t, 3>& leafTriangleVertices(std::int32_t i) const {
        return vertex_ids_[i];
    }
    /// Length scale of the mesh: largest |coordinate| plus the root extent (sets tolerances).
    Real scale() const { return scale_; }
    /// Longest root-to-leaf path (a single leaf has depth 1; empty tree 0). Computed at build.
    int depth() const { return depth_; }
    /// Whole-tree check: child ranges partition their parent, every triangle is in one leaf, and
    /// every node volume contains its triangles' corners (to a tolerance relative to the mesh
    /// scale). On failure returns false and, if `error` is given, says what failed.
    bool validate(std::string* error = nullptr) const;
    /// Refit for a deforming mesh: takes the vertex positions of `mesh` (the triangles the tree
    /// was built from, same order; asserted, and nothing done when the count differs), moves
    /// every triangle and refits every node volume to its triangles, keeping the tree's
    /// structure. O(n log n) (AABB and k-DOP: O(n), each node merging its children's bounds);
    /// queries then answer for the deformed mesh (exact triangle tests; the volumes may be
    /// looser than a rebuild's). Returns the nodes updated (Nu).
    std::int32_t refit(const TriangleMesh& mesh);

private:
    std::vector<Node> nodes_;
    std::vector<std::array<Vec3, 3>> corners_;             // leaf order
    std::vector<std::int32_t> ids_;                        // leaf order -> mesh triangle index
    std::vector<std::array<std::int32_t, 3>> vertex_ids_;  // leaf order: the mesh's indices
    Real scale_ = 0;
    int depth_ = 0;
};

/// Does any triangle of `a` touch or cross any triangle of `b`, B placed by `b_in_a` (B's frame
/// in A's frame)? Exact for the triangle corners as transformed (R v + t, in Real); the volume
/// tests are conservative. Stops at the first intersecting pair. `stats` may be null.
template <class BV>
bool testBvhBvh(const Bvh<BV>& a, const Bvh<BV>& b, const Pose& b_in_a,
                BvhQueryStats* stats = nullptr);

/// Every intersecting triangle pair (touching counts), sorted by (a, b), no duplicates: the same
/// list as intersectMeshMeshBruteForce for the same meshes and pose. `stats` may be null.
template <class BV>
std::vector<TrianglePair> intersectBvhBvh(const Bvh<BV>& a, const Bvh<BV>& b, const Pose& b_in_a,
                                          BvhQueryStats* stats = nullptr);

/// Distance between two meshes with witnesses: the closest triangle pair and its closest points.
struct MeshDistance {
    Real distance = 0;    ///< >= 0; 0 when the meshes touch or cross; +inf for an empty mesh
    std::int32_t a = -1;  ///< witness triangle of A (mesh index), -1 for an empty mesh
    std::int32_t b = -1;  ///< witness triangle of B
    Vec3 point_on_a = Vec3::Zero();  ///< closest point on triangle a, in A's frame
    Vec3 point_on_b = Vec3::Zero();  ///< closest point on triangle b, in A's frame
};

/// Smallest distance between the surfaces of `a` and `b` (B placed by `b_in_a`), by a
/// depth-first traversal that visits the nearer child pair first and skips node pairs whose
/// volume-distance lower bound exceeds the best distance found. Approximate to the rounding of
/// the triangle closest points (relative to the meshes' scale); the same value as
/// distanceMeshMeshBruteForce up to that rounding (a tie may pick another witness pair).
/// Stops at 0 (touching or crossing). stats: bv_tests = lower bounds, triangle_tests = triangle
/// distances. `stats` may be null.
template <class BV>
MeshDistance distanceBvhBvh(const Bvh<BV>& a, const Bvh<BV>& b, const Pose& b_in_a,
                            BvhQueryStats* stats = nullptr);

/// The reference: the minimum over every triangle pair (ties: the first pair in (a, b) order).
MeshDistance distanceMeshMeshBruteForce(const TriangleMesh& a, const TriangleMesh& b,
                                        const Pose& b_in_a, BvhQueryStats* stats = nullptr);

/// Self-collision of one mesh: every pair of its triangles that touch or cross, except adjacent
/// ones (sharing a vertex index; coincident vertices with different indices do not count as
/// shared), as (a, b) with a < b, sorted, no duplicates. One traversal of the tree against
/// itself that visits each pair of subtrees once. `stats` may be null.
template <class BV>
std::vector<TrianglePair> intersectSelf(const Bvh<BV>& tree, BvhQueryStats* stats = nullptr);

/// The reference for intersectSelf: every non-adjacent pair (a < b) with the same exact test.
std::vector<TrianglePair> intersectSelfBruteForce(const TriangleMesh& mesh,
                                                  BvhQueryStats* stats = nullptr);

/// The brute-force reference: every triangle pair (after an exact per-triangle AABB reject) with
/// the same exact triangle test and the same vertex transform. O(n_a n_b).
std::vector<TrianglePair> intersectMeshMeshBruteForce(const TriangleMesh& a, const TriangleMesh& b,
                                                      const Pose& b_in_a,
                                                      BvhQueryStats* stats = nullptr);

/// The brute force's answer (same triangles, boxes and exact tests, same list) found faster: B's
/// triangle boxes sorted along x, each triangle of A tested only against the boxes whose x range
/// can overlap its own. For checking large meshes (benchmarks); O(n log n + candidates).
std::vector<TrianglePair> intersectMeshMeshSweep(const TriangleMesh& a, const TriangleMesh& b,
                                                 const Pose& b_in_a,
                                                 BvhQueryStats* stats = nullptr);

/// Receives the intersecting triangle pairs of MeshBvh::visitIntersecting, all corners in A's
/// frame (B's moved by the query transform).
class TrianglePairVisitor {
public:
    virtual ~TrianglePairVisitor() = default;
    /// Triangle `a` of mesh A (mesh index, corners `ta`) touches or crosses triangle `b` of mesh B
    /// (corners `tb`). Return true to stop the traversal.
    virtual bool visit(std::int32_t a, const std::array<Vec3, 3>& ta, std::int32_t b,
                       const std::array<Vec3, 3>& tb) = 0;
};

/// Receives the candidate triangles of MeshBvh::visitNearBox, corners in the mesh's frame.
class TriangleVisitor {
public:
    virtual ~TriangleVisitor() = default;
    /// Triangle `id` (mesh index) whose leaf volume overlaps the box. Return true to stop.
    virtual bool visit(std::int32_t id, const std::array<Vec3, 3>& corners) = 0;
};

/// A Bvh of a volume type chosen at run time by name (CLI, scenes, benchmarks, mesh shapes):
/// build (buildMeshBvh), query, refit, validate. What else works on a hierarchy takes it as an
/// argument: the cut of a level for drawing (bvh_level.h), the replay of a query's tests for the
/// cost model (bvh_replay.h), the typed tree (treeOf).
class MeshBvh {
public:
    virtual ~MeshBvh() = default;
    /// A copy of the tree (a deforming mesh's, kept by World::snapshot), refitted apart from it.
    virtual std::unique_ptr<MeshBvh> clone() const = 0;
    virtual std::string_view volumeName() const = 0;
    virtual std::int32_t nodeCount() const = 0;
    virtual int depth() const = 0;
    virtual bool validate(std::string* error = nullptr) const = 0;
    /// testBvhBvh with `b`, which must hold the same volume type (asserted; false if not).
    virtual bool testOverlap(const MeshBvh& b, const Pose& b_in_a,
                             BvhQueryStats* stats = nullptr) const = 0;
    /// intersectBvhBvh with `b`, which must hold the same volume type (asserted; empty if not).
    virtual std::vector<TrianglePair> intersect(const MeshBvh& b, const Pose& b_in_a,
                                                BvhQueryStats* stats = nullptr) const = 0;
    /// Number of triangles of the mesh the tree was built from.
    virtual std::int32_t triangleCount() const = 0;
    /// distanceBvhBvh with `b`, which must hold the same volume type (asserted; +inf if not).
    virtual MeshDistance distance(const MeshBvh& b, const Pose& b_in_a,
                                  BvhQueryStats* stats = nullptr) const = 0;
    /// intersectSelf on this tree.
    virtual std::vector<TrianglePair> intersectSelf(BvhQueryStats* stats = nullptr) const = 0;
    /// Bvh::refit (a deforming mesh): returns the nodes updated. Not for a tree shared by shapes
    /// that other threads query.
    virtual std::int32_t refit(const TriangleMesh& mesh) = 0;
    /// True when `b` holds the same volume type (the tandem queries need it).
    virtual bool sameVolumeType(const MeshBvh& b) const = 0;
    /// The tandem traversal with a visitor: every intersecting triangle pair (exact triangle test,
    /// touching counts) goes to `visitor` until it returns true. B is placed by p_a = rotation p_b
    /// + translation (`rotation` orthonormal), the form the narrow phase holds; B's corners are
    /// moved with exactly that expression. `b` must hold the same volume type (asserted; nothing
    /// visited if not). Returns true when the visitor stopped the traversal.
    virtual bool visitIntersecting(const MeshBvh& b, const Mat3& rotation, const Vec3& translation,
                                   TrianglePairVisitor& visitor,
                                   BvhQueryStats* stats = nullptr) const = 0;
    /// The tree-against-volume traversal: the box [box_min, box_max] of a frame B placed by
    /// p_a = rotation p_b + translation gets a volume of this tree's type fitted around it (in
    /// B's frame), and every leaf triangle whose node volumes all overlap it goes to `visitor`
    /// until it returns true. Conservative: every triangle that meets the box is visited (the
    /// volume tests have a slack relative to the scale); others may be. Returns true when the
    /// visitor stopped the traversal. stats->bv_tests counts the node tests.
    virtual bool visitNearBox(const Vec3& box_min, const Vec3& box_max, const Mat3& rotation,
                              const Vec3& translation, TriangleVisitor& visitor,
                              BvhQueryStats* stats = nullptr) const = 0;
};

/// The volume type mesh shapes use unless a scene chooses another (`world.mesh_bvh`): the fastest
/// in `cdlab bench narrowphase` on the two-tori workload.
inline constexpr std::string_view kDefaultMeshBvh = "obb";

/// The names a tree can be built under (buildMeshBvh), as scenes (`world.mesh_bvh`), `cdlab
/// query --bv` and the benchmarks accept them: BvhVolumeTypes in order (sphere, aabb, obb,
/// kdop6, kdop14, kdop18, kdop26, rss, lss), then kWideObbName.
const std::vector<std::string_view>& bvhVolumeNames();

/// The typed tree of `tree` when it holds volume type BV, else null (the wide tree,
/// kWideObbName, holds no Bvh<BV> of its own type: see obbTreeOf).
template <class BV>
const Bvh<BV>* treeOf(const MeshBvh& tree);

/// The 4-wide OBB hierarchy: the binary OBB tree collapsed to nodes of up to four children whose
/// boxes are tested together. Built by buildMeshBvh under this name. Its discrete tandem queries
/// (testOverlap, intersect, visitIntersecting) descend the wide nodes; the rest (distance,
/// intersectSelf, visitNearBox, mesh-mesh CCD through obbTreeOf, the drawn levels of
/// bvh_level.h) use the binary OBB tree it was collapsed from: same triangles, same boxes.
inline constexpr std::string_view kWideObbName = "obb4";

/// The binary OBB tree of `tree`: its own for an obb tree, the one the wide tree (kWideObbName)
/// was collapsed from, else null. Mesh-mesh CCD (timeOfImpactMeshes in ccd.h) runs on it.
const Bvh<Obb>* obbTreeOf(const MeshBvh& tree);

/// Builds the tree of the named volume type (or kWideObbName); nullptr for an unknown name.
std::unique_ptr<MeshBvh> buildMeshBvh(std::string_view volume_name, const TriangleMesh& mesh,
                                      const BvhBuildOptions& options = {});

}  // namespace collision
