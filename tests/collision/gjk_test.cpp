// tests/collision/gjk_test.cpp -- GJK distance against closed forms, and its failure behaviour
// (iteration cap, degenerate input: never NaN, never a hang).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

// Private narrow-phase header (collision/src is not on the test's include path).
#include "narrowphase/gjk.h"
#include "test_random.h"

namespace {

using collision::ConvexCore;
using collision::gjkDistance;
using collision::GjkState;
using collision::Pose;
using collision::Quat;
using collision::Real;
using collision::RelativePose;
using collision::relativePose;
using collision::Shape;
using collision::Vec3;

// RTCD 5.1.3.1: distance from a point to an axis-aligned box centred at the origin.
Real pointBoxDistance(const Vec3& p, const Vec3& h) {
    const Vec3 q = p.cwiseMax(-h).cwiseMin(h);
    return (p - q).norm();
}

TEST(Gjk, PointToBoxMatchesClosedFormOnRandomPoses) {
    cdlab_test::Rng rng(11);
    const Shape box = Shape::box(Vec3(1, 2, 0.5));
    const ConvexCore core_box = ConvexCore::fromShape(box);
    ConvexCore point;  // a sphere core: the point at B's origin
    int separated = 0;
    int overlapping = 0;
    for (int n = 0; n < 5000; ++n) {
        Pose pose_point;
        pose_point.position = rng.vec(-2.5, 2.5);
        const RelativePose rel = relativePose(Pose{}, pose_point);
        const auto out = gjkDistance(core_box, point, rel, Real(3));
        const Real expected = pointBoxDistance(pose_point.position, box.half_extents);
        if (expected == 0) {
            ASSERT_EQ(out.state, GjkState::Overlapping) << n;
            ++overlapping;
        } else {
            ASSERT_EQ(out.state, GjkState::Separated) << n;
            ASSERT_NEAR(out.distance, expected, 1e-10 * (1 + expected)) << n;
            ASSERT_LE(out.lower_bound, expected + 1e-12) << n;
            ++separated;
        }
        ASSERT_LE(out.iterations, collision::kGjkMaxIterations);
    }
    EXPECT_GT(separated, 1000);
    EXPECT_GT(overlapping, 100);
}

TEST(Gjk, RotatedBoxToRotatedBoxFaceDistance) {
    // B, turned 90 degrees about z, spans 1 along A's x; moved 5 along it: face gap 5 - 1 - 1.
    const Shape a = Shape::box(Vec3(1, 2, 3));
    const Shape b = Shape::box(Vec3(2, 1, 3));
    Pose pose_a;
    pose_a.orientation = Quat(Eigen::AngleAxis<Real>(0.3, Vec3(1, 2, 3).normalized()));
    pose_a.position = Vec3(10, -3, 7);
    Pose local;
    local.position = Vec3(5, 0, 0);
    local.orientation = Quat(Eigen::AngleAxis<Real>(M_PI / 2, Vec3::UnitZ()));
    const Pose pose_b = pose_a * local;
    const auto out = gjkDistance(ConvexCore::fromShape(a), ConvexCore::fromShape(b),
                                 relativePose(pose_a, pose_b), Real(4));
    ASSERT_EQ(out.state, GjkState::Separated);
    EXPECT_NEAR(out.distance, 3.0, 1e-9);
}

TEST(Gjk, DegenerateInputNeverProducesNaN) {
    // Zero-size box and a point at the same place; a segment of length zero; huge coordinates.
    const ConvexCore zero_box = ConvexCore::fromShape(Shape::box(Vec3::Zero()));
    const ConvexCore point = ConvexCore::fromShape(Shape::sphere(0));
    const ConvexCore zero_segment = ConvexCore::fromShape(Shape::capsule(0, 0));
    const ConvexCore flat_tri = ConvexCore::triangle(Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2));
    RelativePose same;
    for (const ConvexCore* a : {&zero_box, &point, &zero_segment, &flat_tri}) {
        for (const ConvexCore* b : {&zero_box, &point, &zero_segment, &flat_tri}) {
            for (const Vec3& offset :
                 {Vec3(0, 0, 0), Vec3(1e-300, 0, 0), Vec3(1, 1, 1), Vec3(1e150, -1e150, 3)}) {
                RelativePose rel;
                rel.position = offset;
                const auto out = gjkDistance(*a, *b, rel, Real(1));
                EXPECT_FALSE(std::isnan(out.distance));
                EXPECT_LE(out.iterations, collision::kGjkMaxIterations);
            }
        }
    }
}

TEST(Gjk, HullCoresConvergeWithinTheCap) {
    // Round hulls (many vertices on a sphere) are GJK's slowest case: it must still stop.
    cdlab_test::Rng rng(5);
    auto hull = std::make_shared<collision::ConvexPolytope>();
    for (int i = 0; i < 400; ++i) {
        Vec3 p = rng.vec(-1, 1);
        if (p.norm() < 0.1) continue;
        hull->vertices.push_back(p.normalized());
    }
    const Shape shape = Shape::convexHull(hull);
    const ConvexCore core = ConvexCore::fromShape(shape);
    int failed = 0;
    for (int n = 0; n < 500; ++n) {
        Pose pose_b;
        pose_b.position = rng.vec(-3, 3);
        pose_b.orientation = rng.rotation();
        const auto out = gjkDistance(core, core, relativePose(Pose{}, pose_b), Real(1));
        failed += out.state == GjkState::Failed;
        if (out.state == GjkState::Separated) {
            // Two unit-ish spheres: the distance is within the hull's faceting of |d| - 2.
            EXPECT_NEAR(out.distance, std::max(pose_b.position.norm() - 2, Real(0)), 0.15);
        }
    }
    EXPECT_EQ(failed, 0);
}

}  // namespace
