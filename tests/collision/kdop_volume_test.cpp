// tests/collision/kdop_volume_test.cpp -- per-body world k-DOPs and the polytope they bound:
// every vertex inside every slab, every slab plane touched (the slabs are tight), k = 6 the
// eight box corners; random shapes at the origin, far from it, tiny and huge.
#include "collision/volumes/kdop_volume.h"

#include <gtest/gtest.h>

#include <limits>
#include <memory>

#include "collision/geometry/convex_hull.h"
#include "collision/geometry/shape.h"
#include "test_meshes.h"
#include "test_random.h"

namespace {

using collision::Pose;
using collision::Real;
using collision::Shape;
using collision::Vec3;
using collision::WorldKdop;

constexpr int kKs[] = {6, 14, 18, 26};

Shape randomShape(cdlab_test::Rng& rng, int kind) {
    switch (kind) {
        case 0:
            return Shape::sphere(rng.uniform(0.1, 2));
        case 1:
            return Shape::box(rng.vec(0.1, 2));
        case 2:
            return Shape::capsule(rng.uniform(0.1, 1), rng.uniform(0.1, 2));
        default: {
            std::vector<Vec3> points;
            for (int i = 0; i < 20; ++i) points.push_back(rng.vec(-1, 1));
            collision::ConvexHullOutput h = collision::computeConvexHull(points);
            return Shape::convexHull(
                std::make_shared<const collision::ConvexPolytope>(std::move(h.hull)));
        }
    }
}

/// Every vertex within tol of every half-space; each of the k planes has a vertex within tol.
void expectTightPolytope(const WorldKdop& d, const collision::KdopPolytope& p) {
    const Real tol = collision::kdopPolytopeTolerance(d);
    ASSERT_FALSE(p.vertices.empty());
    for (int i = 0; i < d.k / 2; ++i) {
        const Vec3 n = collision::kdopSlabDirection(d.k, i);
        bool touches_min = false;
        bool touches_max = false;
        for (const Vec3& v : p.vertices) {
            ASSERT_TRUE(v.allFinite());
            const Real s = n.dot(v);
            EXPECT_LE(s, d.max[std::size_t(i)] + tol) << "k=" << d.k << " slab " << i;
            EXPECT_GE(s, d.min[std::size_t(i)] - tol) << "k=" << d.k << " slab " << i;
            touches_max = touches_max || std::abs(s - d.max[std::size_t(i)]) <= tol;
            touches_min = touches_min || std::abs(s - d.min[std::size_t(i)]) <= tol;
        }
        EXPECT_TRUE(touches_max && touches_min) << "k=" << d.k << " slab " << i << " not tight";
    }
    for (const auto& e : p.edges) {
        EXPECT_LT(e[0], e[1]);
        EXPECT_LT(std::size_t(e[1]), p.vertices.size());
    }
}

TEST(KdopVolume, RandomShapesGiveTightPolytopesAtEveryScaleAndOffset) {
    cdlab_test::Rng rng(20261126);
    const Real scales[] = {1e-4, 1, 1e4};
    const Real offsets[] = {0, 1e6};
    int checked = 0;
    for (int trial = 0; trial < 40; ++trial) {
        const Shape base = randomShape(rng, trial % 4);
        const Pose pose{rng.vec(-3, 3), rng.rotation()};
        for (const Real scale : scales) {
            for (const Real offset : offsets) {
                const Pose moved{pose.position * scale + Vec3::Constant(offset), pose.orientation};
                Shape s = base;
                if (trial % 4 == 0) s = Shape::sphere(base.radius * scale);
                if (trial % 4 == 1) s = Shape::box(base.half_extents * scale);
                if (trial % 4 == 2)
                    s = Shape::capsule(base.radius * scale, base.half_height * scale);
                if (trial % 4 == 3 && scale != 1) continue;  // hulls at scale 1 only
                for (const int k : kKs) {
                    const WorldKdop d = collision::computeWorldKdop(s, moved, k);
                    expectTightPolytope(d, collision::kdopPolytope(d));
                    ++checked;
                }
            }
        }
    }
    EXPECT_GT(checked, 300);
}

// A mesh body (a turned torus far from the origin): its k-DOP holds every vertex of the mesh in
// every slab, each slab's two planes touch a mesh vertex (the support of a mesh is its hull's,
// whose vertices are mesh vertices), and the polytope drawn from it is tight.
TEST(KdopVolume, MeshBodyHoldsEveryVertexAndTouchesEverySlabPlane) {
    auto mesh = std::make_shared<const collision::TriangleMesh>(
        cdlab_test::makeTorusMesh(1.5, 0.4, 24, 12));
    collision::ConvexHullOutput hull = collision::computeConvexHull(mesh->vertices);
    ASSERT_TRUE(hull.ok) << hull.error;
    const Shape torus = Shape::triangleMesh(
        mesh, std::make_shared<const collision::ConvexPolytope>(std::move(hull.hull)));
    cdlab_test::Rng rng(17);
    const Pose pose{Vec3(250, -40, 7), rng.rotation()};
    for (const int k : kKs) {
        const WorldKdop d = collision::computeWorldKdop(torus, pose, k);
        const Real tol = collision::kdopPolytopeTolerance(d);
        for (int i = 0; i < k / 2; ++i) {
            const Vec3 n = collision::kdopSlabDirection(k, i);
            Real lo = std::numeric_limits<Real>::infinity();
            Real hi = -lo;
            for (const Vec3& v : mesh->vertices) {
                const Real s = n.dot(pose.apply(v));
                lo = std::min(lo, s);
                hi = std::max(hi, s);
            }
            EXPECT_GE(lo, d.min[std::size_t(i)] - tol) << "k=" << k << " slab " << i;
            EXPECT_LE(hi, d.max[std::size_t(i)] + tol) << "k=" << k << " slab " << i;
            EXPECT_NEAR(lo, d.min[std::size_t(i)], tol) << "k=" << k << " slab " << i;
            EXPECT_NEAR(hi, d.max[std::size_t(i)], tol) << "k=" << k << " slab " << i;
        }
        expectTightPolytope(d, collision::kdopPolytope(d));
    }
}

TEST(KdopVolume, SixDopIsTheEightBoxCorners) {
    const Shape box = Shape::box(Vec3(1, 2, 3));
    const WorldKdop d = collision::computeWorldKdop(box, Pose{Vec3(10, -5, 2)}, 6);
    const collision::KdopPolytope p = collision::kdopPolytope(d);
    ASSERT_EQ(p.vertices.size(), 8u);
    EXPECT_EQ(p.edges.size(), 12u);
    for (int bits = 0; bits < 8; ++bits) {
        const Vec3 c(bits & 1 ? 11 : 9, bits & 2 ? -3 : -7, bits & 4 ? 5 : -1);
        const bool found = std::any_of(p.vertices.begin(), p.vertices.end(),
                                       [&](const Vec3& v) { return v == c; });
        EXPECT_TRUE(found) << c.transpose();
    }
}

TEST(KdopVolume, FourteenDopOfAnAxisAlignedCubeCutsItsCorners) {
    // A sphere of radius 1: the cube [-1,1]^3 with each corner cut by |x+y+z| <= sqrt(3), a
    // triangle per corner: 24 vertices, 36 edges (a truncated cube).
    const WorldKdop d = collision::computeWorldKdop(Shape::sphere(1), Pose{}, 14);
    const collision::KdopPolytope p = collision::kdopPolytope(d);
    EXPECT_EQ(p.vertices.size(), 24u);
    EXPECT_EQ(p.edges.size(), 36u);
    expectTightPolytope(d, p);
}

TEST(KdopVolume, FlatBodyGivesAFlatPolytopeWithoutNans) {
    // A zero-thickness box (a square in z = 4): every slab with a z component still touches it.
    const Shape flat = Shape::box(Vec3(1, 1, 0));
    for (const int k : kKs) {
        const WorldKdop d = collision::computeWorldKdop(flat, Pose{Vec3(0, 0, 4)}, k);
        const collision::KdopPolytope p = collision::kdopPolytope(d);
        expectTightPolytope(d, p);
        for (const Vec3& v : p.vertices) EXPECT_EQ(v.z(), 4);
    }
    const WorldKdop point = collision::computeWorldKdop(Shape::sphere(0), Pose{Vec3(1, 2, 3)}, 26);
    const collision::KdopPolytope p = collision::kdopPolytope(point);
    ASSERT_EQ(p.vertices.size(), 1u);
    EXPECT_EQ(p.vertices[0], Vec3(1, 2, 3));
}

TEST(KdopVolume, OverlapIsTheClosedSlabTest) {
    const Shape unit = Shape::sphere(1);
    // Two spheres 2.05 apart along (1,1,0)/sqrt2: their AABBs overlap (x and y gaps are 1.45 < 2),
    // the 18-DOP's (1,1,0) slab separates them.
    const Vec3 off = Vec3(1, 1, 0).normalized() * 2.05;
    for (const int k : kKs) {
        const WorldKdop a = collision::computeWorldKdop(unit, Pose{}, k);
        const WorldKdop b = collision::computeWorldKdop(unit, Pose{off}, k);
        const bool has_face_diagonals = k == 18 || k == 26;
        EXPECT_EQ(a.overlaps(b), !has_face_diagonals) << "k=" << k;
        EXPECT_EQ(a.overlaps(b), b.overlaps(a));
        const WorldKdop touching = collision::computeWorldKdop(unit, Pose{Vec3(2, 0, 0)}, k);
        EXPECT_TRUE(a.overlaps(touching)) << "touching counts, k=" << k;
    }
}

}  // namespace
