// tests/collision/bvh_volumes_test.cpp -- white-box tests of single BVH node volumes (the traits
// in collision/src/bvh_volumes.h): the LSS's segment-distance overlap test against an independent
// reference and closed forms (parallel, crossing, touching, zero length, 1e6 from the origin,
// near-parallel), its distance lower bound, and its fit's containment and tightness.
#include "volumes/bvh_volumes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "test_random.h"

namespace {

using collision::BvhTransform;
using collision::BvTraits;
using collision::Lss;
using collision::Mat3;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::Vec3;
using Traits = BvTraits<Lss>;

// Distance from point p to the closed segment [a, b] (projection, clamped).
Real pointSegmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const Real len2 = ab.squaredNorm();
    const Real t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, Real(0), Real(1)) : Real(0);
    return (p - (a + ab * t)).norm();
}

// Segment-segment distance by golden-section search over A's parameter: the distance of a point
// moving linearly to a convex set is convex in the parameter, so the search converges to the
// minimum. Independent of RTCD 5.1.9 (no closed-form parameters, no clamping cases).
Real segmentDistanceReference(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1) {
    auto g = [&](Real s) { return pointSegmentDistance(a0 + (a1 - a0) * s, b0, b1); };
    Real lo = 0;
    Real hi = 1;
    const Real phi = (std::sqrt(Real(5)) - 1) / 2;
    for (int i = 0; i < 200 && hi - lo > 0; ++i) {
        const Real m1 = hi - phi * (hi - lo);
        const Real m2 = lo + phi * (hi - lo);
        if (g(m1) <= g(m2)) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    return std::min({g(lo), g(hi), g(Real(0)), g(Real(1))});
}

Lss makeLss(const Vec3& center, const Vec3& axis, Real half_length, Real radius) {
    return Lss{center, axis.normalized(), half_length, radius};
}

// The reference distance between A (in A's frame) and B (in B's frame, placed by pose).
Real referenceDistance(const Lss& a, const Lss& b, const Pose& pose) {
    const Vec3 a0 = a.center - a.axis * a.half_length;
    const Vec3 a1 = a.center + a.axis * a.half_length;
    const Vec3 b0 = pose.apply(b.center - b.axis * b.half_length);
    const Vec3 b1 = pose.apply(b.center + b.axis * b.half_length);
    return segmentDistanceReference(a0, a1, b0, b1);
}

// The traversal's transform for this pose, with the scales of the two volumes.
BvhTransform transformFor(const Lss& a, const Lss& b, const Pose& pose) {
    auto scale = [](const Lss& s) {
        return s.center.cwiseAbs().maxCoeff() + 2 * (s.half_length + s.radius);
    };
    return collision::makeBvhTransform(pose, scale(a), scale(b));
}

bool overlaps(const Lss& a, const Lss& b, const Pose& pose = Pose{}) {
    return Traits::overlaps(a, b, transformFor(a, b, pose));
}

// A with radius ra and B with radius rb: overlap answers for radii summing to the distance
// (touching), just below it (separated by 1e-5 relative) and above it.
void expectTouchingAt(Lss a, Lss b, Real distance, const Pose& pose = Pose{}) {
    a.radius = distance * Real(0.25);
    b.radius = distance - a.radius;
    EXPECT_TRUE(overlaps(a, b, pose)) << "touching at " << distance;
    EXPECT_TRUE(overlaps(b, a, pose.inverse())) << "touching, swapped";
    const Real scale = distance + a.half_length + b.half_length;
    a.radius -= Real(1e-5) * scale;
    EXPECT_FALSE(overlaps(a, b, pose)) << "1e-5 apart at " << distance;
    EXPECT_FALSE(overlaps(b, a, pose.inverse())) << "1e-5 apart, swapped";
}

TEST(Lss, ClosedFormDistancesTouchAtTheSumOfRadii) {
    const Lss x_axis = makeLss(Vec3::Zero(), Vec3::UnitX(), 1, 0);
    // Parallel, side by side with overlapping extents: the lines' distance 2.
    expectTouchingAt(x_axis, makeLss(Vec3(0.5, 2, 0), Vec3::UnitX(), 1, 0), 2);
    // Antiparallel and shifted past the end: corner to corner, sqrt(1 + 1).
    expectTouchingAt(x_axis, makeLss(Vec3(3, 1, 0), -Vec3::UnitX(), 1, 0), std::sqrt(Real(2)));
    // Collinear, end to end: 1.
    expectTouchingAt(x_axis, makeLss(Vec3(3, 0, 0), Vec3::UnitX(), 1, 0), 1);
    // Crossing at right angles, 1.5 apart in z.
    expectTouchingAt(x_axis, makeLss(Vec3(0.25, -0.5, 1.5), Vec3::UnitY(), 1, 0), 1.5);
    // Skew, the closest points beyond B's end: from A's point (0.5, 0, 0) to B's end (0.5, 1, 2).
    expectTouchingAt(x_axis, makeLss(Vec3(0.5, 2, 2), Vec3::UnitY(), 1, 0), std::sqrt(Real(5)));
    // Zero-length B (a sphere) above A's middle, and past A's end.
    expectTouchingAt(x_axis, makeLss(Vec3(0.5, 0, 2), Vec3::UnitZ(), 0, 0), 2);
    expectTouchingAt(x_axis, makeLss(Vec3(4, 0, 0), Vec3::UnitZ(), 0, 0), 3);
    // Both zero length: two spheres.
    expectTouchingAt(makeLss(Vec3(1, 2, 3), Vec3::UnitX(), 0, 0),
                     makeLss(Vec3(1, 2, 6), Vec3::UnitY(), 0, 0), 3);
    // Segments that cross: distance 0, zero radii still overlap; apart by 1e-3 they do not.
    EXPECT_TRUE(overlaps(x_axis, makeLss(Vec3(0.25, 0, 0), Vec3(0, 1, 1), 1, 0)));
    EXPECT_FALSE(overlaps(x_axis, makeLss(Vec3(0.25, 0, 1e-3), Vec3(0, 1, 0), 1, 0)));
}

TEST(Lss, ClosedFormsHoldUnderAPoseAndFarFromTheOrigin) {
    // B given in its own frame, rotated 90 degrees about z and moved: its axis x becomes y.
    const Quat quarter(Eigen::AngleAxis<Real>(std::numbers::pi_v<Real> / 2, Vec3::UnitZ()));
    for (const Real offset : {Real(0), Real(1e6)}) {
        const Vec3 o = Vec3::Constant(offset);
        const Lss a = makeLss(o, Vec3::UnitX(), 1, 0);
        // B's axis along y after the rotation, its centre at o + (0.25, -0.5, 1.5): crossing.
        const Lss b = makeLss(Vec3::Zero(), Vec3::UnitX(), 1, 0);
        expectTouchingAt(a, b, 1.5, Pose{o + Vec3(0.25, -0.5, 1.5), quarter});
        // Parallel after the rotation: B's axis y, A turned to y too.
        const Lss ay = makeLss(o, Vec3::UnitY(), 1, 0);
        expectTouchingAt(ay, b, 2, Pose{o + Vec3(2, 0.5, 0), quarter});
    }
}

TEST(Lss, OverlapMatchesTheReferenceAtRandomPoses) {
    cdlab_test::Rng rng(2024);
    int overlapping = 0;
    int separated = 0;
    for (int k = 0; k < 4000; ++k) {
        const Real offset = (k % 4 == 3) ? Real(1e6) : Real(0);
        const Real size = std::pow(Real(10), rng.uniform(-2, 2));
        // One A in eight and one B in eight has zero length; every fifth pair is near-parallel.
        auto half = [&](bool point) { return point ? Real(0) : rng.uniform(0, 1) * size; };
        Lss a = makeLss(Vec3::Constant(offset) + rng.vec(-1, 1) * size, rng.vec(-1, 1),
                        half(k % 8 == 0), 0);
        Lss b = makeLss(rng.vec(-1, 1) * size, rng.vec(-1, 1), half(k % 8 == 4), 0);
        Pose pose{Vec3::Constant(offset) + rng.vec(-1, 1) * size, rng.rotation()};
        if (k % 5 == 0) {
            // B's axis in A's frame = A's axis turned by a tiny angle.
            const Real angle = std::pow(Real(10), rng.uniform(-12, -3));
            const Vec3 perp = a.axis.unitOrthogonal();
            const Vec3 world_axis = (a.axis + perp * std::tan(angle)).normalized();
            b.axis = (pose.orientation.conjugate() * world_axis).normalized();
        }
        const Real d = referenceDistance(a, b, pose);
        // Radii summing to the distance times (1 + delta), delta in +-1e-3, or exactly (touching).
        const Real delta = (k % 3 == 0) ? Real(0) : rng.uniform(-1e-3, 1e-3);
        const Real sum = d * (1 + delta) + (d == 0 ? size * Real(1e-3) : Real(0));
        a.radius = sum * rng.uniform(0, 1);
        b.radius = sum - a.radius;
        // The reference is the distance of two points of the segments, so d <= r_a + r_b
        // means the capsules share a point: the test must say overlap (touching included). A
        // gap above the test's slack (2.4e-7 of the sizes, plus the transform's rounding
        // slack) must be rejected; in between, either answer is conservative.
        const BvhTransform x = transformFor(a, b, pose);
        const bool got = Traits::overlaps(a, b, x);
        const Real gap = d - (a.radius + b.radius);
        if (gap <= 0) {
            EXPECT_TRUE(got) << "k " << k << " d " << d << " sum " << a.radius + b.radius;
        } else if (gap > Real(1e-5) * (a.half_length + b.half_length + d + size) + 2 * x.tol) {
            EXPECT_FALSE(got) << "k " << k << " gap " << gap;
        }
        (got ? overlapping : separated) += 1;
    }
    // Both outcomes occur in quantity, or the test could not fail.
    EXPECT_GT(overlapping, 1000);
    EXPECT_GT(separated, 1000);
}

TEST(Lss, DistanceLowerBoundIsBelowTheTrueGapAndTight) {
    cdlab_test::Rng rng(77);
    for (int k = 0; k < 2000; ++k) {
        const Lss a = makeLss(rng.vec(-3, 3), rng.vec(-1, 1), rng.uniform(0, 1), rng.uniform(0, 1));
        const Lss b = makeLss(rng.vec(-3, 3), rng.vec(-1, 1), rng.uniform(0, 1), rng.uniform(0, 1));
        const Pose pose{rng.vec(-3, 3), rng.rotation()};
        const Real gap = referenceDistance(a, b, pose) - a.radius - b.radius;
        const Real bound = Traits::distanceLowerBound(a, b, transformFor(a, b, pose));
        EXPECT_LE(bound, gap) << "k " << k;
        EXPECT_GE(bound, gap - Real(1e-5)) << "k " << k;
    }
}

TEST(Lss, FitContainsEveryPointAndFollowsTheLongAxis) {
    cdlab_test::Rng rng(5);
    for (const Real scale : {Real(1e-4), Real(1), Real(1e4)}) {
        for (const Real offset : {Real(0), Real(1e6)}) {
            // A noisy rod along a random direction: length 2 scale, noise 1e-2 scale.
            const Vec3 dir = rng.vec(-1, 1).normalized();
            std::vector<Vec3> pts;
            for (int i = 0; i < 300; ++i) {
                pts.push_back(Vec3::Constant(offset) + dir * rng.uniform(-1, 1) * scale +
                              rng.vec(-1e-2, 1e-2) * scale);
            }
            const Lss s = Traits::fit(pts);
            const Real mag = offset + scale;
            for (const Vec3& p : pts) {
                EXPECT_TRUE(Traits::contains(s, p, Real(64) * collision::kEpsilon * mag))
                    << "scale " << scale << " offset " << offset;
            }
            EXPECT_GT(std::abs(s.axis.dot(dir)), Real(0.999));
            EXPECT_LT(s.radius, Real(0.03) * scale + Real(1e-9) * mag);
            EXPECT_NEAR(s.half_length, scale, Real(0.05) * scale);
        }
    }
    // One point, and a triangle fitted along its longest edge.
    const std::vector<Vec3> one{Vec3(1, 2, 3)};
    const Lss point = Traits::fit(one);
    EXPECT_TRUE(Traits::contains(point, one[0], 0));
    EXPECT_LE(point.radius, Real(1e-12));
    const std::vector<Vec3> tri{Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(1, 1, 0)};
    Mat3 axes;
    ASSERT_TRUE(collision::triangleAxes(tri[0], tri[1], tri[2], &axes));
    const Lss t = Traits::fitWithAxes(tri, axes);
    for (const Vec3& p : tri) EXPECT_TRUE(Traits::contains(t, p, 0));
    EXPECT_NEAR(t.radius, 0.5, 1e-12);  // the apex is 1 above the edge: centred line, radius 1/2
}

}  // namespace
