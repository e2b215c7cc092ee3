// tests/collision/mesh_narrow_phase_test.cpp -- collide() on mesh shapes through their hierarchy,
// for every volume type, against the same shapes without one (the brute-force triangle loop):
// random poses, exactly touching poses, far from the origin and at scales 1e-4 and 1e4.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "collision/bvh/bvh.h"
#include "collision/geometry/convex_hull.h"
#include "collision/narrowphase/narrow_phase.h"
#include "test_meshes.h"
#include "test_random.h"

namespace {

using collision::CollideOutput;
using collision::ContactState;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::Shape;
using collision::TriangleMesh;
using collision::Vec3;

// The mesh scaled by `k`, as a shape with a hierarchy of the named type ("" for none).
Shape meshShape(const TriangleMesh& m, Real k, std::string_view bvh) {
    auto mesh = std::make_shared<TriangleMesh>(m);
    for (Vec3& v : mesh->vertices) v *= k;
    const collision::ConvexHullOutput hull = collision::computeConvexHull(mesh->vertices);
    EXPECT_TRUE(hull.ok) << hull.error;
    std::shared_ptr<const collision::MeshBvh> tree;
    if (!bvh.empty()) tree = collision::buildMeshBvh(bvh, *mesh);
    return Shape::triangleMesh(mesh, std::make_shared<const collision::ConvexPolytope>(hull.hull),
                               tree);
}

Pose at(const Vec3& p, const Quat& q = Quat::Identity()) { return Pose{p, q}; }

const TriangleMesh& torusA() {
    static const TriangleMesh m = cdlab_test::makeTorusMesh(1.0, 0.35, 32, 12);
    return m;
}
const TriangleMesh& torusB() {
    static const TriangleMesh m = cdlab_test::makeTorusMesh(0.8, 0.3, 28, 10);
    return m;
}
const TriangleMesh& gridCube() {
    static const TriangleMesh m = cdlab_test::makeGridCubeMesh(4);
    return m;
}

struct Tally {
    int colliding = 0;
    int penetrating = 0;
    int touching = 0;
    int total = 0;
    void add(ContactState s) {
        ++total;
        colliding += collision::isColliding(s);
        penetrating += s == ContactState::Penetrating;
        touching += s == ContactState::Touching;
    }
};

class MeshNarrowPhase : public ::testing::TestWithParam<std::string> {};

// Random poses of two tori, at scales 1, 1e-4 and 1e4 and 1e6 from the origin: the hierarchy gives
// the state of the brute-force triangle loop.
TEST_P(MeshNarrowPhase, MeshMeshMatchesBruteForceAtRandomPoses) {
    const std::string& bv = GetParam();
    for (const Real k : {Real(1), Real(1e-4), Real(1e4)}) {
        for (const Real offset : {Real(0), Real(1e6)}) {
            const Shape a = meshShape(torusA(), k, bv);
            const Shape b = meshShape(torusB(), k, bv);
            const Shape a_brute = meshShape(torusA(), k, "");
            const Shape b_brute = meshShape(torusB(), k, "");
            cdlab_test::Rng rng(1234);
            Tally tally;
            for (int n = 0; n < 60; ++n) {
                const Vec3 origin = Vec3::Constant(offset * k);
                const Pose pa = at(origin + rng.vec(-0.2, 0.2) * k, rng.rotation());
                const Pose pb = at(origin + rng.vec(-1.6, 1.6) * k, rng.rotation());
                const CollideOutput fast = collide(a, pa, b, pb);
                const CollideOutput brute = collide(a_brute, pa, b_brute, pb);
                ASSERT_EQ(fast.state, brute.state) << bv << " k=" << k << " n=" << n;
                EXPECT_EQ(collide(b, pb, a, pa).state, fast.state);
                EXPECT_GT(fast.bv_tests, 0);
                EXPECT_EQ(brute.bv_tests, 0);
                tally.add(fast.state);
            }
            EXPECT_GT(tally.colliding, tally.total * 3 / 10) << bv << " k=" << k;
            EXPECT_LT(tally.colliding, tally.total * 7 / 10) << bv << " k=" << k;
        }
    }
}

// Grid cubes translated by exact amounts: face, edge and corner contact (Touching), a hair apart
// (Separated) and overlapping (Penetrating).
TEST_P(MeshNarrowPhase, MeshMeshTouchingPosesMatchBruteForce) {
    const std::string& bv = GetParam();
    for (const Real k : {Real(1), Real(1e-4), Real(1e4)}) {
        const Shape a = meshShape(gridCube(), k, bv);
        const Shape a_brute = meshShape(gridCube(), k, "");
        struct Case {
            Vec3 offset;
            ContactState expected;
        };
        const Real gap = Real(1) / 1024;
        const std::vector<Case> cases{
            {Vec3(2, 0, 0), ContactState::Touching},
            {Vec3(2, 0.5, 0.25), ContactState::Touching},
            {Vec3(2, 2, 0), ContactState::Touching},
            {Vec3(2, 2, 2), ContactState::Touching},
            {Vec3(0, -2, 1.5), ContactState::Touching},
            {Vec3(2 + gap, 0, 0), ContactState::Separated},
            {Vec3(2, 2 + gap, 2), ContactState::Separated},
            {Vec3(1.3, 0.2, 0.1), ContactState::Penetrating},
            {Vec3(0.3, 0.35, 0.15), ContactState::Penetrating},
        };
        for (const Real offset : {Real(0), Real(1e6)}) {
            for (const Case& c : cases) {
                const Pose pa = at(Vec3::Constant(offset * k));
                const Pose pb = at(Vec3::Constant(offset * k) + c.offset * k);
                const CollideOutput fast = collide(a, pa, a, pb);
                const CollideOutput brute = collide(a_brute, pa, a_brute, pb);
                EXPECT_EQ(fast.state, brute.state)
                    << bv << " k=" << k << " " << c.offset.transpose();
                if (offset == 0) {
                    EXPECT_EQ(fast.state, c.expected)
                        << bv << " k=" << k << " " << c.offset.transpose();
                }
            }
        }
    }
}

// Every convex shape type against a torus and a grid cube at random poses, plus exact touching.
TEST_P(MeshNarrowPhase, MeshConvexMatchesBruteForce) {
    const std::string& bv = GetParam();
    std::vector<Vec3> hull_points;
    cdlab_test::Rng rng(99);
    for (int i = 0; i < 12; ++i) hull_points.push_back(rng.vec(-0.4, 0.4));
    const collision::ConvexHullOutput hull = collision::computeConvexHull(hull_points);
    ASSERT_TRUE(hull.ok);
    const std::vector<Shape> convex{
        Shape::sphere(0.3), Shape::box(Vec3(0.4, 0.2, 0.3)), Shape::capsule(0.15, 0.4),
        Shape::convexHull(std::make_shared<const collision::ConvexPolytope>(hull.hull))};
    for (const Real k : {Real(1), Real(1e-4), Real(1e4)}) {
        Tally tally;
        for (const TriangleMesh* m : {&torusA(), &gridCube()}) {
            const Shape mesh = meshShape(*m, k, bv);
            const Shape brute = meshShape(*m, k, "");
            for (const Shape& shape : convex) {
                Shape c = shape;
                c.radius *= k;
                c.half_height *= k;
                c.half_extents *= k;
                if (c.hull) {
                    auto scaled = std::make_shared<collision::ConvexPolytope>(*c.hull);
                    for (Vec3& v : scaled->vertices) v *= k;
                    c.hull = scaled;
                }
                for (int n = 0; n < 40; ++n) {
                    const Pose pm = at(rng.vec(-0.2, 0.2) * k, rng.rotation());
                    const Pose pc = at(rng.vec(-1.5, 1.5) * k, rng.rotation());
                    const CollideOutput fast = collide(mesh, pm, c, pc);
                    const CollideOutput slow = collide(brute, pm, c, pc);
                    ASSERT_EQ(fast.state, slow.state) << bv << " k=" << k << " n=" << n;
                    EXPECT_EQ(collide(c, pc, mesh, pm).state, fast.state);
                    // Both stop at the first penetrating triangle, in different orders;
                    // otherwise the hierarchy's candidates are a subset of the brute force's.
                    if (slow.state != ContactState::Penetrating) {
                        EXPECT_LE(fast.triangle_tests, slow.triangle_tests);
                    }
                    tally.add(fast.state);
                }
            }
        }
        EXPECT_GT(tally.colliding, tally.total * 2 / 10) << bv << " k=" << k;
        EXPECT_LT(tally.colliding, tally.total * 8 / 10) << bv << " k=" << k;
        // Exact contact: a box resting on the grid cube's faces, edges and corners.
        const Shape cube = meshShape(gridCube(), k, bv);
        const Shape cube_brute = meshShape(gridCube(), k, "");
        const Shape box = Shape::box(Vec3(0.5, 0.5, 0.5) * k);
        for (const Vec3& p : {Vec3(1.5, 0, 0), Vec3(1.5, 1.5, 0), Vec3(1.5, 1.5, 1.5),
                              Vec3(0, -1.5, 0.75), Vec3(1.5 + 1.0 / 512, 0, 0)}) {
            const CollideOutput fast = collide(cube, Pose{}, box, at(p * k));
            const CollideOutput slow = collide(cube_brute, Pose{}, box, at(p * k));
            EXPECT_EQ(fast.state, slow.state) << bv << " k=" << k << " " << p.transpose();
            EXPECT_EQ(fast.state, p.x() > 1.5 ? ContactState::Separated : ContactState::Touching)
                << bv << " k=" << k << " " << p.transpose();
        }
    }
}

INSTANTIATE_TEST_SUITE_P(
    EveryVolume, MeshNarrowPhase,
    ::testing::ValuesIn(std::vector<std::string>(collision::bvhVolumeNames().begin(),
                                                 collision::bvhVolumeNames().end())),
    [](const ::testing::TestParamInfo<std::string>& param) { return param.param; });

TEST(MeshShape, CarriesTheDefaultHierarchy) {
    const Shape s = meshShape(gridCube(), 1, collision::kDefaultMeshBvh);
    ASSERT_TRUE(s.bvh);
    EXPECT_EQ(s.bvh->volumeName(), collision::kDefaultMeshBvh);
    auto mesh = std::make_shared<const TriangleMesh>(gridCube());
    const Shape by_factory =
        Shape::triangleMesh(mesh, std::make_shared<const collision::ConvexPolytope>(
                                      collision::computeConvexHull(mesh->vertices).hull));
    ASSERT_TRUE(by_factory.bvh);
    EXPECT_EQ(by_factory.bvh->volumeName(), collision::kDefaultMeshBvh);
    EXPECT_EQ(by_factory.bvh->triangleCount(), static_cast<std::int32_t>(mesh->triangles.size()));
    EXPECT_TRUE(by_factory.bvh->validate());
}

// Shapes whose hierarchies cannot run one tandem traversal (different volume types, or one
// without a hierarchy) fall back to the brute-force loop: same states, no BV tests.
TEST(MeshShape, MixedOrMissingHierarchiesFallBackToBruteForce) {
    const Shape obb = meshShape(torusA(), 1, "obb");
    const Shape aabb = meshShape(torusB(), 1, "aabb");
    const Shape none = meshShape(torusB(), 1, "");
    const Shape brute_a = meshShape(torusA(), 1, "");
    cdlab_test::Rng rng(5);
    int colliding = 0;
    for (int n = 0; n < 30; ++n) {
        const Pose pa = at(rng.vec(-0.2, 0.2), rng.rotation());
        const Pose pb = at(rng.vec(-1.6, 1.6), rng.rotation());
        const CollideOutput expected = collide(brute_a, pa, none, pb);
        for (const Shape* b : {&aabb, &none}) {
            const CollideOutput out = collide(obb, pa, *b, pb);
            EXPECT_EQ(out.state, expected.state) << n;
            EXPECT_EQ(out.bv_tests, 0) << n;
        }
        colliding += collision::isColliding(expected.state);
    }
    EXPECT_GT(colliding, 5);
    EXPECT_LT(colliding, 25);
}

}  // namespace
