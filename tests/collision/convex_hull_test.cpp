// tests/collision/convex_hull_test.cpp -- quickhull: containment, orientation, topology,
// degenerate inputs, duplicates, translation far from the origin.
#include "collision/geometry/convex_hull.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace collision {
namespace {

std::vector<Vec3> cubeCorners(Real h, const Vec3& offset = Vec3::Zero()) {
    std::vector<Vec3> pts;
    for (int i = 0; i < 8; ++i) {
        pts.push_back(offset + Vec3(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h));
    }
    return pts;
}

std::vector<Vec3> spherePoints(int n, unsigned seed, Real radius = 1,
                               const Vec3& offset = Vec3::Zero()) {
    std::mt19937 rng(seed);
    std::normal_distribution<Real> g(0, 1);
    std::vector<Vec3> pts;
    while (static_cast<int>(pts.size()) < n) {
        const Vec3 v(g(rng), g(rng), g(rng));
        if (v.norm() < Real(1e-6)) continue;
        pts.push_back(offset + v.normalized() * radius);
    }
    return pts;
}

// The structural checks every hull must pass: closed 2-manifold (each directed edge once, its
// reverse once), Euler V - E + F = 2, every vertex used, every face non-degenerate and outward
// (all hull vertices on or below its plane), every input point inside within `tol`.
void expectValidHull(const ConvexPolytope& hull, const std::vector<Vec3>& input, Real tol) {
    ASSERT_GE(hull.vertices.size(), 4u);
    ASSERT_GE(hull.faces.size(), 4u);
    const auto nv = static_cast<std::int32_t>(hull.vertices.size());
    std::map<std::pair<std::int32_t, std::int32_t>, int> directed;
    std::vector<bool> used(hull.vertices.size(), false);
    for (const auto& f : hull.faces) {
        for (int e = 0; e < 3; ++e) {
            ASSERT_GE(f[e], 0);
            ASSERT_LT(f[e], nv);
            used[f[e]] = true;
            ++directed[{f[e], f[(e + 1) % 3]}];
        }
    }
    for (const auto& [edge, count] : directed) {
        EXPECT_EQ(count, 1) << "directed edge used twice";
        EXPECT_EQ(directed.count({edge.second, edge.first}), 1u) << "edge without a twin";
    }
    for (bool u : used) EXPECT_TRUE(u) << "unused hull vertex";
    const auto v = static_cast<long>(hull.vertices.size());
    const auto e = static_cast<long>(directed.size() / 2);
    const auto f = static_cast<long>(hull.faces.size());
    EXPECT_EQ(v - e + f, 2) << "Euler characteristic";

    Vec3 centroid = Vec3::Zero();
    for (const Vec3& p : hull.vertices) centroid += p;
    centroid /= Real(hull.vertices.size());
    for (const auto& face : hull.faces) {
        const Vec3& a = hull.vertices[face[0]];
        const Vec3 n = (hull.vertices[face[1]] - a).cross(hull.vertices[face[2]] - a);
        ASSERT_GT(n.norm(), 0) << "degenerate face";
        const Vec3 u = n.normalized();
        // Outward: the vertex centroid is strictly inside.
        EXPECT_LT(u.dot(centroid - a), 0);
        for (const Vec3& q : input) EXPECT_LE(u.dot(q - a), tol) << "input point outside";
    }
}

TEST(ConvexHull, TetrahedronIsItself) {
    const std::vector<Vec3> pts = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
    const ConvexHullOutput out = computeConvexHull(pts);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.hull.vertices.size(), 4u);
    EXPECT_EQ(out.hull.faces.size(), 4u);
    // Vertices are the input points, in input order.
    for (int i = 0; i < 4; ++i) EXPECT_EQ(out.hull.vertices[i], pts[i]);
    expectValidHull(out.hull, pts, 1e-12);
}

TEST(ConvexHull, CubeHasEightVerticesAndTwelveTriangles) {
    const std::vector<Vec3> pts = cubeCorners(0.5);
    const ConvexHullOutput out = computeConvexHull(pts);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.hull.vertices.size(), 8u);
    EXPECT_EQ(out.hull.faces.size(), 12u);
    expectValidHull(out.hull, pts, 1e-12);
}

// Points on the faces, edges and inside of a cube (a lattice 5x5x5) are not extreme: only the
// 8 corners may appear, even though edge midpoints can be picked as eye points on the way.
TEST(ConvexHull, CubeLatticeKeepsOnlyCorners) {
    std::vector<Vec3> pts;
    for (int i = 0; i < 5; ++i) {
        for (int j = 0; j < 5; ++j) {
            for (int k = 0; k < 5; ++k) pts.emplace_back(i * 0.25, j * 0.25, k * 0.25);
        }
    }
    const ConvexHullOutput out = computeConvexHull(pts);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.hull.vertices.size(), 8u);
    EXPECT_EQ(out.hull.faces.size(), 12u);
    expectValidHull(out.hull, pts, 1e-12);
    for (const Vec3& v : out.hull.vertices) {
        for (int a = 0; a < 3; ++a) EXPECT_TRUE(v[a] == 0 || v[a] == 1);
    }
}

TEST(ConvexHull, RandomSpherePointsAreAllVertices) {
    for (unsigned seed : {1u, 2u, 3u}) {
        const std::vector<Vec3> pts = spherePoints(500, seed);
        const ConvexHullOutput out = computeConvexHull(pts);
        ASSERT_TRUE(out.ok) << out.error;
        // Every point of a sphere is extreme.
        EXPECT_EQ(out.hull.vertices.size(), pts.size());
        EXPECT_EQ(out.hull.faces.size(), 2 * pts.size() - 4);
        expectValidHull(out.hull, pts, 1e-12);
    }
}

TEST(ConvexHull, RandomBallPointsContainedAndInteriorDropped) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<Real> u(-1, 1);
    std::vector<Vec3> pts;
    while (pts.size() < 2000) {
        const Vec3 v(u(rng), u(rng), u(rng));
        if (v.norm() <= 1) pts.push_back(v);
    }
    const ConvexHullOutput out = computeConvexHull(pts);
    ASSERT_TRUE(out.ok) << out.error;
    // Both outcomes occur: some points are vertices, most are interior.
    EXPECT_GT(out.hull.vertices.size(), 20u);
    EXPECT_LT(out.hull.vertices.size(), pts.size() / 2);
    expectValidHull(out.hull, pts, 1e-12);
}

TEST(ConvexHull, DuplicatePointsAreMerged) {
    std::vector<Vec3> pts = cubeCorners(1);
    const std::vector<Vec3> copy = pts;
    for (int r = 0; r < 3; ++r) pts.insert(pts.end(), copy.begin(), copy.end());
    pts.push_back(Vec3::Zero());
    pts.push_back(Vec3::Zero());
    const ConvexHullOutput out = computeConvexHull(pts);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.hull.vertices.size(), 8u);
    EXPECT_EQ(out.hull.faces.size(), 12u);
    expectValidHull(out.hull, pts, 1e-12);
}

// Metamorphic: a unit set 1e6 from the origin gives the same hull (tolerance follows the extent,
// not the distance from the origin).
TEST(ConvexHull, FarFromOriginSameTopology) {
    const Vec3 offset(1e6, -2e6, 3e6);
    const std::vector<Vec3> near = spherePoints(300, 11);
    std::vector<Vec3> far;
    for (const Vec3& p : near) far.push_back(p + offset);
    const ConvexHullOutput a = computeConvexHull(near);
    const ConvexHullOutput b = computeConvexHull(far);
    ASSERT_TRUE(a.ok) << a.error;
    ASSERT_TRUE(b.ok) << b.error;
    EXPECT_EQ(b.hull.vertices.size(), near.size());
    EXPECT_EQ(b.hull.faces.size(), a.hull.faces.size());
    // Rounding of the translated coordinates is ~ eps * 4e6.
    expectValidHull(b.hull, far, 1e-8);

    const ConvexHullOutput cube = computeConvexHull(cubeCorners(0.5, offset));
    ASSERT_TRUE(cube.ok) << cube.error;
    EXPECT_EQ(cube.hull.vertices.size(), 8u);
    expectValidHull(cube.hull, cubeCorners(0.5, offset), 1e-8);
}

TEST(ConvexHull, ScaleInvariantTopology) {
    const std::vector<Vec3> base = spherePoints(200, 5);
    for (Real s : {Real(1e-4), Real(1e4)}) {
        std::vector<Vec3> pts;
        for (const Vec3& p : base) pts.push_back(p * s);
        const ConvexHullOutput out = computeConvexHull(pts);
        ASSERT_TRUE(out.ok) << out.error;
        EXPECT_EQ(out.hull.vertices.size(), base.size());
        expectValidHull(out.hull, pts, 1e-12 * s);
    }
}

TEST(ConvexHull, Deterministic) {
    const std::vector<Vec3> pts = spherePoints(400, 9);
    const ConvexHullOutput a = computeConvexHull(pts);
    const ConvexHullOutput b = computeConvexHull(pts);
    ASSERT_TRUE(a.ok);
    EXPECT_EQ(a.hull.vertices, b.hull.vertices);
    EXPECT_EQ(a.hull.faces, b.hull.faces);
}

TEST(ConvexHull, TooFewPointsFail) {
    for (std::size_t n = 0; n < 4; ++n) {
        const std::vector<Vec3> few = spherePoints(static_cast<int>(n), 1);
        const ConvexHullOutput out = computeConvexHull(few);
        EXPECT_FALSE(out.ok);
        EXPECT_NE(out.error.find("at least 4"), std::string::npos) << out.error;
    }
}

TEST(ConvexHull, CoincidentCollinearCoplanarFail) {
    const std::vector<Vec3> same(6, Vec3(1, 2, 3));
    ConvexHullOutput out = computeConvexHull(same);
    EXPECT_FALSE(out.ok);
    EXPECT_FALSE(out.error.empty());

    std::vector<Vec3> line;
    for (int i = 0; i < 10; ++i) line.emplace_back(i, 2 * i, -i);
    out = computeConvexHull(line);
    EXPECT_FALSE(out.ok);
    EXPECT_NE(out.error.find("collinear"), std::string::npos) << out.error;

    std::vector<Vec3> plane;
    for (int i = 0; i < 5; ++i) {
        for (int j = 0; j < 5; ++j) plane.emplace_back(i, j, Real(0.5) * i - Real(0.25) * j);
    }
    out = computeConvexHull(plane);
    EXPECT_FALSE(out.ok);
    EXPECT_NE(out.error.find("coplanar"), std::string::npos) << out.error;

    // Coplanar far from the origin: the tolerance is relative, so 1e6 does not make it "thick".
    std::vector<Vec3> far_plane;
    for (const Vec3& p : plane) far_plane.push_back(p + Vec3(1e6, 1e6, 1e6));
    out = computeConvexHull(far_plane);
    EXPECT_FALSE(out.ok);
}

TEST(ConvexHull, NonFiniteFails) {
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    const Real inf = std::numeric_limits<Real>::infinity();
    for (Real bad : {nan, inf, -inf}) {
        std::vector<Vec3> pts = cubeCorners(1);
        pts[3].y() = bad;
        const ConvexHullOutput out = computeConvexHull(pts);
        EXPECT_FALSE(out.ok);
        EXPECT_NE(out.error.find("not finite"), std::string::npos) << out.error;
    }
}

// Random points on a few planes (many coplanar subsets, lots of near-ties) must still give a
// valid closed hull: the adversarial case for triangle-only quickhull.
TEST(ConvexHull, PointsOnCubeFacesAndEdges) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<Real> u(-1, 1);
    std::uniform_int_distribution<int> axis(0, 2);
    std::vector<Vec3> pts;
    for (int i = 0; i < 1000; ++i) {
        Vec3 p(u(rng), u(rng), u(rng));
        p[axis(rng)] = u(rng) < 0 ? -1 : 1;
        if (i % 3 == 0) p[(axis(rng) + 1) % 3] = u(rng) < 0 ? -1 : 1;
        pts.push_back(p);
    }
    const std::vector<Vec3> corners = cubeCorners(1);
    pts.insert(pts.end(), corners.begin(), corners.end());
    const ConvexHullOutput out = computeConvexHull(pts);
    ASSERT_TRUE(out.ok) << out.error;
    EXPECT_EQ(out.hull.vertices.size(), 8u);
    expectValidHull(out.hull, pts, 1e-12);
}

}  // namespace
}  // namespace collision
