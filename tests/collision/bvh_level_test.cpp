// tests/collision/bvh_level_test.cpp -- one level of a mesh hierarchy coloured by contact state
// (draw.bvh_depth) and the contact witnesses (draw.contacts): the node states of two interlocked
// tori against a brute-force computation written here from the tree's public nodes, for every
// volume type; mesh-convex marks; the witnesses of each pair kind.
#include "collision/bvh/bvh_level.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "collision/geometry/convex_hull.h"
#include "collision/narrowphase/contact.h"
#include "collision/narrowphase/narrow_phase.h"
#include "geometry/triangle_distance.h"
#include "narrowphase/gjk.h"
#include "test_meshes.h"
#include "volumes/bvh_volumes.h"
#include "bvh_typed_tests.h"

namespace {

using collision::BvhLevel;
using collision::BvhNodeState;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::Shape;
using collision::TriangleMesh;
using collision::TrianglePair;
using collision::Vec3;

Shape meshShape(const TriangleMesh& m, std::string_view bvh) {
    auto mesh = std::make_shared<TriangleMesh>(m);
    const collision::ConvexHullOutput hull = collision::computeConvexHull(mesh->vertices);
    EXPECT_TRUE(hull.ok) << hull.error;
    std::shared_ptr<const collision::MeshBvh> tree = collision::buildMeshBvh(bvh, *mesh);
    return Shape::triangleMesh(mesh, std::make_shared<const collision::ConvexPolytope>(hull.hull),
                               tree);
}

using cdlab_test::torusA;
using cdlab_test::torusB;

// Two chain links: A lies in the xy plane around the origin; B stands in the xz plane (turned
// 90 degrees about x, then 7 degrees about z so nothing lines up), its centre at (shift, 0, 0):
//
//        z                    shift = 1.0: B's tube passes through A's hole (x in [-0.1, 0.5])
//        |    .-B-.                        and outside A (x in [1.5, 2.1]): no triangle meets,
//   -----A====+====A----- x                but node volumes do
//        |    '---'           shift = 1.3: B's inner tube (x in [0.2, 0.8]) cuts A's tube
//                                          (x in [0.65, 1.35]): confirmed triangle pairs
Pose poseA() {
    return Pose{Vec3(0.25, -0.5, 2.0), Quat(Eigen::AngleAxis<Real>(0.3, Vec3::UnitY()))};
}
Pose poseB(Real shift) {
    const Quat local = Quat(Eigen::AngleAxis<Real>(0.12, Vec3::UnitZ())) *
                       Quat(Eigen::AngleAxis<Real>(1.5707963267948966, Vec3::UnitX()));
    const Pose a = poseA();
    return Pose{a.position + a.orientation * Vec3(shift, 0, 0), a.orientation * local};
}

// The brute force: the cut at `depth` found by walking Bvh<BV>'s public nodes (node at `depth`
// or a leaf above it), each node's triangles from its leaves, every node pair tested, and the
// confirmed triangles from the all-pairs triangle loop.
template <class BV>
struct BruteCut {
    std::vector<std::int32_t> nodes;                // depth-first order
    std::vector<std::set<std::int32_t>> triangles;  // mesh indices per node
};

template <class BV>
void collectCut(const collision::Bvh<BV>& tree, std::int32_t node, int d, int depth,
                BruteCut<BV>& out) {
    const auto& n = tree.nodes()[static_cast<std::size_t>(node)];
    if (d == depth || n.isLeaf()) {
        std::set<std::int32_t> tris;
        std::vector<std::int32_t> stack{node};
        while (!stack.empty()) {
            const auto& m = tree.nodes()[static_cast<std::size_t>(stack.back())];
            const std::int32_t at = stack.back();
            stack.pop_back();
            if (m.isLeaf()) {
                for (std::int32_t k = m.first; k < m.first + m.count; ++k) {
                    tris.insert(tree.leafTriangleId(k));
                }
            } else {
                stack.push_back(at + 1);
                stack.push_back(m.right);
            }
        }
        out.nodes.push_back(node);
        out.triangles.push_back(std::move(tris));
        return;
    }
    collectCut(tree, node + 1, d + 1, depth, out);
    collectCut(tree, n.right, d + 1, depth, out);
}

template <class BV>
std::vector<BvhNodeState> bruteStates(const collision::Bvh<BV>& mine,
                                      const collision::Bvh<BV>& other, bool mine_is_a,
                                      const collision::BvhTransform& x, int depth,
                                      const std::set<std::int32_t>& confirmed) {
    BruteCut<BV> cut_mine;
    BruteCut<BV> cut_other;
    collectCut(mine, 0, 0, depth, cut_mine);
    collectCut(other, 0, 0, depth, cut_other);
    std::vector<BvhNodeState> states;
    for (std::size_t i = 0; i < cut_mine.nodes.size(); ++i) {
        bool overlap = false;
        const BV& v = mine.nodes()[static_cast<std::size_t>(cut_mine.nodes[i])].volume;
        for (const std::int32_t j : cut_other.nodes) {
            const BV& w = other.nodes()[static_cast<std::size_t>(j)].volume;
            overlap = overlap || (mine_is_a ? collision::BvTraits<BV>::overlaps(v, w, x)
                                            : collision::BvTraits<BV>::overlaps(w, v, x));
        }
        bool red = false;
        for (const std::int32_t t : cut_mine.triangles[i]) red = red || confirmed.count(t) > 0;
        states.push_back(red       ? BvhNodeState::Confirmed
                         : overlap ? BvhNodeState::Overlapping
                                   : BvhNodeState::Apart);
    }
    return states;
}

struct Counts {
    int green = 0;
    int yellow = 0;
    int red = 0;
};
Counts count(const std::vector<BvhNodeState>& states) {
    Counts c;
    for (const BvhNodeState s : states) {
        c.green += s == BvhNodeState::Apart;
        c.yellow += s == BvhNodeState::Overlapping;
        c.red += s == BvhNodeState::Confirmed;
    }
    return c;
}

template <class BV>
class BvhLevelTyped : public ::testing::Test {};
TYPED_TEST_SUITE(BvhLevelTyped, BvhVolumeTestTypes, BvhVolumeTestName);

// The states of both tori's nodes at depths 3 and 5 equal the brute force, node by node, and the
// case has nodes of every colour (so the comparison can fail on each of them).
TYPED_TEST(BvhLevelTyped, InterlockedToriMatchBruteForce) {
    using BV = TypeParam;
    const std::string_view name = collision::BvName<BV>::value;
    const Shape a = meshShape(torusA(), name);
    const Shape b = meshShape(torusB(), name);
    const collision::Bvh<BV> tree_a(torusA());
    const collision::Bvh<BV> tree_b(torusB());
    for (const Real shift : {Real(1.0), Real(1.3)}) {
        const Pose pa = poseA();
        const Pose pb = poseB(shift);
        const std::vector<TrianglePair> pairs = collision::collidingTrianglePairs(a, pa, b, pb);
        const collision::RelativePose rel = collision::relativePose(pa, pb);
        const Pose b_in_a{rel.position, Quat(rel.rotation)};
        EXPECT_EQ(pairs, collision::intersectMeshMeshBruteForce(torusA(), torusB(), b_in_a));
        EXPECT_EQ(pairs.empty(), shift < 1.2) << "shift " << shift;
        std::set<std::int32_t> red_a;
        std::set<std::int32_t> red_b;
        for (const TrianglePair& p : pairs) {
            red_a.insert(p.a);
            red_b.insert(p.b);
        }
        // B in A's frame for A's nodes; A in B's frame for B's (the test is symmetric up to
        // its slack, so each side is tested the way the traversal tests it: A's frame).
        const collision::BvhTransform x =
            collision::makeBvhTransform(rel.rotation, rel.position, tree_a.scale(), tree_b.scale());
        for (const int depth : {3, 5}) {
            BvhLevel la = collision::makeBvhLevel(*a.bvh, depth);
            BvhLevel lb = collision::makeBvhLevel(*b.bvh, depth);
            collision::markBvhLevels(la, *a.bvh, pa, lb, *b.bvh, pb, pairs);
            const auto want_a = bruteStates(tree_a, tree_b, true, x, depth, red_a);
            const auto want_b = bruteStates(tree_b, tree_a, false, x, depth, red_b);
            EXPECT_EQ(la.states, want_a) << "A, shift " << shift << ", depth " << depth;
            EXPECT_EQ(lb.states, want_b) << "B, shift " << shift << ", depth " << depth;
            const Counts ca = count(la.states);
            EXPECT_EQ(ca.green + ca.yellow + ca.red, int(la.nodes.size()));
            EXPECT_GT(ca.green, 0) << "shift " << shift << ", depth " << depth;
            EXPECT_EQ(ca.red > 0, shift > 1.2) << "shift " << shift << ", depth " << depth;
            // At depth 3 of the crossing case every overlapping node of A holds a confirmed
            // triangle for most types; at depth 5 the overlap reaches past the contact.
            if (shift < 1.2 || depth == 5) {
                EXPECT_GT(ca.yellow, 0) << "shift " << shift << ", depth " << depth;
            }
            // The level's nodes partition the triangles.
            std::vector<std::int32_t> all;
            for (const auto& n : la.nodes)
                all.insert(all.end(), n.triangles.begin(), n.triangles.end());
            std::sort(all.begin(), all.end());
            ASSERT_EQ(all.size(), torusA().triangles.size());
            for (std::size_t t = 0; t < all.size(); ++t) ASSERT_EQ(all[t], std::int32_t(t));
        }
    }
}

// A level beyond the leaves is the leaves; depth 0 is the root alone.
TEST(BvhLevel, DepthZeroIsTheRootAndDeepLevelsAreTheLeaves) {
    const Shape a = meshShape(torusA(), "obb");
    const BvhLevel root = collision::makeBvhLevel(*a.bvh, 0);
    ASSERT_EQ(root.nodes.size(), 1u);
    EXPECT_EQ(root.nodes[0].triangles.size(), torusA().triangles.size());
    const BvhLevel deep = collision::makeBvhLevel(*a.bvh, a.bvh->depth() + 3);
    EXPECT_EQ(deep.nodes.size(), torusA().triangles.size());  // one triangle per leaf
    EXPECT_TRUE(collision::makeBvhLevel(*a.bvh, -1).nodes.empty());
}

// Mesh-convex: a sphere dipping into the torus tube. Red nodes are exactly those holding a
// triangle the narrow phase confirms; those triangles are the ones within the radius (up to the
// touching band); far away, every node is green.
TEST(BvhLevel, MeshConvexMarksTheTrianglesTheNarrowPhaseConfirms) {
    const Shape a = meshShape(torusA(), "obb");
    const Shape ball = Shape::sphere(0.2);
    const Pose pa = poseA();
    const Pose pball{pa.position + pa.orientation * Vec3(1.0, 0, 0.4), Quat::Identity()};
    const std::vector<std::int32_t> tris = collision::collidingTriangles(a, pa, ball, pball);
    ASSERT_FALSE(tris.empty());
    EXPECT_TRUE(collision::isColliding(collision::collide(a, pa, ball, pball).state));
    // Ball centre in A's frame: (1, 0, 0.4); the tube surface is 0.05 below it.
    const Vec3 c(1.0, 0, 0.4);
    for (std::size_t t = 0; t < torusA().triangles.size(); ++t) {
        const auto& tri = torusA().triangles[t];
        const collision::TriangleDistance d = collision::distanceTriangleTriangle(
            torusA().vertices[std::size_t(tri[0])], torusA().vertices[std::size_t(tri[1])],
            torusA().vertices[std::size_t(tri[2])], c, c, c);
        const bool listed = std::binary_search(tris.begin(), tris.end(), std::int32_t(t));
        if (d.distance < 0.2 * (1 - 1e-6)) {
            EXPECT_TRUE(listed) << t;
        }
        if (d.distance > 0.2 * (1 + 1e-6)) {
            EXPECT_FALSE(listed) << t;
        }
    }
    BvhLevel level = collision::makeBvhLevel(*a.bvh, 4);
    collision::markBvhLevel(level, *a.bvh, pa, ball, pball, tris);
    const Counts c4 = count(level.states);
    EXPECT_GT(c4.red, 0);
    EXPECT_GT(c4.green, 0);
    for (std::size_t i = 0; i < level.nodes.size(); ++i) {
        bool holds = false;
        for (const std::int32_t t : level.nodes[i].triangles) {
            holds = holds || std::binary_search(tris.begin(), tris.end(), t);
        }
        EXPECT_EQ(level.states[i] == BvhNodeState::Confirmed, holds) << i;
    }
    BvhLevel far = collision::makeBvhLevel(*a.bvh, 4);
    const Pose away{pa.position + Vec3(10, 0, 0), Quat::Identity()};
    collision::markBvhLevel(far, *a.bvh, pa, ball, away, {});
    EXPECT_EQ(count(far.states).green, int(far.nodes.size()));
}

// Convex pairs: the witness is contact()'s. Mesh pairs: one witness per confirmed triangle pair,
// the two points a rounding apart, unit normals. Swapping A and B mirrors mesh-convex witnesses.
TEST(ContactWitnesses, EachPairKindGivesItsWitnesses) {
    const Shape box = Shape::box(Vec3(0.5, 0.5, 0.5));
    const Shape ball = Shape::sphere(0.5);
    const Pose p0{Vec3(0, 0, 0), Quat::Identity()};
    const Pose p1{Vec3(0.9, 0.1, 0), Quat::Identity()};
    const auto convex = collision::contactWitnesses(box, p0, ball, p1);
    const collision::ContactOutput ref = collision::contact(box, p0, ball, p1);
    ASSERT_EQ(convex.size(), 1u);
    EXPECT_EQ(convex[0].point_a, ref.point_a);
    EXPECT_EQ(convex[0].normal, ref.normal);
    EXPECT_TRUE(
        collision::contactWitnesses(box, p0, ball, Pose{Vec3(3, 0, 0), Quat::Identity()}).empty());

    const Shape a = meshShape(torusA(), "obb");
    const Shape b = meshShape(torusB(), "obb");
    const auto mesh_mesh = collision::contactWitnesses(a, poseA(), b, poseB(1.3));
    ASSERT_EQ(mesh_mesh.size(),
              collision::collidingTrianglePairs(a, poseA(), b, poseB(1.3)).size());
    ASSERT_FALSE(mesh_mesh.empty());
    for (const auto& w : mesh_mesh) {
        EXPECT_LT((w.point_a - w.point_b).norm(), 1e-9);
        EXPECT_NEAR(w.normal.norm(), 1.0, 1e-12);
    }
    EXPECT_TRUE(collision::contactWitnesses(a, poseA(), b, poseB(1.0)).empty());

    const Pose pa = poseA();
    const Pose pball{pa.position + pa.orientation * Vec3(1.0, 0, 0.4), Quat::Identity()};
    const Shape small = Shape::sphere(0.2);
    const auto mesh_convex = collision::contactWitnesses(a, pa, small, pball);
    const auto convex_mesh = collision::contactWitnesses(small, pball, a, pa);
    ASSERT_FALSE(mesh_convex.empty());
    ASSERT_EQ(mesh_convex.size(), convex_mesh.size());
    for (std::size_t i = 0; i < mesh_convex.size(); ++i) {
        EXPECT_EQ(mesh_convex[i].point_a, convex_mesh[i].point_b);
        EXPECT_EQ(mesh_convex[i].normal, -convex_mesh[i].normal);
        EXPECT_NEAR(mesh_convex[i].normal.norm(), 1.0, 1e-9);
        // The ball's witness lies on its surface.
        EXPECT_NEAR((mesh_convex[i].point_b - pball.position).norm(), 0.2, 1e-9);
    }
}

}  // namespace
