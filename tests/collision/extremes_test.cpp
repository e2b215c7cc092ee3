// Numerics at the extremes: every convex pair type swept over sizes 1e-4..1e4 and offsets from
// the origin 0..1e8; sphere CCD over the same grid and speeds from 1e-3 to 1e6 sizes per step;
// vertex-face CCD with zero and extreme motion far from the origin; triangle tests on nearly
// parallel, touching and sliver triangles. Expected values are computed in long double from the
// inputs exactly as stored (the rounding of the inputs is not the algorithm's error); each
// tolerance is stated where it is used, relative to size and to the position ulp at the offset.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include "collision/ccd/ccd.h"
#include "collision/geometry/convex_hull.h"
#include "collision/narrowphase/contact.h"
#include "collision/narrowphase/narrow_phase.h"
#include "geometry/triangle_triangle.h"

namespace {

using collision::CcdState;
using collision::collide;
using collision::ContactState;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::Shape;
using collision::Vec3;

constexpr std::array<Real, 5> kSizes{1e-4, 1e-2, 1, 1e2, 1e4};
constexpr std::array<Real, 6> kOffsets{0, 1e3, 1e4, 1e6, 1e7, 1e8};

Real ulpAt(Real x) {
    const Real a = std::abs(x);
    return std::nextafter(a, std::numeric_limits<Real>::infinity()) - a;
}

Shape cubeHull(Real half) {
    std::vector<Vec3> corners;
    for (int i = 0; i < 8; ++i) {
        corners.emplace_back(i & 1 ? half : -half, i & 2 ? half : -half, i & 4 ? half : -half);
    }
    collision::ConvexHullOutput h = collision::computeConvexHull(corners);
    EXPECT_TRUE(h.ok) << h.error;
    return Shape::convexHull(std::make_shared<const collision::ConvexPolytope>(std::move(h.hull)));
}

// A shape of size s and its extent along its local +x (all four are symmetric about the origin,
// so two of them side by side on a line through their centres are closest along that line).
struct Sized {
    std::string name;
    Shape shape;
    Real extent_x;
};

std::array<Sized, 4> shapesOfSize(Real s) {
    return {{{"sphere", Shape::sphere(s), s},
             {"box", Shape::box(Vec3(s, 0.5 * s, 2 * s)), s},
             {"capsule", Shape::capsule(Real(0.5) * s, s), Real(0.5) * s},
             {"hull", cubeHull(s), s}}};
}

// Pair types side by side along the world direction `u` (unit, = R * x), both turned by R, at
// offset o, with a gap of `gap` between them. Checks state and distance against the gap as the
// stored positions give it.
void checkPairsAlong(const Quat& q, Real gap_fraction) {
    const Vec3 u = q * Vec3::UnitX();
    for (Real s : kSizes) {
        const std::array<Sized, 4> shapes = shapesOfSize(s);
        for (Real o : kOffsets) {
            const Vec3 base = Vec3(o, -0.5 * o, 0.25 * o);
            for (const Sized& a : shapes) {
                for (const Sized& b : shapes) {
                    const Real gap = gap_fraction * s;
                    const Vec3 pa = base;
                    const Vec3 pb = base + (a.extent_x + b.extent_x + gap) * u;
                    // The gap the stored positions really have, along u, in long double.
                    long double along = 0;
                    for (int k = 0; k < 3; ++k) {
                        along += (static_cast<long double>(pb[k]) - pa[k]) * u[k];
                    }
                    const Real true_gap = static_cast<Real>(along - a.extent_x - b.extent_x);
                    const std::string what = a.name + "-" + b.name + " size " + std::to_string(s) +
                                             " offset " + std::to_string(o);
                    const collision::CollideOutput ab =
                        collide(a.shape, Pose{pa, q}, b.shape, Pose{pb, q});
                    const collision::CollideOutput ba =
                        collide(b.shape, Pose{pb, q}, a.shape, Pose{pa, q});
                    ASSERT_EQ(ab.state, ba.state) << what << ": swapping A and B";
                    ASSERT_TRUE(std::isfinite(ab.distance)) << what;
                    if (gap_fraction > 0) {
                        ASSERT_EQ(ab.state, ContactState::Separated) << what;
                        // Tolerance: GJK stops at 1e-12 relative; the relative pose is rounded
                        // once (a few ulps of the offset per coordinate, magnified by nothing);
                        // rotating by R costs a few ulps of the size. 1e-9 s + 16 ulp(o).
                        EXPECT_NEAR(ab.distance, true_gap, 1e-9 * s + 16 * ulpAt(o)) << what;
                        EXPECT_NEAR(ba.distance, ab.distance, 1e-9 * s + 16 * ulpAt(o)) << what;
                    } else {
                        ASSERT_EQ(ab.state, ContactState::Penetrating) << what;
                    }
                }
            }
        }
    }
}

TEST(Extremes, ConvexPairsSeparatedAtEverySizeAndOffset) {
    checkPairsAlong(Quat::Identity(), 0.25);
    checkPairsAlong(Quat(Eigen::AngleAxis<Real>(0.5, Vec3(1, 2, 3).normalized())), 0.25);
}

TEST(Extremes, ConvexPairsPenetratingAtEverySizeAndOffset) {
    checkPairsAlong(Quat::Identity(), -0.25);
    checkPairsAlong(Quat(Eigen::AngleAxis<Real>(0.5, Vec3(1, 2, 3).normalized())), -0.25);
}

TEST(Extremes, ExactTouchingIsTouchingAtEveryPowerOfTwoSizeAndOffset) {
    // Power-of-two sizes and offsets (2^-13 .. 2^13 and 0, 2^10 .. 2^27 ~ 1.3e8) make every
    // position sum exact, so the shapes really touch; the one convention says Touching, in
    // collide() and in contact() called both ways, with one normal: +x (every pair touches at
    // the x-extreme point of both surfaces, where each surface's normal is x), finite, unit and
    // mirrored (contact.h: swapping A and B negates the normal).
    int calls = 0;
    for (int size_exp = -13; size_exp <= 13; ++size_exp) {
        const Real s = std::ldexp(Real(1), size_exp);
        const std::array<Sized, 4> shapes = shapesOfSize(s);
        for (int off_exp : {-1, 10, 20, 27}) {
            const Real o = off_exp < 0 ? 0 : std::ldexp(Real(1), off_exp);
            for (const Sized& a : shapes) {
                for (const Sized& b : shapes) {
                    const Vec3 pa(o, o, -o);
                    const Vec3 pb = pa + Vec3(a.extent_x + b.extent_x, 0, 0);
                    ASSERT_EQ(pb.x() - pa.x(), a.extent_x + b.extent_x);  // exact
                    const Pose pose_a{pa, Quat::Identity()};
                    const Pose pose_b{pb, Quat::Identity()};
                    const std::string what = a.name + "-" + b.name + " size 2^" +
                                             std::to_string(size_exp) + " offset " +
                                             std::to_string(o);
                    const collision::CollideOutput r = collide(a.shape, pose_a, b.shape, pose_b);
                    EXPECT_EQ(r.state, ContactState::Touching) << what;
                    const collision::ContactOutput ab =
                        collision::contact(a.shape, pose_a, b.shape, pose_b);
                    const collision::ContactOutput ba =
                        collision::contact(b.shape, pose_b, a.shape, pose_a);
                    calls += 2;
                    EXPECT_EQ(ab.state, ContactState::Touching) << what;
                    EXPECT_EQ(ba.state, ab.state) << what << ": swapping A and B";
                    ASSERT_TRUE(ab.normal.allFinite() && ba.normal.allFinite()) << what;
                    // Normals are unit vectors: a tolerance of a few ulps of 1 is relative.
                    constexpr Real kUnit = 1e-12;
                    EXPECT_NEAR(ab.normal.norm(), 1, kUnit) << what;
                    EXPECT_NEAR(ba.normal.norm(), 1, kUnit) << what;
                    EXPECT_LE((ab.normal + ba.normal).norm(), kUnit)
                        << what << ": n_ab " << ab.normal.transpose() << ", n_ba "
                        << ba.normal.transpose();
                    EXPECT_NEAR(ab.normal.x(), 1, kUnit) << what << ": " << ab.normal.transpose();
                    // Touching: |signed distance| within the band, the same both ways.
                    const Real band = collision::kTouchRelativeTolerance * 4 * s;
                    EXPECT_LE(std::abs(ab.signed_distance), band) << what;
                    EXPECT_LE(std::abs(ba.signed_distance), band) << what;
                }
            }
        }
    }
    EXPECT_EQ(calls, 27 * 4 * 16 * 2);
}

// Nearly parallel boxes: two cubes of half size s, A's top feature against B's bottom feature,
// B turned by a small angle theta so that the two features are parallel but for theta.
// - faces: A axis-aligned; B turned by theta about z: A's top face (y = s) against B's bottom
//   face, tilted by theta, whose lowest edge (along z) lies over A's face (B is shifted 0.25 s
//   along x so that edge projects well inside it).
// - edges: A turned 45 deg about z (top feature: the edge along z at y = s sqrt 2); B the same
//   then turned by theta about y, so its bottom edge is horizontal and crosses A's top edge
//   at an angle theta above A's centre.
// In both, all of A lies below A's top feature and all of B above B's bottom feature, and the
// two features meet in projection, so the distance is the vertical gap between them. The
// penetration depth of two boxes is the smallest overlap over the 15 separating axes (RTCD
// 4.4.1; the minimum translation of two polytopes is along a face normal of their Minkowski
// difference, each of which is one of these axes). Both are evaluated in long double from the
// stored poses (the rounding of the inputs is not the algorithm's error).
using LVec = Eigen::Matrix<long double, 3, 1>;
using LMat = Eigen::Matrix<long double, 3, 3>;

LMat rotationOf(const Quat& q) { return q.cast<long double>().toRotationMatrix(); }

// Half extent of a cube of half size s with rotation r along the unit world direction n.
long double cubeRadius(const LMat& r, long double s, const LVec& n) {
    return s * (std::abs(r.col(0).dot(n)) + std::abs(r.col(1).dot(n)) + std::abs(r.col(2).dot(n)));
}

// Smallest overlap of the two cubes over the 15 SAT axes (axes of parallel edge pairs whose cross
// product vanishes in long double are skipped: a face axis covers them).
long double satDepth(const LMat& ra, const LMat& rb, long double s, const LVec& d) {
    long double best = std::numeric_limits<long double>::infinity();
    auto axis = [&](const LVec& n) {
        best = std::min(best, cubeRadius(ra, s, n) + cubeRadius(rb, s, n) - std::abs(d.dot(n)));
    };
    for (int i = 0; i < 3; ++i) {
        axis(ra.col(i));
        axis(rb.col(i));
        for (int j = 0; j < 3; ++j) {
            const LVec c = ra.col(i).cross(rb.col(j));
            const long double len = c.norm();
            if (len > 1e-15L) axis(c / len);
        }
    }
    return best;
}

// Regression (edges, angle 1e-7, gap +-1e-7 size): the box SAT of collide() and contact()
// skipped the cross axis of edges within 1e-6 rad of parallel, so two ridges 1e-7 s apart were
// Penetrating and a 1e-7 s overlap came out as 1.41e-7 s (the face axes' answer).
//
//        B  \/        B's bottom ridge, turned by theta about the vertical
//        A  /\        A's top ridge
TEST(Extremes, NearlyParallelBoxFacesAndEdgesAtEverySizeAndOffset) {
    constexpr std::array<Real, 4> kAngles{1e-3, 1e-5, 1e-7, 1e-9};
    int separated = 0, penetrating = 0;
    for (const bool edges : {false, true}) {
        for (Real s : kSizes) {
            const Shape cube = Shape::box(Vec3::Constant(s));
            for (Real o : kOffsets) {
                const Vec3 base(o, -0.5 * o, 0.25 * o);
                for (Real theta : kAngles) {
                    const Quat qz45(Eigen::AngleAxis<Real>(M_PI / 4, Vec3::UnitZ()));
                    const Quat qa = edges ? qz45 : Quat::Identity();
                    const Quat qb = edges
                                        ? Quat(Eigen::AngleAxis<Real>(theta, Vec3::UnitY())) * qz45
                                        : Quat(Eigen::AngleAxis<Real>(theta, Vec3::UnitZ()));
                    const LMat ra = rotationOf(qa);
                    const LMat rb = rotationOf(qb);
                    // Heights of A's top and B's bottom above their centres.
                    const long double up_a = cubeRadius(ra, s, LVec::UnitY());
                    const long double down_b = cubeRadius(rb, s, LVec::UnitY());
                    // Gaps of a tenth, a thousandth and 1e-7 of the size (or 64 ulps of the
                    // offset where that is more, so the stored poses still hold the gap);
                    // overlaps the same.
                    const Real tiny = std::max(Real(1e-7) * s, 64 * ulpAt(o));
                    for (const Real gap : {Real(0.1) * s, Real(1e-3) * s, tiny, -tiny,
                                           Real(-1e-3) * s, Real(-0.1) * s}) {
                        const Real lift = static_cast<Real>(up_a + down_b) + gap;
                        const Vec3 pa = base;
                        const Vec3 pb = base + Vec3(edges ? 0 : 0.25 * s, lift, 0);
                        LVec d;
                        for (int k = 0; k < 3; ++k) {
                            d[k] = static_cast<long double>(pb[k]) - pa[k];
                        }
                        const long double true_gap = d.y() - up_a - down_b;
                        const collision::ContactOutput c =
                            collision::contact(cube, Pose{pa, qa}, cube, Pose{pb, qb});
                        char what_buf[128];
                        std::snprintf(what_buf, sizeof what_buf,
                                      "%s size %g offset %g angle %g gap %g size",
                                      edges ? "edges" : "faces", s, o, theta, gap / s);
                        const std::string what = what_buf;
                        ASSERT_TRUE(c.normal.allFinite()) << what;
                        EXPECT_NEAR(c.normal.norm(), 1, 1e-12) << what;
                        EXPECT_EQ(collide(cube, Pose{pa, qa}, cube, Pose{pb, qb}).state, c.state)
                            << what << ": collide() and contact() agree";
                        // Same tolerance as the other pairs: GJK/EPA/SAT to 1e-9 of the size,
                        // the rounding of the relative pose a few ulps of the offset.
                        const Real tol = 1e-9 * s + 16 * ulpAt(o);
                        if (gap > 0) {
                            ++separated;
                            ASSERT_GT(true_gap, 0) << what;
                            EXPECT_EQ(c.state, ContactState::Separated) << what;
                            EXPECT_NEAR(c.signed_distance, static_cast<Real>(true_gap), tol)
                                << what;
                        } else {
                            ++penetrating;
                            const long double depth = satDepth(ra, rb, s, d);
                            ASSERT_GT(depth, 0) << what;
                            EXPECT_EQ(c.state, ContactState::Penetrating) << what;
                            EXPECT_NEAR(c.signed_distance, -static_cast<Real>(depth), tol)
                                << what << " (vertical overlap " << -true_gap << ")";
                        }
                    }
                }
            }
        }
    }
    EXPECT_EQ(separated, 2 * 5 * 6 * 4 * 3);
    EXPECT_EQ(penetrating, separated);
}

TEST(Extremes, SphereTimeOfImpactAcrossSizesOffsetsAndSpeeds) {
    for (Real s : kSizes) {
        for (Real o : kOffsets) {
            for (Real speed : {Real(1e-3), Real(1), Real(1e3), Real(1e6)}) {
                // A (radius s) moves by `speed * s` along x; B (radius s) waits, `side` off the
                // line of motion (0: head on; s: an oblique hit), so that contact happens 30 %
                // into the step.
                for (Real side : {Real(0), s}) {
                    const Real move = speed * s;
                    const Vec3 a0(o - move, o, o);
                    const Vec3 a1(o, o, o);
                    const Vec3 b(a0.x() + std::sqrt(4 * s * s - side * side) + 0.3 * move, o + side,
                                 o);
                    const long double travel = static_cast<long double>(a1.x()) - a0.x();
                    const long double h = static_cast<long double>(b.y()) - a0.y();
                    const long double reach = std::sqrt(4.0L * s * s - h * h);
                    const long double t_true =
                        (static_cast<long double>(b.x()) - a0.x() - reach) / travel;
                    const collision::CcdOutput r =
                        collision::timeOfImpactSpheres(a0, a1, s, b, b, s);
                    const std::string what = "size " + std::to_string(s) + " offset " +
                                             std::to_string(o) + " speed " + std::to_string(speed) +
                                             " side " + std::to_string(side);
                    ASSERT_EQ(r.state, CcdState::Hit) << what;
                    // "Exact to rounding of the relative quantities": each relative coordinate is
                    // rounded at the offset's (or the motion's) ulp; in t that is ulp / travel.
                    const Real tol = 1e-12 + 8 * ulpAt(std::max(o, move)) / Real(travel);
                    EXPECT_NEAR(r.t, static_cast<Real>(t_true), tol) << what;
                    EXPECT_TRUE(r.normal.allFinite()) << what;
                    EXPECT_NEAR(r.normal.norm(), 1, 1e-12) << what;
                    if (side == 0) {
                        EXPECT_NEAR(r.normal.x(), 1, 1e-9) << what;
                    }
                }
            }
        }
    }
}

TEST(Extremes, VertexFaceCcdFarFromOriginZeroAndExtremeMotion) {
    for (Real s : {Real(1e-4), Real(1), Real(1e4)}) {
        for (Real o : kOffsets) {
            const Vec3 base(o, -o, o);
            auto input = [&](Real z0, Real z1, Real side) {
                collision::VertexFaceCcdInput in;
                in.t0 = {base + Vec3(side, 0.25 * s, z0), base + Vec3(-s, -s, 0),
                         base + Vec3(s, -s, 0), base + Vec3(0, s, 0)};
                in.t1 = in.t0;
                in.t1[0] = base + Vec3(side, 0.25 * s, z1);
                return in;
            };
            const std::string what = "size " + std::to_string(s) + " offset " + std::to_string(o);
            // Crossing the face: a hit, never after the stored crossing time.
            for (Real travel : {Real(2), Real(2e3), Real(2e6)}) {
                const collision::VertexFaceCcdInput in =
                    input(0.5 * travel * s, -0.5 * travel * s, 0);
                const long double z0 = static_cast<long double>(in.t0[0].z()) - in.t0[1].z();
                const long double z1 = static_cast<long double>(in.t1[0].z()) - in.t1[1].z();
                const Real t_true = static_cast<Real>(z0 / (z0 - z1));
                const collision::CcdOutput r = collision::vertexFaceCcd(in);
                ASSERT_EQ(r.state, CcdState::Hit) << what << " travel " << travel;
                EXPECT_LE(r.t, t_true) << what << " travel " << travel;
                EXPECT_GE(r.t, 0) << what;
                // Early by at most the acceptance width over the closing speed. A Hit box's
                // image is within the acceptance width max(tolerance * size, 4 err) of contact,
                // plus err for the rounding of its corners (ccd/inclusion.cpp: err = 64 u M,
                // u = eps / 2, M the largest input coordinate); the vertex closes on the face at
                // |z0 - z1| per unit t. So t >= t_true - (1e-6 size + 192 u M) / |z0 - z1|,
                // size the largest extent of the 8 points' bounding box. Stated with 256 u M.
                Real size = 0;
                Real m = 0;
                for (int k = 0; k < 3; ++k) {
                    Real lo = std::numeric_limits<Real>::infinity();
                    Real hi = -lo;
                    for (int i = 0; i < 4; ++i) {
                        for (const Vec3& p : {in.t0[i], in.t1[i]}) {
                            lo = std::min(lo, p[k]);
                            hi = std::max(hi, p[k]);
                            m = std::max(m, std::abs(p[k]));
                        }
                    }
                    size = std::max(size, hi - lo);
                }
                const Real speed = static_cast<Real>(z0 - z1);
                const Real tol = (collision::CcdSettings{}.tolerance * size +
                                  256 * (std::numeric_limits<Real>::epsilon() / 2) * m) /
                                 speed;
                EXPECT_GE(r.t, t_true - tol)
                    << what << " travel " << travel << ": t_true - t = " << t_true - r.t
                    << ", tolerance " << tol;
            }
            // No motion at all: separated stays separated; resting on the face is a hit at 0.
            const collision::CcdOutput still = collision::vertexFaceCcd(input(0.5 * s, 0.5 * s, 0));
            EXPECT_EQ(still.state, CcdState::Separated) << what;
            const collision::CcdOutput resting = collision::vertexFaceCcd(input(0, 0, 0));
            EXPECT_EQ(resting.state, CcdState::Hit) << what;
            EXPECT_EQ(resting.t, 0) << what;
            // Passing beside the face, a size away: no contact. A conservative method may call a
            // near miss a hit only within its error bound (about ulp(o) times a small factor);
            // one size of clearance is far outside it at every offset here.
            const collision::CcdOutput miss =
                collision::vertexFaceCcd(input(0.5 * s, -0.5 * s, 3 * s));
            EXPECT_EQ(miss.state, CcdState::Separated) << what;
        }
    }
}

TEST(Extremes, TrianglesNearlyParallelTouchingAndSliver) {
    for (Real o : kOffsets) {
        const Vec3 base(o, o, o);
        // Two overlapping triangles in parallel planes 2^-40 apart (relative to unit size), or
        // one ulp of the offset where that is more (2^-40 is below the ulp from 1e4 on, and a
        // gap the stored coordinates cannot hold would be no gap): exact predicates keep them
        // apart; in one plane they meet.
        const Real eps = std::max(std::ldexp(Real(1), -40), ulpAt(base.z()));
        const Vec3 a0 = base + Vec3(-1, -1, 0), a1 = base + Vec3(1, -1, 0),
                   a2 = base + Vec3(0, 1, 0);
        const Vec3 up(0, 0, eps);
        ASSERT_EQ((base.z() + eps) - base.z(), eps) << "offset " << o;  // the gap is stored
        EXPECT_FALSE(collision::testTriangleTriangle(a0, a1, a2, a0 + up + Vec3(0.5, 0, 0), a1 + up,
                                                     a2 + up))
            << "offset " << o << " gap " << eps;
        EXPECT_TRUE(collision::testTriangleTriangle(
            a0, a1, a2, a0 + Vec3(0.5, 0.25, 0), a1 + Vec3(0.5, 0.25, 0), a2 + Vec3(0.5, 0.25, 0)))
            << "offset " << o;
        // Sharing exactly one vertex: touching counts.
        EXPECT_TRUE(collision::testTriangleTriangle(a0, a1, a2, a2, a2 + Vec3(1, 1, 1),
                                                    a2 + Vec3(-1, 1, 2)))
            << "offset " << o;
        // A sliver 1e-12 tall standing through the face, and one beside it.
        const Vec3 s0 = base + Vec3(0, 0, -1), s1 = base + Vec3(0, 0, 1);
        const Vec3 s2 = base + Vec3(1e-12, 0, 0.5);
        EXPECT_TRUE(collision::testTriangleTriangle(a0, a1, a2, s0, s1, s2)) << "offset " << o;
        const Vec3 off(3, 0, 0);
        EXPECT_FALSE(collision::testTriangleTriangle(a0, a1, a2, s0 + off, s1 + off, s2 + off))
            << "offset " << o;
        // Fully degenerate: a triangle that is a point on the face, and one that is a segment
        // crossing it, are tested as what they are.
        EXPECT_TRUE(collision::testTriangleTriangle(a0, a1, a2, base, base, base));
        EXPECT_TRUE(collision::testTriangleTriangle(a0, a1, a2, s0, s1, s1));
        EXPECT_FALSE(collision::testTriangleTriangle(a0, a1, a2, s0 + off, s1 + off, s1 + off));
    }
}

}  // namespace
