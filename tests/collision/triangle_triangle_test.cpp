// tests/collision/triangle_triangle_test.cpp -- the exact predicates and the triangle-triangle
// test: hand-made touching/coplanar cases, and random integer-grid triangles (dense in touching and
// coplanar configurations) against an exact separating-axis reference.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>

// Private narrow-phase headers (collision/src is not on the test's include path).
#include "geometry/predicates.h"
#include "geometry/triangle_triangle.h"
#include "test_random.h"

namespace {

using collision::orient2d;
using collision::orient3d;
using collision::testTriangleTriangle;
using collision::Vec3;

__extension__ typedef __int128 Int128;

int sign(Int128 x) { return x > 0 ? 1 : (x < 0 ? -1 : 0); }

// Exact reference: integer coordinates below 2^30, so the determinant fits in 128 bits.
int orient3dInt(const std::array<std::int64_t, 3>& a, const std::array<std::int64_t, 3>& b,
                const std::array<std::int64_t, 3>& c, const std::array<std::int64_t, 3>& d) {
    const Int128 ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
    const Int128 vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
    const Int128 wx = d[0] - a[0], wy = d[1] - a[1], wz = d[2] - a[2];
    return sign(ux * (vy * wz - vz * wy) + uy * (vz * wx - vx * wz) + uz * (vx * wy - vy * wx));
}

Vec3 toVec(const std::array<std::int64_t, 3>& p, double unit) {
    return Vec3(double(p[0]) * unit, double(p[1]) * unit, double(p[2]) * unit);
}

TEST(Predicates, Orient3dSignIsExactOnNearlyCoplanarPoints) {
    cdlab_test::Rng rng(7);
    int zeros = 0;
    int nonzeros = 0;
    for (int n = 0; n < 20000; ++n) {
        std::array<std::int64_t, 3> a{}, b{}, c{};
        for (int k = 0; k < 3; ++k) {
            a[k] = rng.integer(-(1 << 28), 1 << 28);
            b[k] = rng.integer(-(1 << 28), 1 << 28);
            c[k] = rng.integer(-(1 << 28), 1 << 28);
        }
        // d = a + 3 (b - a) - 2 (c - a) + tiny: on the plane or one unit off it.
        std::array<std::int64_t, 3> d{};
        for (int k = 0; k < 3; ++k) d[k] = a[k] + 3 * (b[k] - a[k]) - 2 * (c[k] - a[k]);
        d[rng.integer(0, 2)] += rng.integer(-1, 1);
        const int expected = orient3dInt(a, b, c, d);
        (expected == 0 ? zeros : nonzeros) += 1;
        // Power-of-two units keep the values exact; 2^-40 makes them non-integers.
        for (const double unit : {1.0, std::ldexp(1.0, -40)}) {
            ASSERT_EQ(orient3d(toVec(a, unit), toVec(b, unit), toVec(c, unit), toVec(d, unit)),
                      expected)
                << n;
        }
    }
    EXPECT_GT(zeros, 1000);
    EXPECT_GT(nonzeros, 1000);
}

TEST(Predicates, Orient2dSignIsExactOnNearlyCollinearPoints) {
    // Shewchuk's classic failure: points near the line y = x, one ulp apart.
    const double base = 0.5;
    const double ulp = std::ldexp(1.0, -53);
    int positives = 0;
    int negatives = 0;
    int zeros = 0;
    for (int i = 0; i < 64; ++i) {
        for (int j = 0; j < 64; ++j) {
            const double px = base + i * ulp;
            const double py = base + j * ulp;
            // Exactly 12 (py - px): the sign of j - i. Naive doubles get many of these wrong.
            const int s = orient2d(px, py, 12, 12, 24, 24);
            const int expected = (j > i) - (j < i);
            ASSERT_EQ(s, expected) << i << " " << j;
            (s > 0 ? positives : (s < 0 ? negatives : zeros)) += 1;
        }
    }
    EXPECT_GT(positives, 0);
    EXPECT_GT(negatives, 0);
    EXPECT_EQ(zeros, 64);
}

// ---- Hand-made cases. ----

struct Tri {
    Vec3 p, q, r;
};

// Every vertex order of both triangles and both argument orders must agree.
bool intersectAllOrders(const Tri& t1, const Tri& t2, bool expected) {
    const std::array<std::array<int, 3>, 6> perms{
        {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}}};
    const std::array<Vec3, 3> v1{t1.p, t1.q, t1.r};
    const std::array<Vec3, 3> v2{t2.p, t2.q, t2.r};
    for (const auto& a : perms) {
        for (const auto& b : perms) {
            const bool x =
                testTriangleTriangle(v1[a[0]], v1[a[1]], v1[a[2]], v2[b[0]], v2[b[1]], v2[b[2]]);
            const bool y =
                testTriangleTriangle(v2[b[0]], v2[b[1]], v2[b[2]], v1[a[0]], v1[a[1]], v1[a[2]]);
            if (x != expected || y != expected) return false;
        }
    }
    return true;
}

TEST(TriangleTriangle, CrossingAndSeparated) {
    const Tri t1{Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0)};
    EXPECT_TRUE(
        intersectAllOrders(t1, {Vec3(0.5, 0.5, -1), Vec3(0.5, 0.5, 1), Vec3(3, 3, 0.5)}, true));
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(5, 5, -1), Vec3(5, 5, 1), Vec3(6, 6, 0)}, false));
    // Plane crossing but beside the triangle (the line of intersection misses it).
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(3, -1, -1), Vec3(3, 3, -1), Vec3(3, 1, 1)}, false));
}

TEST(TriangleTriangle, CoplanarOverlapTouchAndMiss) {
    const Tri t1{Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 0)};
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(1, 1, 0), Vec3(5, 1, 0), Vec3(1, 5, 0)}, true));
    // Contained.
    EXPECT_TRUE(
        intersectAllOrders(t1, {Vec3(0.5, 0.5, 0), Vec3(1, 0.5, 0), Vec3(0.5, 1, 0)}, true));
    // Shared edge, triangles on opposite sides.
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(4, 0, 0), Vec3(0, 4, 0), Vec3(4, 4, 0)}, true));
    // Shared vertex only.
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(4, 0, 0), Vec3(6, 0, 0), Vec3(6, 1, 0)}, true));
    // Vertex on the other's edge.
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(2, 2, 0), Vec3(5, 3, 0), Vec3(3, 5, 0)}, true));
    // Near miss: the same, moved off the hypotenuse by one ulp of 2.
    const double off = std::nextafter(2.0, 3.0);
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(off, off, 0), Vec3(5, 3, 0), Vec3(3, 5, 0)}, false));
}

TEST(TriangleTriangle, NonCoplanarTouching) {
    const Tri t1{Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 0)};
    // A vertex resting on the interior of t1.
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(1, 1, 0), Vec3(1, 1, 3), Vec3(2, 0.5, 3)}, true));
    // A vertex on t1's edge, the rest above.
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(2, 0, 0), Vec3(2, -1, 3), Vec3(3, 1, 3)}, true));
    // Edge lying on t1's edge (hinge).
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 0, 4)}, true));
    // Shared vertex, otherwise apart.
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(4, 0, 0), Vec3(5, 0, 1), Vec3(5, 1, 1)}, true));
    // Near miss: vertex one ulp above the interior of t1.
    const double up = std::nextafter(0.0, 1.0);
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(1, 1, up), Vec3(1, 1, 3), Vec3(2, 0.5, 3)}, false));
    // Near miss across an edge: t2 crosses t1's plane just beyond the hypotenuse x + y = 4.
    const double beyond = std::nextafter(2.0, 3.0);
    EXPECT_TRUE(intersectAllOrders(
        t1, {Vec3(beyond, beyond, -1), Vec3(beyond, beyond, 1), Vec3(5, 5, 0)}, false));
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(2, 2, -1), Vec3(2, 2, 1), Vec3(5, 5, 0)}, true));
}

TEST(TriangleTriangle, DegenerateTrianglesAreSegments) {
    const Tri t1{Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 0)};
    // A "triangle" that is the segment from (1,1,-1) to (1,1,1) through t1's interior.
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(1, 1, -1), Vec3(1, 1, 0.5), Vec3(1, 1, 1)}, true));
    EXPECT_TRUE(intersectAllOrders(t1, {Vec3(5, 1, -1), Vec3(5, 1, 0.5), Vec3(5, 1, 1)}, false));
    // Two crossing segments in the plane z = 7.
    EXPECT_TRUE(intersectAllOrders({Vec3(0, 0, 7), Vec3(1, 1, 7), Vec3(2, 2, 7)},
                                   {Vec3(0, 2, 7), Vec3(1, 1, 7), Vec3(2, 0, 7)}, true));
    EXPECT_TRUE(intersectAllOrders({Vec3(0, 0, 7), Vec3(1, 1, 7), Vec3(2, 2, 7)},
                                   {Vec3(0, 2, 8), Vec3(1, 1, 8), Vec3(2, 0, 8)}, false));
}

// ---- Random grid triangles against an exact separating-axis reference. ----

using IVec = std::array<std::int64_t, 3>;

IVec sub(const IVec& a, const IVec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
IVec cross(const IVec& a, const IVec& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
std::int64_t dot(const IVec& a, const IVec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Closed convex sets are disjoint iff some axis separates them strictly. For two triangles the
// candidates are both normals, the 9 edge-edge cross products and, for the coplanar case, the
// in-plane edge normals n x e. Small integers keep every product exact.
bool satReference(const std::array<IVec, 3>& t1, const std::array<IVec, 3>& t2) {
    std::array<IVec, 3> e1{sub(t1[1], t1[0]), sub(t1[2], t1[1]), sub(t1[0], t1[2])};
    std::array<IVec, 3> e2{sub(t2[1], t2[0]), sub(t2[2], t2[1]), sub(t2[0], t2[2])};
    std::vector<IVec> axes{cross(e1[0], e1[1]), cross(e2[0], e2[1])};
    for (const auto& a : e1) {
        for (const auto& b : e2) axes.push_back(cross(a, b));
    }
    for (const auto& e : e1) axes.push_back(cross(axes[0], e));
    for (const auto& e : e2) axes.push_back(cross(axes[1], e));
    for (const auto& axis : axes) {
        if (axis == IVec{0, 0, 0}) continue;
        std::int64_t lo1 = dot(axis, t1[0]), hi1 = lo1, lo2 = dot(axis, t2[0]), hi2 = lo2;
        for (int i = 1; i < 3; ++i) {
            lo1 = std::min(lo1, dot(axis, t1[i]));
            hi1 = std::max(hi1, dot(axis, t1[i]));
            lo2 = std::min(lo2, dot(axis, t2[i]));
            hi2 = std::max(hi2, dot(axis, t2[i]));
        }
        if (hi1 < lo2 || hi2 < lo1) return false;
    }
    return true;
}

TEST(TriangleTriangle, RandomGridTrianglesMatchExactSeparatingAxes) {
    cdlab_test::Rng rng(2024);
    int hits = 0;
    int misses = 0;
    int coplanar_hits = 0;
    const int kPairs = 60000;
    for (int n = 0; n < kPairs; ++n) {
        std::array<IVec, 3> t1{}, t2{};
        const bool flat = n % 3 == 0;  // a third of the pairs are coplanar (z = 0)
        for (int i = 0; i < 3; ++i) {
            for (int k = 0; k < 3; ++k) {
                t1[i][k] = (flat && k == 2) ? 0 : rng.integer(-3, 3);
                t2[i][k] = (flat && k == 2) ? 0 : rng.integer(-3, 3);
            }
        }
        const bool degenerate1 = cross(sub(t1[1], t1[0]), sub(t1[2], t1[0])) == IVec{0, 0, 0};
        const bool degenerate2 = cross(sub(t2[1], t2[0]), sub(t2[2], t2[0])) == IVec{0, 0, 0};
        if (degenerate1 || degenerate2) continue;  // the SAT axes above assume real triangles
        const bool expected = satReference(t1, t2);
        // Scaled by 2^-3 and shifted by 2^20: exact, so the answer must not change.
        for (const double unit : {1.0, 0.125}) {
            const double shift = unit == 1.0 ? 0.0 : std::ldexp(1.0, 20);
            auto v = [&](const IVec& p) {
                return Vec3(p[0] * unit + shift, p[1] * unit + shift, p[2] * unit + shift);
            };
            ASSERT_EQ(
                testTriangleTriangle(v(t1[0]), v(t1[1]), v(t1[2]), v(t2[0]), v(t2[1]), v(t2[2])),
                expected)
                << "pair " << n;
        }
        expected ? ++hits : ++misses;
        if (expected && flat) ++coplanar_hits;
    }
    // Both outcomes occur in bulk, coplanar ones included.
    EXPECT_GT(hits, kPairs / 10);
    EXPECT_GT(misses, kPairs / 10);
    EXPECT_GT(coplanar_hits, kPairs / 20);
}

}  // namespace
