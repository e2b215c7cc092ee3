// tests/collision/bvh_test.cpp -- the generic mesh BVH for every volume type: differential
// against the brute-force triangle-pair reference (random, touching and coplanar poses),
// containment of every fitted volume (validate), metamorphic translation and scaling, and the
// lookup by name.
#include "collision/bvh/bvh.h"
#include "collision/bvh/bvh_replay.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "test_meshes.h"
#include "test_random.h"
#include "test_scale.h"
#include "bvh_typed_tests.h"

namespace {

using collision::Aabb;
using collision::Bvh;
using collision::BvhBuildOptions;
using collision::BvhQueryStats;
using collision::BvhSplit;
using collision::BvhVolumeTypes;
using collision::BvName;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::TriangleMesh;
using collision::TrianglePair;
using collision::Vec3;

TriangleMesh transformed(const TriangleMesh& m, Real scale, const Vec3& offset) {
    TriangleMesh out = m;
    for (Vec3& v : out.vertices) v = v * scale + offset;
    return out;
}

// The relative pose that puts B' = s B + d where A' = s A + d puts B: x'(s v + d) = s x(v) + d.
Pose scaledPose(const Pose& x, Real scale, const Vec3& offset) {
    return Pose{x.position * scale + offset - (x.orientation * offset), x.orientation};
}

std::vector<Pose> randomPoses(std::uint64_t seed, int count, Real range) {
    cdlab_test::Rng rng(seed);
    std::vector<Pose> poses;
    for (int i = 0; i < count; ++i) poses.push_back(Pose{rng.vec(-range, range), rng.rotation()});
    return poses;
}

using cdlab_test::torusA;
using cdlab_test::torusB;

const std::vector<Pose>& differentialPoses() {
    static const std::vector<Pose> poses = randomPoses(4242, 16, 2.0);
    return poses;
}
// Brute-force answers, computed once and shared by every volume type.
const std::vector<TrianglePair>& bruteAnswer(std::size_t pose) {
    static std::map<std::size_t, std::vector<TrianglePair>> cache;
    auto it = cache.find(pose);
    if (it == cache.end()) {
        it = cache
                 .emplace(pose, collision::intersectMeshMeshBruteForce(torusA(), torusB(),
                                                                       differentialPoses()[pose]))
                 .first;
    }
    return it->second;
}

template <class BV>
class BvhTyped : public ::testing::Test {};
TYPED_TEST_SUITE(BvhTyped, BvhVolumeTestTypes, BvhVolumeTestName);

TYPED_TEST(BvhTyped, EveryFittedVolumeContainsItsTriangles) {
    for (const BvhSplit split : {BvhSplit::Median, BvhSplit::Mean}) {
        for (const int leaf : {1, 4}) {
            const BvhBuildOptions options{split, leaf};
            for (const TriangleMesh* mesh : {&torusA(), &torusB()}) {
                const Bvh<TypeParam> tree(*mesh, options);
                std::string error;
                EXPECT_TRUE(tree.validate(&error)) << error;
                EXPECT_EQ(tree.triangleCount(), static_cast<int>(mesh->triangles.size()));
                if (leaf == 1) {
                    EXPECT_EQ(tree.nodes().size(), 2 * mesh->triangles.size() - 1);
                }
            }
        }
    }
    // Far from the origin and at extreme scales the fits must still contain their corners.
    for (const Real scale : {Real(1e-4), Real(1), Real(1e4)}) {
        const Bvh<TypeParam> tree(transformed(torusB(), scale, Vec3(1e6, -1e6, 1e6)));
        std::string error;
        EXPECT_TRUE(tree.validate(&error)) << "scale " << scale << ": " << error;
    }
    const Bvh<TypeParam> median(torusA());
    EXPECT_EQ(median.depth(), 12);  // ceil(log2 1536) + 1
}

TYPED_TEST(BvhTyped, AllPairsMatchBruteForceAtRandomPoses) {
    const Bvh<TypeParam> a(torusA());
    const Bvh<TypeParam> b(torusB());
    int colliding = 0;
    for (std::size_t k = 0; k < differentialPoses().size(); ++k) {
        const Pose& pose = differentialPoses()[k];
        BvhQueryStats all;
        BvhQueryStats first;
        const std::vector<TrianglePair> pairs = collision::intersectBvhBvh(a, b, pose, &all);
        const bool hit = collision::testBvhBvh(a, b, pose, &first);
        EXPECT_EQ(pairs, bruteAnswer(k)) << "pose " << k;
        EXPECT_EQ(hit, !pairs.empty()) << "pose " << k;
        EXPECT_LE(first.triangle_tests, all.triangle_tests);
        EXPECT_GT(all.bv_tests, 0);
        colliding += hit ? 1 : 0;
    }
    // Both outcomes must occur, or the test could not fail.
    EXPECT_GE(colliding, 4);
    EXPECT_LE(colliding, 12);
}

// A deformed torus A: radial waves and a twist about z, large enough to move triangles by more
// than their leaves' sizes.
TriangleMesh deformedTorusA() {
    TriangleMesh m = torusA();
    for (Vec3& v : m.vertices) {
        const Real angle = std::atan2(v.y(), v.x());
        const Real k = 1 + Real(0.25) * std::sin(3 * angle);
        const Real twist = Real(0.4) * v.z();
        const Vec3 w(v.x() * k, v.y() * k, v.z() * (1 + Real(0.5) * std::cos(2 * angle)));
        v = Vec3(w.x() * std::cos(twist) - w.y() * std::sin(twist),
                 w.x() * std::sin(twist) + w.y() * std::cos(twist), w.z());
    }
    return m;
}

TYPED_TEST(BvhTyped, RefitGivesTheRebuildsAnswers) {
    const TriangleMesh deformed = deformedTorusA();
    Bvh<TypeParam> refitted(torusA());
    EXPECT_EQ(refitted.refit(deformed), static_cast<std::int32_t>(refitted.nodes().size()));
    std::string error;
    EXPECT_TRUE(refitted.validate(&error)) << error;  // every volume contains the moved triangles
    const Bvh<TypeParam> rebuilt(deformed);
    const Bvh<TypeParam> b(torusB());
    int changed = 0;
    for (std::size_t k = 0; k < differentialPoses().size(); ++k) {
        const Pose& pose = differentialPoses()[k];
        const std::vector<TrianglePair> expected =
            collision::intersectMeshMeshBruteForce(deformed, torusB(), pose);
        EXPECT_EQ(collision::intersectBvhBvh(refitted, b, pose), expected) << "pose " << k;
        EXPECT_EQ(collision::intersectBvhBvh(rebuilt, b, pose), expected) << "pose " << k;
        EXPECT_EQ(collision::testBvhBvh(refitted, b, pose), !expected.empty()) << "pose " << k;
        changed += expected != bruteAnswer(k);
    }
    // The deformation changes most answers, so a refit that did nothing would fail above.
    EXPECT_GE(changed, 5);
    // Through the run-time interface too.
    auto tree = collision::buildMeshBvh(BvName<TypeParam>::value, torusA());
    EXPECT_GT(tree->refit(deformed), 0);
    const auto tree_b = collision::buildMeshBvh(BvName<TypeParam>::value, torusB());
    EXPECT_EQ(tree->intersect(*tree_b, differentialPoses()[0]),
              collision::intersectMeshMeshBruteForce(deformed, torusB(), differentialPoses()[0]));
}

// One mesh made of torus A and torus B placed by `pose`: its self-intersections are the pairs
// between the two parts (plus none inside a torus, whose neighbours share vertices).
TriangleMesh unionMesh(const Pose& pose) {
    TriangleMesh m = torusA();
    const auto offset = static_cast<std::int32_t>(m.vertices.size());
    for (const Vec3& v : torusB().vertices) m.vertices.push_back(pose.apply(v));
    for (const auto& t : torusB().triangles) {
        m.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    }
    return m;
}

// Brute-force self pairs of unionMesh(pose k), computed once for every volume type.
const std::vector<TrianglePair>& bruteSelfAnswer(std::size_t k) {
    static std::map<std::size_t, std::vector<TrianglePair>> cache;
    auto it = cache.find(k);
    if (it == cache.end()) {
        it = cache.emplace(k, collision::intersectSelfBruteForce(unionMesh(differentialPoses()[k])))
                 .first;
    }
    return it->second;
}

TYPED_TEST(BvhTyped, SelfCollisionMatchesBruteForce) {
    int non_empty = 0;
    for (std::size_t k = 0; k < 6; ++k) {
        const TriangleMesh mesh = unionMesh(differentialPoses()[k]);
        const Bvh<TypeParam> tree(mesh);
        BvhQueryStats stats;
        const std::vector<TrianglePair>& brute = bruteSelfAnswer(k);
        EXPECT_EQ(collision::intersectSelf(tree, &stats), brute) << "pose " << k;
        EXPECT_GT(stats.bv_tests, 0);
        non_empty += !brute.empty();
        // Fat leaves hold adjacent triangles together: still excluded.
        const Bvh<TypeParam> fat(mesh, BvhBuildOptions{BvhSplit::Mean, 4});
        EXPECT_EQ(collision::intersectSelf(fat), brute) << "pose " << k;
    }
    EXPECT_GE(non_empty, 2);
    EXPECT_LE(non_empty, 5);
    // A closed torus alone: every touching pair is adjacent (shares a vertex).
    EXPECT_TRUE(collision::intersectSelfBruteForce(torusA()).empty());
    EXPECT_TRUE(collision::intersectSelf(Bvh<TypeParam>(torusA())).empty());
    // A grid cube with a copy of one face's triangle pushed through the cube: it crosses the
    // faces it passes through, and the pairs come out as the brute force's.
    TriangleMesh cube = cdlab_test::makeGridCubeMesh(2);
    const auto base = static_cast<std::int32_t>(cube.vertices.size());
    cube.vertices.push_back(Vec3(-1.5, 0.1, 0.2));
    cube.vertices.push_back(Vec3(1.5, 0.3, -0.1));
    cube.vertices.push_back(Vec3(0.2, 1.5, 0.3));
    cube.triangles.push_back({base, base + 1, base + 2});
    const auto brute = collision::intersectSelfBruteForce(cube);
    EXPECT_FALSE(brute.empty());
    EXPECT_EQ(collision::intersectSelf(Bvh<TypeParam>(cube)), brute);
    auto runtime = collision::buildMeshBvh(BvName<TypeParam>::value, cube);
    EXPECT_EQ(runtime->intersectSelf(), brute);
}

// Small tori for the distance brute force (256 and 196 triangles).
const TriangleMesh& smallTorusA() {
    static const TriangleMesh m = cdlab_test::makeTorusMesh(1.0, 0.35, 16, 8);
    return m;
}
const TriangleMesh& smallTorusB() {
    static const TriangleMesh m = cdlab_test::makeTorusMesh(0.8, 0.3, 14, 7);
    return m;
}
const std::vector<Pose>& distancePoses() {
    static const std::vector<Pose> poses = randomPoses(777, 12, 3.0);
    return poses;
}

// The brute force once per (scale, pose), shared by every volume type.
const collision::MeshDistance& bruteDistance(Real scale, std::size_t pose_index,
                                             const TriangleMesh& a, const TriangleMesh& b,
                                             const Pose& pose) {
    static std::map<std::pair<Real, std::size_t>, collision::MeshDistance> cache;
    const auto key = std::make_pair(scale, pose_index);
    auto it = cache.find(key);
    if (it == cache.end()) {
        it = cache.emplace(key, collision::distanceMeshMeshBruteForce(a, b, pose)).first;
    }
    return it->second;
}

TYPED_TEST(BvhTyped, DistanceMatchesBruteForceWithWitnesses) {
    int separated = 0;
    int touching = 0;
    // Under CDLAB_TEST_SCALE the first poses only (the brute force dominates); at least 6 of the
    // 12 keep both outcomes at every scale.
    const std::size_t pose_count = static_cast<std::size_t>(cdlab_test::scaled(12, 6));
    ASSERT_LE(pose_count, distancePoses().size());
    for (const Real scale : {Real(1), Real(1e-4), Real(1e4)}) {
        const Vec3 offset = scale == 1 ? Vec3(Vec3::Zero()) : Vec3(Vec3(1e6, -1e6, 1e6) * scale);
        const TriangleMesh ma = transformed(smallTorusA(), scale, offset);
        const TriangleMesh mb = transformed(smallTorusB(), scale, offset);
        const Bvh<TypeParam> a(ma);
        const Bvh<TypeParam> b(mb);
        const Real tol = Real(1e-9) * scale;  // relative to the meshes' size
        for (std::size_t pose_index = 0; pose_index < pose_count; ++pose_index) {
            const Pose& p0 = distancePoses()[pose_index];
            const Pose pose = scaledPose(p0, scale, offset);
            BvhQueryStats stats;
            const collision::MeshDistance fast = collision::distanceBvhBvh(a, b, pose, &stats);
            const collision::MeshDistance& brute = bruteDistance(
                scale, static_cast<std::size_t>(&p0 - &distancePoses()[0]), ma, mb, pose);
            ASSERT_GE(fast.a, 0);
            ASSERT_GE(fast.b, 0);
            EXPECT_NEAR(fast.distance, brute.distance, tol);
            // The witnesses are points of the witness triangles, as far apart as reported.
            EXPECT_NEAR((fast.point_on_a - fast.point_on_b).norm(), fast.distance, tol);
            const auto& ta = ma.triangles[static_cast<std::size_t>(fast.a)];
            const auto& tb = mb.triangles[static_cast<std::size_t>(fast.b)];
            std::array<Vec3, 3> corners_b;
            for (std::size_t k = 0; k < 3; ++k) {
                corners_b[k] =
                    pose.orientation * mb.vertices[static_cast<std::size_t>(tb[k])] + pose.position;
            }
            const Vec3 na = (ma.vertices[ta[1]] - ma.vertices[ta[0]])
                                .cross(ma.vertices[ta[2]] - ma.vertices[ta[0]])
                                .normalized();
            const Vec3 nb =
                (corners_b[1] - corners_b[0]).cross(corners_b[2] - corners_b[0]).normalized();
            EXPECT_NEAR(na.dot(fast.point_on_a - ma.vertices[ta[0]]), 0, tol);
            EXPECT_NEAR(nb.dot(fast.point_on_b - corners_b[0]), 0, tol);
            if (brute.distance > 0) {
                ++separated;
                EXPECT_GT(stats.bv_tests, 0);
            } else {
                ++touching;
            }
        }
    }
    EXPECT_GE(separated, cdlab_test::scaled(9, 3));
    EXPECT_GE(touching, cdlab_test::scaled(9, 3));
    // Closed form: grid cubes a gap g apart along x; witnesses on the facing faces.
    const TriangleMesh cube = cdlab_test::makeGridCubeMesh(2);
    const Bvh<TypeParam> tree(cube);
    for (const Real g : {Real(0.25), Real(1e-3), Real(0)}) {
        const collision::MeshDistance d =
            collision::distanceBvhBvh(tree, tree, Pose{Vec3(2 + g, 0.3, -0.2), Quat::Identity()});
        EXPECT_NEAR(d.distance, g, 1e-12);
        EXPECT_NEAR(d.point_on_a.x(), 1, 1e-12);
        EXPECT_NEAR(d.point_on_b.x(), 1 + g, 1e-12);
    }
    auto runtime = collision::buildMeshBvh(BvName<TypeParam>::value, cube);
    EXPECT_NEAR(runtime->distance(*runtime, Pose{Vec3(0, 2.5, 0), Quat::Identity()}).distance, 0.5,
                1e-12);
}

TYPED_TEST(BvhTyped, BottomUpBuildGivesTheBruteForceAnswers) {
    for (const int leaf : {1, 3}) {
        const BvhBuildOptions options{BvhSplit::Median, leaf, collision::BvhBuild::BottomUp};
        const Bvh<TypeParam> a(torusA(), options);
        const Bvh<TypeParam> b(torusB(), options);
        std::string error;
        EXPECT_TRUE(a.validate(&error)) << error;
        EXPECT_TRUE(b.validate(&error)) << error;
        if (leaf == 1) {
            EXPECT_EQ(a.nodes().size(), 2 * torusA().triangles.size() - 1);
        }
        // Not the top-down tree in disguise: another structure.
        const Bvh<TypeParam> top(torusA(), BvhBuildOptions{BvhSplit::Median, leaf});
        bool differs = top.nodes().size() != a.nodes().size();
        for (std::size_t i = 0; !differs && i < a.nodes().size(); ++i) {
            differs =
                top.nodes()[i].right != a.nodes()[i].right ||
                top.leafTriangleId(static_cast<std::int32_t>(i % torusA().triangles.size())) !=
                    a.leafTriangleId(static_cast<std::int32_t>(i % torusA().triangles.size()));
        }
        EXPECT_TRUE(differs);
        for (std::size_t k = 0; k < differentialPoses().size(); ++k) {
            const Pose& pose = differentialPoses()[k];
            EXPECT_EQ(collision::intersectBvhBvh(a, b, pose), bruteAnswer(k)) << "pose " << k;
            EXPECT_EQ(collision::testBvhBvh(a, b, pose), !bruteAnswer(k).empty()) << "pose " << k;
        }
    }
    // Deterministic: two builds give the same nodes.
    const BvhBuildOptions options{BvhSplit::Median, 1, collision::BvhBuild::BottomUp};
    const Bvh<TypeParam> x(torusB(), options);
    const Bvh<TypeParam> y(torusB(), options);
    ASSERT_EQ(x.nodes().size(), y.nodes().size());
    for (std::size_t i = 0; i < x.nodes().size(); ++i) {
        EXPECT_EQ(x.nodes()[i].right, y.nodes()[i].right);
        EXPECT_EQ(x.nodes()[i].first, y.nodes()[i].first);
        EXPECT_EQ(x.nodes()[i].cost, y.nodes()[i].cost);
    }
}

TYPED_TEST(BvhTyped, MeanSplitAndFatLeavesGiveTheSameAnswer) {
    const Bvh<TypeParam> a(torusA(), BvhBuildOptions{BvhSplit::Mean, 4});
    const Bvh<TypeParam> b(torusB(), BvhBuildOptions{BvhSplit::Mean, 3});
    for (std::size_t k = 0; k < 6; ++k) {
        EXPECT_EQ(collision::intersectBvhBvh(a, b, differentialPoses()[k]), bruteAnswer(k));
    }
}

// Touching and coplanar cases on an exactly representable cube (8 x 8 squares per face):
//   identical pose: every triangle touches itself and its neighbours;
//   +2 along x:     the faces x = 1 of A and x = -1 of B coincide (coplanar, face to face);
//   +2, +1/8, +1/8: the same faces with the grids offset by half a cell (crossing edges);
//   +2, +2, 0:      the cubes share only an edge line; +2, +2, +2: only a corner.
TYPED_TEST(BvhTyped, TouchingAndCoplanarPosesMatchBruteForce) {
    const TriangleMesh cube = cdlab_test::makeGridCubeMesh(8);
    const Bvh<TypeParam> tree(cube);
    const Quat quarter_turn(std::cos(std::numbers::pi_v<Real> / 4),
                            std::sin(std::numbers::pi_v<Real> / 4), 0, 0);
    const std::vector<Pose> poses = {
        Pose{},
        Pose{Vec3(2, 0, 0), Quat::Identity()},
        Pose{Vec3(2, 0.125, 0.125), Quat::Identity()},
        Pose{Vec3(2, 2, 0), Quat::Identity()},
        Pose{Vec3(2, 2, 2), Quat::Identity()},
        Pose{Vec3(2, 0, 0), quarter_turn},             // rotated: touching up to the rounding of R
        Pose{Vec3(2 + 1e-9, 0, 0), Quat::Identity()},  // a hair apart
    };
    for (std::size_t k = 0; k < poses.size(); ++k) {
        const auto brute = collision::intersectMeshMeshBruteForce(cube, cube, poses[k]);
        EXPECT_EQ(collision::intersectBvhBvh(tree, tree, poses[k]), brute) << "pose " << k;
        EXPECT_EQ(collision::testBvhBvh(tree, tree, poses[k]), !brute.empty()) << "pose " << k;
        if (k <= 4) {
            EXPECT_FALSE(brute.empty()) << "pose " << k;
        }
        if (k == 6) {
            EXPECT_TRUE(brute.empty());
        }
    }
    // Two copies of a torus at the identical pose.
    const Bvh<TypeParam> torus(torusB());
    EXPECT_EQ(collision::intersectBvhBvh(torus, torus, Pose{}),
              collision::intersectMeshMeshBruteForce(torusB(), torusB(), Pose{}));
}

// Metamorphic: move both meshes 1e6 away and scale them by 1e-4 and 1e4. The BVH must still
// equal brute force on the moved scene exactly, and (these poses being generic, with no contact
// within rounding of touching) give the original pair list.
TYPED_TEST(BvhTyped, TranslatedAndScaledScenesGiveTheSameAnswer) {
    const TriangleMesh small_a = cdlab_test::makeTorusMesh(1.0, 0.35, 24, 12);
    const TriangleMesh small_b = cdlab_test::makeTorusMesh(0.8, 0.3, 20, 10);
    const std::vector<Pose> poses = randomPoses(100, 6, 1.6);
    int colliding = 0;
    for (const Real scale : {Real(1), Real(1e-4), Real(1e4)}) {
        const Vec3 offset = Vec3(1e6, -2e6, 0.5e6) * scale;
        const TriangleMesh ma = transformed(small_a, scale, offset);
        const TriangleMesh mb = transformed(small_b, scale, offset);
        const Bvh<TypeParam> a(ma);
        const Bvh<TypeParam> b(mb);
        for (const Pose& pose : poses) {
            const Pose moved = scaledPose(pose, scale, offset);
            const auto pairs = collision::intersectBvhBvh(a, b, moved);
            EXPECT_EQ(pairs, collision::intersectMeshMeshBruteForce(ma, mb, moved))
                << "scale " << scale;
            EXPECT_EQ(pairs, collision::intersectMeshMeshBruteForce(small_a, small_b, pose))
                << "scale " << scale;
            colliding += pairs.empty() ? 0 : 1;
        }
    }
    // Both outcomes at every scale (the pair lists are equal across scales, so 3 times the
    // count at scale 1), or equal empty lists could pass.
    EXPECT_GE(colliding, 3 * 2);
    EXPECT_LE(colliding, 3 * 4);
}

// Real-size meshes (10k+ triangles): two 10k-triangle tori and a grid cube of 32 x 32 squares a
// face (12288 triangles). The reference is the sweep form of the brute force
// (intersectMeshMeshSweep: the same boxes and exact tests, so the same list; checked equal to the
// brute force on these kinds of pose in SweepReferenceEqualsBruteForce), computed once per pose
// and shared by every volume type.
const TriangleMesh& bigTorusA() {
    static const TriangleMesh m = cdlab_test::makeTorusMesh(1.0, 0.35, 100, 50);
    return m;
}
const TriangleMesh& bigTorusB() {
    static const TriangleMesh m = cdlab_test::makeTorusMesh(0.9, 0.3, 100, 50);
    return m;
}
const TriangleMesh& bigCube() {
    static const TriangleMesh m = cdlab_test::makeGridCubeMesh(32);
    return m;
}

// A rotation by `angle` about x: it keeps x exact (R row 0 is (1, 0, 0) in floating point too),
// so a face x = const stays exactly in its plane.
Quat aboutX(Real angle) { return Quat(std::cos(angle / 2), std::sin(angle / 2), 0, 0); }

enum class LargeMeshes { Tori, Cubes };
struct LargeCase {
    LargeMeshes meshes;
    Pose pose;
    std::vector<TrianglePair> expected;
};
struct LargeGroup {
    std::string name;
    std::vector<LargeCase> cases;
    int colliding = 0;
};

// Four groups of poses:
//   random:   the tori, B's centre uniform in [-1.8, 1.8]^3, uniform rotation;
//   cubes:    the cube against itself, centre uniform in [-3, 3]^3, uniform rotation;
//   touching: the cubes face to face at x = 1 (grids aligned; offset by half a cell; B turned a
//             quarter about x), edge to edge, corner to corner, and a hair apart;
//   coplanar: face x = 1 of A against face x = -1 of B moved to x = 1, B turned about x by a
//             random angle and slid in the face's plane by up to 3.5 in y and z.
const std::vector<LargeGroup>& largeGroups() {
    static const std::vector<LargeGroup> groups = [] {
        std::vector<LargeGroup> g(4);
        g[0].name = "random tori";
        for (const Pose& p : randomPoses(7, 6, 1.8))
            g[0].cases.push_back({LargeMeshes::Tori, p, {}});
        g[1].name = "random cubes";
        for (const Pose& p : randomPoses(8, 4, 3.0))
            g[1].cases.push_back({LargeMeshes::Cubes, p, {}});
        g[2].name = "touching cubes";
        const Real half_cell = Real(1) / 32;  // cells are 2/32 wide: exact offsets
        for (const Pose& p :
             {Pose{Vec3(2, 0, 0), Quat::Identity()},
              Pose{Vec3(2, half_cell, half_cell), Quat::Identity()},
              Pose{Vec3(2, 0, 0), aboutX(std::numbers::pi_v<Real> / 2)},
              Pose{Vec3(2, 2, 0), Quat::Identity()}, Pose{Vec3(2, 2, 2), Quat::Identity()},
              Pose{Vec3(2 + 1e-9, 0, 0), Quat::Identity()}}) {
            g[2].cases.push_back({LargeMeshes::Cubes, p, {}});
        }
        g[3].name = "coplanar cubes";
        cdlab_test::Rng rng(31);
        for (int i = 0; i < 6; ++i) {
            const Vec3 slide(2, rng.uniform(-3.5, 3.5), rng.uniform(-3.5, 3.5));
            const Real angle = rng.uniform(0, 2 * std::numbers::pi_v<Real>);
            g[3].cases.push_back({LargeMeshes::Cubes, Pose{slide, aboutX(angle)}, {}});
        }
        for (LargeGroup& group : g) {
            for (LargeCase& c : group.cases) {
                c.expected =
                    c.meshes == LargeMeshes::Tori
                        ? collision::intersectMeshMeshSweep(bigTorusA(), bigTorusB(), c.pose)
                        : collision::intersectMeshMeshSweep(bigCube(), bigCube(), c.pose);
                group.colliding += c.expected.empty() ? 0 : 1;
            }
        }
        return g;
    }();
    return groups;
}

TYPED_TEST(BvhTyped, LargeMeshesMatchBruteForceAtRandomTouchingAndCoplanarPoses) {
    ASSERT_EQ(bigTorusA().triangles.size(), 10000u);
    ASSERT_EQ(bigTorusB().triangles.size(), 10000u);
    ASSERT_EQ(bigCube().triangles.size(), 12288u);
    const Bvh<TypeParam> torus_a(bigTorusA());
    const Bvh<TypeParam> torus_b(bigTorusB());
    const Bvh<TypeParam> cube(bigCube());
    EXPECT_TRUE(torus_a.validate());
    EXPECT_TRUE(cube.validate());
    for (const LargeGroup& group : largeGroups()) {
        for (std::size_t k = 0; k < group.cases.size(); ++k) {
            const LargeCase& c = group.cases[k];
            const Bvh<TypeParam>& a = c.meshes == LargeMeshes::Tori ? torus_a : cube;
            const Bvh<TypeParam>& b = c.meshes == LargeMeshes::Tori ? torus_b : cube;
            EXPECT_EQ(collision::intersectBvhBvh(a, b, c.pose), c.expected)
                << group.name << " pose " << k;
            EXPECT_EQ(collision::testBvhBvh(a, b, c.pose), !c.expected.empty())
                << group.name << " pose " << k;
        }
    }
    // Each random group hits both outcomes (or the comparison could pass on empty lists); the
    // touching poses all touch except the last, a hair apart.
    const auto& g = largeGroups();
    EXPECT_GE(g[0].colliding, 2);
    EXPECT_LE(g[0].colliding, 4);
    EXPECT_GE(g[1].colliding, 1);
    EXPECT_LE(g[1].colliding, 3);
    EXPECT_EQ(g[2].colliding, 5);
    EXPECT_TRUE(g[2].cases.back().expected.empty());
    EXPECT_GE(g[3].colliding, 2);
    EXPECT_LE(g[3].colliding, 4);
}

// Swapping A and B mirrors the answer: the pairs of (b, a) under the inverse pose, each swapped,
// are the pairs of (a, b). Generic random poses (no contact within rounding of touching) and
// exactly representable touching poses, where the inverse pose is exact too.
TYPED_TEST(BvhTyped, SwappingTheMeshesMirrorsThePairs) {
    const Bvh<TypeParam> a(torusA());
    const Bvh<TypeParam> b(torusB());
    auto mirrored = [](std::vector<TrianglePair> pairs) {
        for (TrianglePair& p : pairs) std::swap(p.a, p.b);
        std::sort(pairs.begin(), pairs.end());
        return pairs;
    };
    int colliding = 0;
    for (std::size_t k = 0; k < differentialPoses().size(); ++k) {
        const Pose& pose = differentialPoses()[k];
        const std::vector<TrianglePair> swapped =
            mirrored(collision::intersectBvhBvh(b, a, pose.inverse()));
        EXPECT_EQ(swapped, bruteAnswer(k)) << "pose " << k;
        EXPECT_EQ(collision::testBvhBvh(b, a, pose.inverse()), !bruteAnswer(k).empty())
            << "pose " << k;
        colliding += bruteAnswer(k).empty() ? 0 : 1;
    }
    EXPECT_GE(colliding, 4);
    EXPECT_LE(colliding, 12);
    // Touching grid cubes of different sizes (exact coordinates): face, edge and corner contact.
    const TriangleMesh big = transformed(cdlab_test::makeGridCubeMesh(4), 2, Vec3::Zero());
    const TriangleMesh small = cdlab_test::makeGridCubeMesh(8);
    const Bvh<TypeParam> tree_big(big);
    const Bvh<TypeParam> tree_small(small);
    for (const Vec3& d : {Vec3(3, 0.5, 0.25), Vec3(3, 3, 0), Vec3(3, 3, 3), Vec3(0, -3, 0.5)}) {
        const Pose pose{d, Quat::Identity()};
        const auto expected = collision::intersectMeshMeshBruteForce(big, small, pose);
        EXPECT_FALSE(expected.empty()) << d.transpose();
        EXPECT_EQ(collision::intersectBvhBvh(tree_big, tree_small, pose), expected);
        EXPECT_EQ(mirrored(collision::intersectBvhBvh(tree_small, tree_big, pose.inverse())),
                  expected)
            << d.transpose();
    }
}

TEST(Bvh, LookupByNameCoversTheTypeList) {
    const std::vector<std::string_view> expected = {"sphere", "aabb", "obb", "kdop6", "kdop14",
                                                    "kdop18", "kdop26", "rss", "lss", "obb4"};
    EXPECT_EQ(collision::bvhVolumeNames(), expected);
    EXPECT_EQ(collision::buildMeshBvh("lss?", torusA()), nullptr);
    const Pose pose = differentialPoses()[0];
    for (const std::string_view name : collision::bvhVolumeNames()) {
        const auto a = collision::buildMeshBvh(name, torusA());
        const auto b = collision::buildMeshBvh(name, torusB());
        ASSERT_NE(a, nullptr) << name;
        EXPECT_EQ(a->volumeName(), name);
        // The wide tree counts its wide nodes: fewer than the binary tree's.
        if (name == collision::kWideObbName) {
            EXPECT_LT(a->nodeCount(), 2 * 1536 - 1);
            EXPECT_GT(a->nodeCount(), (2 * 1536 - 1) / 4);
        } else {
            EXPECT_EQ(a->nodeCount(), 2 * 1536 - 1);
        }
        EXPECT_TRUE(a->validate());
        BvhQueryStats stats;
        EXPECT_EQ(a->intersect(*b, pose, &stats), bruteAnswer(0)) << name;
        EXPECT_EQ(a->testOverlap(*b, pose), !bruteAnswer(0).empty()) << name;
        EXPECT_GT(stats.bv_tests, 0);
    }
}

// The sample behind the measured Cv and Cp is the query's own work: recordTests gives as many
// node and triangle pairs as the query's counters, and replaying them finds what the query found.
// With one triangle per leaf every overlapping node pair either pushes two children or is a leaf
// pair with one triangle test, so the overlaps are (Nv - 1) / 2 + Np exactly.
TEST(Bvh, RecordedTestsReplayAsTheQueryMadeThem) {
    int colliding = 0;
    for (const std::string_view name : collision::bvhVolumeNames()) {
        const auto a = collision::buildMeshBvh(name, torusA());
        const auto b = collision::buildMeshBvh(name, torusB());
        if (name == collision::kWideObbName) {
            // Its node tests run four lanes at a time: nothing to record as node pairs.
            const collision::BvhTestSample sample =
                collision::recordTests(*a, *b, differentialPoses()[0]);
            EXPECT_TRUE(sample.node_pairs.empty());
            EXPECT_TRUE(sample.triangle_pairs.empty());
            continue;
        }
        for (std::size_t k = 0; k < 6; ++k) {
            const Pose& pose = differentialPoses()[k];
            BvhQueryStats stats;
            const auto pairs = a->intersect(*b, pose, &stats);
            const collision::BvhTestSample sample = collision::recordTests(*a, *b, pose);
            const auto nv = static_cast<std::int64_t>(sample.node_pairs.size());
            const auto np = static_cast<std::int64_t>(sample.triangle_pairs.size());
            EXPECT_EQ(nv, stats.bv_tests) << name << " pose " << k;
            EXPECT_EQ(np, stats.triangle_tests) << name << " pose " << k;
            EXPECT_EQ(collision::replayVolumeTests(*a, *b, pose, sample, 1), (nv - 1) / 2 + np)
                << name << " pose " << k;
            EXPECT_EQ(collision::replayVolumeTests(*a, *b, pose, sample, 3),
                      3 * ((nv - 1) / 2 + np));
            EXPECT_EQ(collision::replayTriangleTests(*a, *b, pose, sample, 1),
                      static_cast<std::int64_t>(pairs.size()))
                << name << " pose " << k;
            EXPECT_EQ(collision::replayTriangleTests(*a, *b, pose, sample, 2),
                      2 * static_cast<std::int64_t>(pairs.size()));
            colliding += pairs.empty() ? 0 : 1;
        }
        // A sample of other trees (an index past this tree's nodes) is refused, not read.
        collision::BvhTestSample bad;
        bad.node_pairs.push_back({a->nodeCount(), 0});
        EXPECT_EQ(collision::replayVolumeTests(*a, *b, Pose{}, bad, 1), -1);
        bad.triangle_pairs.push_back({0, b->triangleCount()});
        EXPECT_EQ(collision::replayTriangleTests(*a, *b, Pose{}, bad, 1), -1);
    }
    EXPECT_GT(colliding, 0);
    EXPECT_LT(colliding, 6 * 9);
}

TEST(Bvh, SweepReferenceEqualsBruteForce) {
    // Random poses of the tori, and grid cubes touching face to face, edge to edge and corner to
    // corner (exact coordinates): the sweep returns the brute force's list, with as many tests.
    int non_empty = 0;
    for (std::size_t i = 0; i < differentialPoses().size(); ++i) {
        BvhQueryStats brute_stats;
        BvhQueryStats sweep_stats;
        const Pose& p = differentialPoses()[i];
        const auto brute =
            collision::intersectMeshMeshBruteForce(torusA(), torusB(), p, &brute_stats);
        EXPECT_EQ(collision::intersectMeshMeshSweep(torusA(), torusB(), p, &sweep_stats), brute);
        EXPECT_EQ(sweep_stats.triangle_tests, brute_stats.triangle_tests);
        non_empty += !brute.empty();
    }
    EXPECT_GT(non_empty, 3);
    const TriangleMesh cube = cdlab_test::makeGridCubeMesh(4);
    for (const Vec3& d : {Vec3(2, 0, 0), Vec3(2, 2, 0), Vec3(2, 2, 2), Vec3(0, -2, 0.5)}) {
        const Pose p{d, Quat::Identity()};
        const auto brute = collision::intersectMeshMeshBruteForce(cube, cube, p);
        EXPECT_FALSE(brute.empty());
        EXPECT_EQ(collision::intersectMeshMeshSweep(cube, cube, p), brute);
    }
    // The kinds of pose the large-mesh test uses: faces flush with the grids offset by half a
    // cell, B turned about x (a quarter and a random angle: coplanar faces, crossing edges), and
    // the random cube poses.
    const TriangleMesh fine = cdlab_test::makeGridCubeMesh(8);
    std::vector<Pose> poses = {Pose{Vec3(2, 0.125, 0.125), Quat::Identity()},
                               Pose{Vec3(2, 0, 0), aboutX(std::numbers::pi_v<Real> / 2)},
                               Pose{Vec3(2, 0.7, -1.1), aboutX(Real(0.83))},
                               Pose{Vec3(2, 2.2, 0.4), aboutX(Real(2.1))}};
    for (const Pose& p : randomPoses(8, 4, 3.0)) poses.push_back(p);
    int touching = 0;
    for (std::size_t k = 0; k < poses.size(); ++k) {
        const auto brute = collision::intersectMeshMeshBruteForce(fine, fine, poses[k]);
        EXPECT_EQ(collision::intersectMeshMeshSweep(fine, fine, poses[k]), brute) << "pose " << k;
        touching += brute.empty() ? 0 : 1;
    }
    EXPECT_GE(touching, 4);
    EXPECT_LE(touching, 7);
}

TEST(Bvh, EmptyMeshHasNoContacts) {
    const TriangleMesh empty;
    const Bvh<Aabb> e(empty);
    const Bvh<Aabb> t(torusA());
    EXPECT_TRUE(e.validate());
    EXPECT_EQ(e.depth(), 0);
    EXPECT_FALSE(collision::testBvhBvh(e, t, Pose{}));
    EXPECT_TRUE(collision::intersectBvhBvh(t, e, Pose{}).empty());
}

// The BVH prunes: on a colliding pose it tests under 1 % of the triangle pairs.
TEST(Bvh, CountersShowPruning) {
    const Bvh<collision::Obb> a(torusA());
    const Bvh<collision::Obb> b(torusB());
    BvhQueryStats bvh;
    std::size_t k = 0;
    while (k < differentialPoses().size() && bruteAnswer(k).empty()) ++k;
    ASSERT_LT(k, differentialPoses().size());
    collision::intersectBvhBvh(a, b, differentialPoses()[k], &bvh);
    EXPECT_LT(bvh.triangle_tests * 100, static_cast<std::int64_t>(1536 * 1200));
    EXPECT_GE(bvh.triangle_tests, static_cast<std::int64_t>(bruteAnswer(k).size()));
}

}  // namespace
