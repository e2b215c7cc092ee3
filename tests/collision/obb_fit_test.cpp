// The bodies' OBB fit (fitObbTight through fitLocalBounds): the cube from a mesh is the cube in
// any rotation and vertex order, every vertex is inside, and the box is never larger than the
// covariance fit and within a measured bound of the best box a brute-force orientation search
// finds. The 2-D rectangle step agrees with its O(h^2) reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "collision/geometry/convex_hull.h"
#include "collision/geometry/shape.h"
#include "collision/volumes/bounding_volumes.h"
#include "test_meshes.h"
#include "test_random.h"
#include "test_scale.h"
#include "volumes/min_area_rectangle.h"

namespace collision {
namespace {

using cdlab_test::Rng;

// The fitted box may exceed the best box the brute-force search finds by at most this factor.
// Measured (the table the VolumeRatio tests print): cube, cylinder and torus 1.0000 (the best box
// has a face on a hull face, which the fit solves exactly); random hulls at most 1.014 (thin
// ellipsoid hulls, whose best box has no face on a hull face). The bound leaves twice that
// margin; the covariance fit alone gives 1.34 and 4.13 on the cube and up to 1.72 on the random
// hulls, so a fit that falls back to it fails here.
constexpr Real kBruteRatioBound = 1.03;

Real volumeOf(const Obb& o) { return 8 * o.half_extents.prod(); }

// The unit cube as a PLY or OFF file holds it: 8 corners, each face two triangles.
TriangleMesh unitCubeMesh() {
    TriangleMesh m;
    for (int k = 0; k < 8; ++k) {
        m.vertices.emplace_back(k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 : -0.5, k & 4 ? 0.5 : -0.5);
    }
    const int quads[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                             {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& f : quads) {
        m.triangles.push_back({f[0], f[1], f[2]});
        m.triangles.push_back({f[0], f[2], f[3]});
    }
    return m;
}

// A closed cylinder around z: radius r, height h, `segments` around, fan-triangulated caps.
TriangleMesh cylinderMesh(Real r, Real h, int segments) {
    TriangleMesh m;
    for (int i = 0; i < segments; ++i) {
        const Real a = 2 * std::numbers::pi_v<Real> * i / segments;
        m.vertices.emplace_back(r * std::cos(a), r * std::sin(a), -h / 2);
        m.vertices.emplace_back(r * std::cos(a), r * std::sin(a), h / 2);
    }
    const auto bottom = static_cast<std::int32_t>(m.vertices.size());
    m.vertices.emplace_back(0, 0, -h / 2);
    m.vertices.emplace_back(0, 0, h / 2);
    for (int i = 0; i < segments; ++i) {
        const std::int32_t a = 2 * i;
        const std::int32_t b = 2 * ((i + 1) % segments);
        m.triangles.push_back({a, b, b + 1});
        m.triangles.push_back({a, b + 1, a + 1});
        m.triangles.push_back({bottom, b, a});
        m.triangles.push_back({bottom + 1, a + 1, b + 1});
    }
    return m;
}

// The same mesh with its vertices (and triangles) in a shuffled order, placed by `pose`.
TriangleMesh scrambled(const TriangleMesh& in, const Pose& pose, Rng& rng) {
    const int n = static_cast<int>(in.vertices.size());
    std::vector<std::int32_t> where(n);
    for (int i = 0; i < n; ++i) where[i] = i;
    for (int i = n - 1; i > 0; --i) std::swap(where[i], where[rng.integer(0, i)]);
    TriangleMesh out;
    out.vertices.resize(n);
    for (int i = 0; i < n; ++i) out.vertices[where[i]] = pose.apply(in.vertices[i]);
    for (const auto& t : in.triangles)
        out.triangles.push_back({where[t[0]], where[t[1]], where[t[2]]});
    for (int i = static_cast<int>(out.triangles.size()) - 1; i > 0; --i) {
        std::swap(out.triangles[i], out.triangles[rng.integer(0, i)]);
    }
    return out;
}

Shape meshShape(const TriangleMesh& m) {
    const ConvexHullOutput hull = computeConvexHull(m.vertices);
    EXPECT_TRUE(hull.ok) << hull.error;
    return Shape::triangleMesh(std::make_shared<TriangleMesh>(m),
                               std::make_shared<ConvexPolytope>(hull.hull), nullptr);
}

// Brute-force reference: the smallest projection box over a grid of Euler angles (Rz Ry Rx, a
// 4 degree step over alpha in [0, pi), beta in [-pi/2, pi/2], gamma in [0, pi), which covers
// every box orientation since a box is symmetric under half turns about its axes), then a local
// pattern search (half turns about the box's own axes, step halving to 1e-7 rad) from the 12
// best grid orientations. Returns the volume of the best box found (no slack).
Real bruteForceBestVolume(const std::vector<Vec3>& points) {
    const Vec3 origin = points[0];
    std::vector<double> xyz;
    for (const Vec3& p : points) {
        for (int k = 0; k < 3; ++k) xyz.push_back(double(p[k] - origin[k]));
    }
    auto volume = [&](const Mat3& r) {
        double lo[3] = {1e300, 1e300, 1e300};
        double hi[3] = {-1e300, -1e300, -1e300};
        for (std::size_t i = 0; i < xyz.size(); i += 3) {
            for (int k = 0; k < 3; ++k) {
                const double d = r(0, k) * xyz[i] + r(1, k) * xyz[i + 1] + r(2, k) * xyz[i + 2];
                lo[k] = std::min(lo[k], d);
                hi[k] = std::max(hi[k], d);
            }
        }
        return (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    };
    const Real pi = std::numbers::pi_v<Real>;
    const Real step = 4 * pi / 180;
    std::vector<std::pair<Real, Mat3>> grid;
    for (Real a = 0; a < pi; a += step) {
        for (Real b = -pi / 2; b <= pi / 2 + 1e-12; b += step) {
            for (Real c = 0; c < pi; c += step) {
                const Mat3 r = (Eigen::AngleAxis<Real>(a, Vec3::UnitZ()) *
                                Eigen::AngleAxis<Real>(b, Vec3::UnitY()) *
                                Eigen::AngleAxis<Real>(c, Vec3::UnitX()))
                                   .toRotationMatrix();
                grid.emplace_back(volume(r), r);
            }
        }
    }
    const std::size_t starts = std::min<std::size_t>(12, grid.size());
    std::partial_sort(grid.begin(), grid.begin() + starts, grid.end(),
                      [](const auto& x, const auto& y) { return x.first < y.first; });
    Real best = grid[0].first;
    for (std::size_t s = 0; s < starts; ++s) {
        Mat3 r = grid[s].second;
        Real v = grid[s].first;
        for (Real delta = step / 2; delta > 1e-7; delta /= 2) {
            bool improved = true;
            while (improved) {
                improved = false;
                for (int axis = 0; axis < 3; ++axis) {
                    for (Real sign : {Real(-1), Real(1)}) {
                        const Mat3 cand = r * Eigen::AngleAxis<Real>(sign * delta, Vec3::Unit(axis))
                                                  .toRotationMatrix();
                        const Real cv = volume(cand);
                        if (cv < v) {
                            v = cv;
                            r = cand;
                            improved = true;
                        }
                    }
                }
            }
        }
        best = std::min(best, v);
    }
    return best;
}

struct RatioRow {
    std::string name;
    Real old_volume = 0;    // covariance (principal-axes) fit
    Real new_volume = 0;    // fitLocalBounds, i.e. fitObbTight
    Real brute_volume = 0;  // best box the brute-force search found
};

// Fits `shape`, checks containment of `points`, prints and records the row, and asserts the new
// box is no larger than the covariance box and within kBruteRatioBound of the brute-force best.
RatioRow checkRatios(const std::string& name, const Shape& shape, const std::vector<Vec3>& points) {
    const LocalBounds b = fitLocalBounds(shape);
    for (const Vec3& p : points) {
        const Vec3 local = b.obb.axes.transpose() * (p - b.obb.center);
        EXPECT_TRUE((local.cwiseAbs().array() <= b.obb.half_extents.array()).all()) << name;
    }
    RatioRow row{name, volumeOf(fitObbPrincipal(*shape.hull)), volumeOf(b.obb),
                 bruteForceBestVolume(shape.hull->vertices)};
    std::printf("[ obb fit ] %-22s old/brute %7.4f   new/brute %7.4f   brute %.6g\n", name.c_str(),
                double(row.old_volume / row.brute_volume),
                double(row.new_volume / row.brute_volume), double(row.brute_volume));
    ::testing::Test::RecordProperty(name + "_old_over_brute",
                                    std::to_string(row.old_volume / row.brute_volume));
    ::testing::Test::RecordProperty(name + "_new_over_brute",
                                    std::to_string(row.new_volume / row.brute_volume));
    // The slack is a few ulps of the size: 1e-12 relative absorbs it.
    EXPECT_LE(row.new_volume, row.old_volume * (1 + 1e-12)) << name;
    EXPECT_LE(row.new_volume, row.brute_volume * kBruteRatioBound) << name;
    return row;
}

// Issue: a unit cube loaded from PLY or OFF got half extents [0.707, 0.728, 0.843]: its surface
// covariance is isotropic, so the principal axes were rounding noise. Any rotation, any vertex
// and triangle order, hull or mesh: the box is the cube.
//
//        +------+            old: a box at arbitrary axes,
//       /|     /|                 corners outside the cube's own bounding sphere
//      +------+ |            new: half extents 0.5, 0.5, 0.5
//      | +----|-+
//      |/     |/
//      +------+
TEST(ObbFit, UnitCubeFromAMeshIsTheCubeInAnyRotationAndOrder) {
    Rng rng(5);
    const TriangleMesh cube = unitCubeMesh();
    for (int trial = 0; trial < 40; ++trial) {
        const Pose pose{trial % 2 ? rng.vec(-1e3, 1e3) : Vec3::Zero(),
                        trial == 0 ? Quat::Identity() : rng.rotation()};
        const TriangleMesh m = trial < 2 ? cube : scrambled(cube, pose, rng);
        const Shape mesh = meshShape(m);
        for (const Shape& s : {mesh, Shape::convexHull(mesh.hull)}) {
            const LocalBounds b = fitLocalBounds(s);
            const Real size = 0.5 + pose.position.cwiseAbs().maxCoeff();
            for (int k = 0; k < 3; ++k) {
                EXPECT_NEAR(b.obb.half_extents[k], 0.5, 1e-9 * size)
                    << "trial " << trial << " " << shapeTypeName(s.type);
            }
            // The box fits in the cube around the bounding sphere, and its corners (the cube's)
            // lie on that sphere, not outside it.
            EXPECT_LE(b.obb.half_extents.maxCoeff(), b.sphere.radius);
            Vec3 corners[8];
            b.obb.corners(corners);
            for (const Vec3& c : corners) {
                EXPECT_LE((c - b.sphere.center).norm(), b.sphere.radius + 1e-9 * size);
            }
        }
    }
    // A cube whose faces are grids (hull faces split into many coplanar triangles).
    const Shape grid = meshShape(cdlab_test::makeGridCubeMesh(6));
    const LocalBounds g = fitLocalBounds(grid);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(g.obb.half_extents[k], 1.0, 1e-9);
}

TEST(ObbFit, VolumeRatioToBruteForceOnCubeCylinderTorus) {
    Rng rng(9);
    const Pose turn{Vec3(3, -2, 7), rng.rotation()};
    const RatioRow cube = checkRatios("cube", meshShape(unitCubeMesh()), unitCubeMesh().vertices);
    EXPECT_NEAR(cube.new_volume, 1.0, 1e-9);  // analytic minimum
    const TriangleMesh turned = scrambled(unitCubeMesh(), turn, rng);
    checkRatios("cube_rotated", meshShape(turned), turned.vertices);

    // Cylinder r = 1, h = 2 with 64 segments: the smooth cylinder's minimum is 8; the polygon's
    // is 2 h (2 cos(pi/64))^2 = 7.981 (a rectangle side on a polygon edge).
    const TriangleMesh cyl = scrambled(cylinderMesh(1, 2, 64), turn, rng);
    const RatioRow c = checkRatios("cylinder_64", meshShape(cyl), cyl.vertices);
    const Real polygon_min = 2 * 4 * std::pow(std::cos(std::numbers::pi_v<Real> / 64), 2);
    EXPECT_NEAR(c.new_volume, polygon_min, 1e-9 * polygon_min);
    std::printf("[ obb fit ] cylinder_64 new / smooth analytic 8: %.4f\n",
                double(c.new_volume / 8));

    // Torus ring 1, tube 0.3, 50 x 20 segments: 2,000 triangles.
    const TriangleMesh torus = cdlab_test::makeTorusMesh(1, 0.3, 50, 20);
    checkRatios("torus_2k", meshShape(torus), torus.vertices);
    const TriangleMesh torus_turned = scrambled(torus, turn, rng);
    checkRatios("torus_2k_rotated", meshShape(torus_turned), torus_turned.vertices);
}

TEST(ObbFit, VolumeRatioToBruteForceOnRandomHulls) {
    // Points in a box, in a ball and in a thin ellipsoid, rotated: hulls of 8 to 60 vertices.
    for (int seed = 0; seed < cdlab_test::scaled(12, 3); ++seed) {
        Rng rng(100 + seed);
        const Quat q = rng.rotation();
        const Vec3 scale(1, seed % 3 == 2 ? 0.2 : 0.7, seed % 3 == 2 ? 0.05 : 0.4);
        std::vector<Vec3> pts;
        const int n = 8 + 5 * seed;
        while (static_cast<int>(pts.size()) < n) {
            const Vec3 p = rng.vec(-1, 1);
            if (seed % 3 != 0 && p.norm() > 1) continue;
            pts.push_back(q * p.cwiseProduct(scale));
        }
        const ConvexHullOutput hull = computeConvexHull(pts);
        ASSERT_TRUE(hull.ok) << hull.error;
        const Shape s = Shape::convexHull(std::make_shared<ConvexPolytope>(hull.hull));
        checkRatios("random_" + std::to_string(seed), s, pts);
    }
}

// Containment is by construction (exact projection ranges plus a relative slack): it holds for
// random hulls far from the origin and at tiny and huge scales, where the fit is the same box
// translated and scaled (volume within 1e-6 of scale^3 times the unit fit).
TEST(ObbFit, RandomHullsContainEveryVertexFarAndTinyAndHuge) {
    int checked = 0;
    const int seeds = cdlab_test::scaled(40, 8);
    for (int seed = 0; seed < seeds; ++seed) {
        Rng rng(700 + seed);
        std::vector<Vec3> unit;
        const int n = 4 + seed * 3;
        for (int i = 0; i < n; ++i) unit.push_back(rng.vec(-1, 1).cwiseProduct(Vec3(1, 0.6, 0.3)));
        const ConvexHullOutput h0 = computeConvexHull(unit);
        if (!h0.ok) continue;
        const Real v0 = volumeOf(fitObbTight(h0.hull));
        for (const Vec3& offset : {Vec3(0, 0, 0), Vec3(1e6, -2e6, 3e6), Vec3(-5e3, 0, 1)}) {
            for (Real scale : {Real(1e-4), Real(1), Real(1e4)}) {
                std::vector<Vec3> pts;
                for (const Vec3& p : unit) pts.push_back(offset + scale * p);
                const ConvexHullOutput hull = computeConvexHull(pts);
                ASSERT_TRUE(hull.ok) << hull.error;
                const auto poly = std::make_shared<ConvexPolytope>(hull.hull);
                const LocalBounds b = fitLocalBounds(Shape::convexHull(poly));
                for (const Vec3& p : pts) {
                    const Vec3 local = b.obb.axes.transpose() * (p - b.obb.center);
                    EXPECT_TRUE((local.cwiseAbs().array() <= b.obb.half_extents.array()).all())
                        << "seed " << seed << " scale " << scale;
                }
                EXPECT_NEAR((b.obb.axes.transpose() * b.obb.axes - Mat3::Identity()).norm(), 0,
                            1e-12);
                EXPECT_NEAR(b.obb.axes.determinant(), 1, 1e-12);
                // Far from the origin the slack (a few ulps of 1e6) dominates a tiny hull, so
                // only near the origin is the box the unit box scaled.
                if (offset.norm() < 1e4 * scale) {
                    EXPECT_NEAR(volumeOf(b.obb) / (scale * scale * scale), v0, 1e-6 * v0)
                        << "seed " << seed << " scale " << scale;
                }
                ++checked;
            }
        }
    }
    EXPECT_EQ(checked, 9 * seeds);
}

TEST(MinAreaRectangle, CalipersEqualTheQuadraticReference) {
    Rng rng(17);
    for (int trial = 0; trial < 300; ++trial) {
        std::vector<Point2> pts;
        const int n = 3 + trial % 60;
        const Real sx = rng.uniform(0.1, 10);
        for (int i = 0; i < n; ++i)
            pts.push_back(Point2{sx * rng.uniform(-1, 1), rng.uniform(-1, 1)});
        const std::vector<Point2> hull = convexHull2(pts);
        const Rectangle2 fast = minAreaRectangle(hull);
        const Rectangle2 slow = minAreaRectangleBruteForce(hull);
        EXPECT_NEAR(fast.area, slow.area, 1e-12 * slow.area) << "trial " << trial;
    }
    // A unit square turned by 30 degrees: the rectangle is the square.
    std::vector<Point2> square;
    for (int k = 0; k < 4; ++k) {
        const Real a = std::numbers::pi_v<Real> / 6 + k * std::numbers::pi_v<Real> / 2;
        square.push_back(Point2{std::cos(a), std::sin(a)});
    }
    EXPECT_NEAR(minAreaRectangle(convexHull2(square)).area, 2.0, 1e-12);
}

}  // namespace
}  // namespace collision
