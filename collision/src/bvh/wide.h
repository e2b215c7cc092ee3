// collision/src/bvh/wide.h -- a 4-wide OBB hierarchy: the binary OBB tree collapsed so that each
// node holds up to four children's boxes side by side (structure of arrays), and one box is tested
// against all four in one pass of lane arithmetic, two SSE2 lanes at a time (Wald, Benthin, Boulos
// 2008, "Getting rid of packets"; Dammertz et al. 2008, "Shallow bounding volume hierarchies"). The
// binary tree stays inside: it owns the triangles and answers the queries that do not descend in
// tandem.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "collision/bvh/bvh.h"
#include "collision/math.h"
#include "volumes/bvh_volumes.h"

namespace collision {

/// Two doubles in lanes (GCC/Clang vector extension): one SSE2 register on the x86-64
/// baseline. A wide node's four lanes are tested as two such halves. Double lanes run the same
/// arithmetic as the binary tree's scalar test, so no outward rounding is needed beyond the
/// traversal's slack.
using WideLanes = double __attribute__((vector_size(16)));
using WideMask = std::int64_t __attribute__((vector_size(16)));

/// One wide node: up to four children, lane l holding child l's box.
struct WideObbNode {
    alignas(16) double center[3][4];  ///< centre coordinate r
    alignas(16) double axes[9][4];    ///< axes[3 c + r]: component r of box axis c
    alignas(16) double half[3][4];    ///< half extent along axis c
    std::array<Real, 4> cost{};       ///< the child's volume (picks the node to descend)
    std::array<std::int32_t, 4> child{-1, -1, -1, -1};  ///< internal child: its wide node
    std::array<std::int32_t, 4> first{};                ///< leaf child: first triangle (leaf order)
    std::array<std::int32_t, 4> count{};                ///< leaf child: triangles (> 0); 0 internal
    std::int32_t size = 0;  ///< lanes in use (1 for the root node, else 2-4)
};

/// Which lanes of `node` overlap the box `b` (given in the lanes' frame): bit l set for lane l.
/// The 15-axis separating-axis test of testSat15 per lane (Gottschalk, Lin, Manocha 1996 §4),
/// with the same slacks (`tol`, |R| + 16 eps), so it is conservative like the scalar test.
unsigned overlapLanes(const WideObbNode& node, const Obb& b, Real tol);

/// The wide OBB tree of a mesh. Node 0 holds the root alone (one lane); every other node is the
/// collapse of a binary subtree: an internal binary node's two children, the larger internal one
/// repeatedly replaced by its own two, until four or all leaves. Nodes are in depth-first order.
class WideObbTree {
public:
    explicit WideObbTree(const TriangleMesh& mesh, const BvhBuildOptions& options = {});

    const Bvh<Obb>& binary() const { return binary_; }
    const std::vector<WideObbNode>& nodes() const { return nodes_; }
    /// The binary tree's depth plus one bounds the wide depth; traversal stacks use it.
    int depth() const { return binary_.depth(); }
    /// The binary tree's check, then every lane equal to the binary node it was copied from and
    /// every binary node reachable through the wide nodes exactly once.
    bool validate(std::string* error) const;
    /// Refits the binary tree and copies its volumes into the lanes again.
    std::int32_t refit(const TriangleMesh& mesh);

private:
    void collapse();
    std::int32_t collapseNode(std::int32_t binary_index);
    void fillLane(WideObbNode& node, int lane, std::int32_t binary_index) const;

    Bvh<Obb> binary_;
    std::vector<WideObbNode> nodes_;
    std::vector<std::int32_t> lane_source_;  // 4 per wide node: binary node of each lane (-1)
};

/// First contact of two wide trees (B placed by x): testBvhBvh's answer.
bool testWide(const WideObbTree& a, const WideObbTree& b, const BvhTransform& x,
              BvhQueryStats* stats);
/// Every intersecting triangle pair, sorted: intersectBvhBvh's answer.
std::vector<TrianglePair> intersectWide(const WideObbTree& a, const WideObbTree& b,
                                        const BvhTransform& x, BvhQueryStats* stats);
/// Every intersecting pair to `visitor` (mesh indices, corners in A's frame) until it returns
/// true; returns true when stopped.
bool visitWide(const WideObbTree& a, const WideObbTree& b, const BvhTransform& x,
               TrianglePairVisitor& visitor, BvhQueryStats* stats);

}  // namespace collision
