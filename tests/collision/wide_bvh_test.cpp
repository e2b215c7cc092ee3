// tests/collision/wide_bvh_test.cpp -- the 4-wide OBB tree (buildMeshBvh(kWideObbName)):
// differential against the brute-force triangle-pair reference on the cases the binary trees
// are held to (random, touching, coplanar, degenerate, far from the origin, tiny and huge meshes,
// large meshes), its four-lane box test against the scalar one, and the collapse's bookkeeping.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "bvh/wide.h"
#include "collision/bvh/bvh.h"
#include "collision/bvh/bvh_level.h"
#include "test_meshes.h"
#include "test_random.h"
#include "volumes/bvh_volumes.h"

namespace {

using collision::BvhBuildOptions;
using collision::BvhQueryStats;
using collision::BvhSplit;
using collision::MeshBvh;
using collision::Obb;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::TriangleMesh;
using collision::TrianglePair;
using collision::Vec3;

std::unique_ptr<MeshBvh> wide(const TriangleMesh& mesh, const BvhBuildOptions& options = {}) {
    return collision::buildMeshBvh(collision::kWideObbName, mesh, options);
}

TriangleMesh transformed(const TriangleMesh& m, Real scale, const Vec3& offset) {
    TriangleMesh out = m;
    for (Vec3& v : out.vertices) v = v * scale + offset;
    return out;
}

std::vector<Pose> randomPoses(std::uint64_t seed, int count, Real range) {
    cdlab_test::Rng rng(seed);
    std::vector<Pose> poses;
    for (int i = 0; i < count; ++i) poses.push_back(Pose{rng.vec(-range, range), rng.rotation()});
    return poses;
}

// Checks first contact, all pairs and the visitor of the wide trees against the brute force;
// returns whether the meshes touch.
class CollectPairs final : public collision::TrianglePairVisitor {
public:
    bool visit(std::int32_t a, const std::array<Vec3, 3>&, std::int32_t b,
               const std::array<Vec3, 3>&) override {
        pairs.push_back({a, b});
        return false;
    }
    std::vector<TrianglePair> pairs;
};
bool expectBruteForceAnswer(const TriangleMesh& ma, const MeshBvh& a, const TriangleMesh& mb,
                            const MeshBvh& b, const Pose& pose, const std::string& what) {
    const std::vector<TrianglePair> expected =
        ma.triangles.size() * mb.triangles.size() <= 4000000
            ? collision::intersectMeshMeshBruteForce(ma, mb, pose)
            : collision::intersectMeshMeshSweep(ma, mb, pose);
    EXPECT_EQ(a.intersect(b, pose), expected) << what;
    EXPECT_EQ(a.testOverlap(b, pose), !expected.empty()) << what;
    CollectPairs visitor;
    a.visitIntersecting(b, pose.rotation(), pose.position, visitor);
    std::sort(visitor.pairs.begin(), visitor.pairs.end());
    EXPECT_EQ(visitor.pairs, expected) << what;
    return !expected.empty();
}

using cdlab_test::torusA;
using cdlab_test::torusB;

TEST(WideBvh, CollapseKeepsEveryBinaryBoxAndValidates) {
    for (const BvhSplit split : {BvhSplit::Median, BvhSplit::Mean}) {
        for (const int leaf : {1, 4}) {
            const collision::WideObbTree tree(torusA(), BvhBuildOptions{split, leaf});
            std::string error;
            EXPECT_TRUE(tree.validate(&error)) << error;
            // Four lanes per node except the root's: about a third of the binary node count.
            const auto binary_nodes = tree.binary().nodes().size();
            EXPECT_LE(tree.nodes().size(), binary_nodes / 3 + 2);
        }
    }
    for (const Real scale : {Real(1e-4), Real(1), Real(1e4)}) {
        const auto tree = wide(transformed(torusB(), scale, Vec3(1e6, -1e6, 1e6)));
        std::string error;
        EXPECT_TRUE(tree->validate(&error)) << "scale " << scale << ": " << error;
    }
}

TEST(WideBvh, ValidateSeesALaneThatDiffersFromItsBinaryBox) {
    collision::WideObbTree tree(torusA());
    ASSERT_TRUE(tree.validate(nullptr));
    auto& node = const_cast<collision::WideObbNode&>(tree.nodes()[1]);
    node.half[2][1] *= Real(0.5);
    std::string error;
    EXPECT_FALSE(tree.validate(&error));
    EXPECT_NE(error.find("lane 1"), std::string::npos) << error;
}

// Random boxes, B's placed by a random pose: every lane's bit is the scalar test's answer
// (generic boxes are never within the slack of touching, so conservative means equal here).
TEST(WideBvh, FourLaneTestAgreesWithTheScalarBoxTest) {
    cdlab_test::Rng rng(77);
    int overlapping = 0;
    int separated = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        collision::WideObbNode node;
        std::array<Obb, 4> boxes;
        node.size = 1 + trial % 4;
        for (int l = 0; l < 4; ++l) {
            Obb& box = boxes[static_cast<std::size_t>(l)];
            box.center = rng.vec(-2, 2);
            box.axes = rng.rotation().toRotationMatrix();
            box.half_extents = rng.vec(0.05, 1.0);
            const Obb& lane = boxes[static_cast<std::size_t>(l < node.size ? l : 0)];
            for (int r = 0; r < 3; ++r) {
                node.center[r][l] = lane.center[r];
                node.half[r][l] = lane.half_extents[r];
                for (int c = 0; c < 3; ++c) node.axes[3 * c + r][l] = lane.axes(r, c);
            }
        }
        const Pose pose{rng.vec(-1, 1), rng.rotation()};
        const collision::BvhTransform x = collision::makeBvhTransform(pose, 3, 3);
        const Obb b{rng.vec(-2, 2), rng.rotation().toRotationMatrix(), rng.vec(0.05, 1.0)};
        const Obb moved = collision::BvTraits<Obb>::move(b, x);
        const unsigned hits = collision::overlapLanes(node, moved, x.tol);
        for (int l = 0; l < 4; ++l) {
            const bool scalar = l < node.size && collision::BvTraits<Obb>::overlaps(
                                                     boxes[static_cast<std::size_t>(l)], b, x);
            EXPECT_EQ(((hits >> l) & 1u) != 0, scalar) << "trial " << trial << " lane " << l;
            overlapping += scalar ? 1 : 0;
            separated += (l < node.size && !scalar) ? 1 : 0;
        }
    }
    EXPECT_GT(overlapping, 500);
    EXPECT_GT(separated, 500);
}

TEST(WideBvh, AllPairsAndFirstContactMatchBruteForceAtRandomPoses) {
    const auto a = wide(torusA());
    const auto b = wide(torusB());
    int colliding = 0;
    const std::vector<Pose> poses = randomPoses(4242, 16, 2.0);
    for (std::size_t k = 0; k < poses.size(); ++k) {
        colliding += expectBruteForceAnswer(torusA(), *a, torusB(), *b, poses[k],
                                            "pose " + std::to_string(k))
                         ? 1
                         : 0;
    }
    EXPECT_GE(colliding, 4);
    EXPECT_LE(colliding, 12);
    // Fat leaves and the mean split collapse to other shapes: same answers.
    const auto fat_a = wide(torusA(), BvhBuildOptions{BvhSplit::Mean, 4});
    const auto fat_b = wide(torusB(), BvhBuildOptions{BvhSplit::Mean, 4});
    for (std::size_t k = 0; k < 6; ++k) {
        expectBruteForceAnswer(torusA(), *fat_a, torusB(), *fat_b, poses[k],
                               "fat pose " + std::to_string(k));
    }
}

// The grid cube (exact coordinates): face to face, offset grids, quarter turn, edge, corner, a
// hair apart; and two tori at the identical pose.
TEST(WideBvh, TouchingAndCoplanarPosesMatchBruteForce) {
    const TriangleMesh cube = cdlab_test::makeGridCubeMesh(8);
    const auto tree = wide(cube);
    const Quat quarter_turn(std::cos(std::numbers::pi_v<Real> / 4),
                            std::sin(std::numbers::pi_v<Real> / 4), 0, 0);
    const std::vector<Pose> poses = {
        Pose{},
        Pose{Vec3(2, 0, 0), Quat::Identity()},
        Pose{Vec3(2, 0.125, 0.125), Quat::Identity()},
        Pose{Vec3(2, 2, 0), Quat::Identity()},
        Pose{Vec3(2, 2, 2), Quat::Identity()},
        Pose{Vec3(2, 0, 0), quarter_turn},
        Pose{Vec3(2 + 1e-9, 0, 0), Quat::Identity()},
    };
    for (std::size_t k = 0; k < poses.size(); ++k) {
        const bool hit =
            expectBruteForceAnswer(cube, *tree, cube, *tree, poses[k], "pose " + std::to_string(k));
        EXPECT_EQ(hit, k != 6) << "pose " << k;
    }
    const auto torus = wide(torusB());
    expectBruteForceAnswer(torusB(), *torus, torusB(), *torus, Pose{}, "identical tori");
}

// Both meshes 1e6 from the origin and scaled by 1e-4 and 1e4: the same answers as brute force on
// the moved scene.
TEST(WideBvh, FarTinyAndHugeMeshesMatchBruteForce) {
    const TriangleMesh small_a = cdlab_test::makeTorusMesh(1.0, 0.35, 24, 12);
    const TriangleMesh small_b = cdlab_test::makeTorusMesh(0.8, 0.3, 20, 10);
    int colliding = 0;
    for (const Real scale : {Real(1), Real(1e-4), Real(1e4)}) {
        const Vec3 offset = Vec3(1e6, -2e6, 0.5e6) * scale;
        const TriangleMesh ma = transformed(small_a, scale, offset);
        const TriangleMesh mb = transformed(small_b, scale, offset);
        const auto a = wide(ma);
        const auto b = wide(mb);
        for (const Pose& pose : randomPoses(100, 6, 1.6)) {
            const Pose moved{pose.position * scale + offset - (pose.orientation * offset),
                             pose.orientation};
            colliding +=
                expectBruteForceAnswer(ma, *a, mb, *b, moved, "scale " + std::to_string(scale)) ? 1
                                                                                                : 0;
        }
    }
    EXPECT_GE(colliding, 3 * 2);
}

// Zero-area triangles (a repeated vertex, three collinear corners), slivers and a lone triangle
// (the root is a leaf) among ordinary ones.
TEST(WideBvh, DegenerateTrianglesMatchBruteForce) {
    TriangleMesh mesh = cdlab_test::makeTorusMesh(1.0, 0.35, 12, 8);
    const auto base = static_cast<std::int32_t>(mesh.vertices.size());
    mesh.vertices.push_back(Vec3(0.2, 0.1, 0));
    mesh.vertices.push_back(Vec3(0.4, 0.2, 0));
    mesh.vertices.push_back(Vec3(0.8, 0.4, 0));
    mesh.vertices.push_back(Vec3(1.3, 0.0, 0.3));
    mesh.triangles.push_back({base, base + 1, base + 2});      // collinear
    mesh.triangles.push_back({base, base, base + 3});          // repeated vertex
    mesh.triangles.push_back({base + 3, base + 3, base + 3});  // a point
    const auto tree = wide(mesh);
    EXPECT_TRUE(tree->validate());
    int colliding = 0;
    for (const Pose& pose : randomPoses(5, 12, 1.5)) {
        colliding += expectBruteForceAnswer(mesh, *tree, mesh, *tree, pose, "degenerate") ? 1 : 0;
    }
    EXPECT_GE(colliding, 2);
    TriangleMesh lone;
    lone.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    lone.triangles = {{0, 1, 2}};
    const auto one = wide(lone);
    expectBruteForceAnswer(lone, *one, mesh, *tree, Pose{Vec3(0.5, 0, 0), Quat::Identity()},
                           "lone triangle");
    expectBruteForceAnswer(mesh, *tree, lone, *one, Pose{Vec3(1, 0, 0), Quat::Identity()},
                           "lone triangle as B");
    const auto empty = wide(TriangleMesh{});
    EXPECT_FALSE(empty->testOverlap(*tree, Pose{}));
    EXPECT_TRUE(tree->intersect(*empty, Pose{}).empty());
}

// 10k-triangle tori at random poses and 12k-triangle grid cubes face to face and coplanar.
TEST(WideBvh, LargeMeshesMatchBruteForce) {
    const TriangleMesh ta = cdlab_test::makeTorusMesh(1.0, 0.35, 100, 50);
    const TriangleMesh tb = cdlab_test::makeTorusMesh(0.9, 0.3, 100, 50);
    const TriangleMesh cube = cdlab_test::makeGridCubeMesh(32);
    const auto a = wide(ta);
    const auto b = wide(tb);
    const auto c = wide(cube);
    int colliding = 0;
    for (const Pose& pose : randomPoses(7, 6, 1.8)) {
        colliding += expectBruteForceAnswer(ta, *a, tb, *b, pose, "tori") ? 1 : 0;
    }
    EXPECT_GE(colliding, 2);
    const Real half_cell = Real(1) / 32;
    cdlab_test::Rng rng(31);
    std::vector<Pose> poses = {Pose{Vec3(2, 0, 0), Quat::Identity()},
                               Pose{Vec3(2, half_cell, half_cell), Quat::Identity()},
                               Pose{Vec3(2, 2, 2), Quat::Identity()}};
    for (int i = 0; i < 3; ++i) {
        const Real angle = rng.uniform(0, 2 * std::numbers::pi_v<Real>);
        poses.push_back(Pose{Vec3(2, rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5)),
                             Quat(std::cos(angle / 2), std::sin(angle / 2), 0, 0)});
    }
    for (const Pose& pose : poses) {
        EXPECT_TRUE(expectBruteForceAnswer(cube, *c, cube, *c, pose, "cubes"));
    }
}

// The queries that run on the binary tree inside (distance, self-collision, refit) answer as the
// binary OBB tree does.
TEST(WideBvh, OtherQueriesAnswerAsTheBinaryObbTree) {
    const auto wa = wide(torusA());
    const auto wb = wide(torusB());
    const auto oa = collision::buildMeshBvh("obb", torusA());
    const auto ob = collision::buildMeshBvh("obb", torusB());
    const Pose pose = randomPoses(3, 1, 1.0).front();
    EXPECT_EQ(wa->distance(*wb, pose).distance, oa->distance(*ob, pose).distance);
    EXPECT_EQ(wa->intersectSelf(), oa->intersectSelf());
    TriangleMesh deformed = torusA();
    for (Vec3& v : deformed.vertices) v.z() *= 1 + Real(0.3) * v.x();
    wa->refit(deformed);
    EXPECT_TRUE(wa->validate());
    for (const Pose& p : randomPoses(9, 6, 1.5)) {
        expectBruteForceAnswer(deformed, *wa, torusB(), *wb, p, "refitted");
    }
}

// The binary OBB tree inside is what mesh-mesh CCD (obbTreeOf) and the drawn levels
// (bvh_level.h) use: the same nodes, cuts and overlapping node pairs as an obb tree's.
TEST(WideBvh, BinaryTreeInsideServesCcdAndLevels) {
    const auto wa = wide(torusA());
    const auto wb = wide(torusB());
    const auto oa = collision::buildMeshBvh("obb", torusA());
    const auto ob = collision::buildMeshBvh("obb", torusB());
    const collision::Bvh<Obb>* binary = collision::obbTreeOf(*wa);
    ASSERT_NE(binary, nullptr);
    EXPECT_EQ(collision::treeOf<Obb>(*wa), nullptr);
    EXPECT_EQ(collision::obbTreeOf(*oa), collision::treeOf<Obb>(*oa));
    EXPECT_EQ(collision::obbTreeOf(*collision::buildMeshBvh("aabb", torusA())), nullptr);
    EXPECT_EQ(binary->nodes().size(), collision::treeOf<Obb>(*oa)->nodes().size());
    const Pose pose = randomPoses(5, 1, 0.8).front();
    const collision::Mat3 rotation = pose.orientation.toRotationMatrix();
    for (const int depth : {0, 2, 5}) {
        const auto nodes_w = collision::levelNodes(*wa, depth);
        const auto nodes_o = collision::levelNodes(*oa, depth);
        ASSERT_FALSE(nodes_w.empty()) << depth;
        ASSERT_EQ(nodes_w.size(), nodes_o.size()) << depth;
        for (std::size_t i = 0; i < nodes_w.size(); ++i) {
            EXPECT_EQ(nodes_w[i].node, nodes_o[i].node);
            EXPECT_EQ(nodes_w[i].triangles, nodes_o[i].triangles);
            EXPECT_EQ(nodes_w[i].box.center, nodes_o[i].box.center);
        }
        EXPECT_EQ(collision::levelOverlaps(*wa, depth, *wb, rotation, pose.position),
                  collision::levelOverlaps(*oa, depth, *ob, rotation, pose.position))
            << depth;
    }
}

}  // namespace
