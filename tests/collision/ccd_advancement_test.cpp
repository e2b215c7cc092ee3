// tests/collision/ccd_advancement_test.cpp -- conservative advancement (timeOfImpact): analytic
// times of impact (sphere vs thin plate, rotating bar vs wall), metamorphic invariance (1e6
// offset, scales 1e-4..1e4, A/B swap), and random pairs against dense sampling with collide():
// the returned time is never later than the first sampled contact, and Separated is never
// contradicted by a sample.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "collision/ccd/ccd.h"
#include "collision/geometry/shape.h"
#include "collision/narrowphase/narrow_phase.h"
#include "test_random.h"
#include "test_shapes.h"

namespace collision {
namespace {

Sweep linear(const Vec3& start, const Vec3& translation) {
    Sweep s;
    s.start.position = start;
    s.translation = translation;
    return s;
}

ToiInput makeInput(const Shape& a, const Sweep& sa, const Shape& b, const Sweep& sb) {
    ToiInput in;
    in.a = &a;
    in.b = &b;
    in.sweep_a = sa;
    in.sweep_b = sb;
    return in;
}

// 5 cm sphere at 1000 m/s, dt = 1/30 (33.3 m in one step) against a 1 cm plate: the plate's
// faces at x = +-0.005, so contact when the centre reaches x = -0.055.
TEST(ConservativeAdvancement, FastSphereAgainstThinPlateMatchesClosedForm) {
    const Shape sphere = Shape::sphere(0.05);
    const Shape plate = Shape::box(Vec3(0.005, 1, 1));
    const Real travel = 1000.0 / 30;
    for (const Real x0 : {-10.0, -1.0, -0.2}) {
        ToiInput in = makeInput(sphere, linear(Vec3(x0, 0.3, -0.2), Vec3(travel, 0, 0)), plate,
                                linear(Vec3::Zero(), Vec3::Zero()));
        const ToiOutput out = timeOfImpact(in);
        const Real exact = (-0.055 - x0) / travel;
        ASSERT_EQ(out.state, CcdState::Hit) << x0;
        // Never later; early by at most the acceptance tolerance (1e-3 * 0.05 m) in travel.
        EXPECT_LE(out.t, exact);
        EXPECT_GE(out.t, exact - 1e-3 * 0.05 / travel);
        EXPECT_LE(out.iterations, 3);
        EXPECT_NEAR(out.normal.x(), 1, 1e-12);
        EXPECT_NEAR(out.point_b.x(), -0.005, 1e-12);
    }
    // Target gap: stop 1 mm before contact.
    ToiInput in = makeInput(sphere, linear(Vec3(-1, 0, 0), Vec3(2, 0, 0)), plate,
                            linear(Vec3::Zero(), Vec3::Zero()));
    in.target_gap = 1e-3;
    const ToiOutput out = timeOfImpact(in);
    ASSERT_EQ(out.state, CcdState::Hit);
    const Real exact = (1 - 0.056) / 2;
    EXPECT_LE(out.t, exact);
    EXPECT_GE(out.t, exact - 1e-3 * 0.05 / 2);
    // Missing the plate (passing beside it) is Separated.
    in.sweep_a = linear(Vec3(-1, 1.2, 0), Vec3(2, 0, 0));
    EXPECT_EQ(timeOfImpact(in).state, CcdState::Separated);
}

// A thin bar (half extents 1, 0.02, 0.02) spinning about z at its centre, from along y towards
// x, reaches a wall whose face is x = 0.8. The bar's extent along x at angle alpha from the x
// axis is cos(alpha) + 0.02 sin(alpha) = R cos(alpha - beta), R = sqrt(1 + 0.02^2),
// beta = atan(0.02): contact at alpha* = beta + acos(0.8 / R).
TEST(ConservativeAdvancement, RotatingBarAgainstWallMatchesClosedForm) {
    const Shape bar = Shape::box(Vec3(1, 0.02, 0.02));
    const Shape wall = Shape::box(Vec3(0.05, 5, 5));
    const Real turn = 1.2;  // rad over the step, from alpha = pi/2 down
    Sweep sa;
    sa.start.orientation = Quat(Eigen::AngleAxis<Real>(M_PI / 2, Vec3::UnitZ()));
    sa.rotation = Vec3(0, 0, -turn);
    const ToiInput in = makeInput(bar, sa, wall, linear(Vec3(0.85, 0, 0), Vec3::Zero()));
    const ToiOutput out = timeOfImpact(in);
    const Real big_r = std::sqrt(1 + 0.02 * 0.02);
    const Real alpha = std::atan(0.02) + std::acos(0.8 / big_r);
    const Real exact = (M_PI / 2 - alpha) / turn;
    ASSERT_EQ(out.state, CcdState::Hit);
    EXPECT_LE(out.t, exact);
    // Tolerance 1e-3 * bounding radius of the bar (~1 m) of gap; the tip moves ~1.2 m per
    // unit t across the wall normal at contact (sin(alpha) ~ 0.6, so ~0.7 m): 2e-3 in t.
    EXPECT_GE(out.t, exact - 2e-3);
    EXPECT_LT(out.iterations, 64);
    EXPECT_NEAR(out.normal.x(), 1, 1e-9);
    RecordProperty("bar_iterations", out.iterations);
    // Turning only 0.6 rad (to alpha = 0.97, extent 0.58 < 0.8) never touches it.
    ToiInput away = in;
    away.sweep_a.rotation = Vec3(0, 0, -0.6);
    EXPECT_EQ(timeOfImpact(away).state, CcdState::Separated);
}

// The acceptance tolerance trades iterations for an earlier stop, never for a late one: the
// advancement visits the same sequence of conservative times whatever the tolerance and stops
// at the first within target_gap + tolerance, so a looser tolerance stops at an earlier (or the
// same) iterate. Same bar and wall as above (closed-form contact time `exact`).
TEST(ConservativeAdvancement, LooserToleranceStopsEarlierWithFewerIterations) {
    const Shape bar = Shape::box(Vec3(1, 0.02, 0.02));
    const Shape wall = Shape::box(Vec3(0.05, 5, 5));
    const Real turn = 1.2;
    Sweep sa;
    sa.start.orientation = Quat(Eigen::AngleAxis<Real>(M_PI / 2, Vec3::UnitZ()));
    sa.rotation = Vec3(0, 0, -turn);
    ToiInput in = makeInput(bar, sa, wall, linear(Vec3(0.85, 0, 0), Vec3::Zero()));
    const Real big_r = std::sqrt(1 + 0.02 * 0.02);
    const Real alpha = std::atan(0.02) + std::acos(0.8 / big_r);
    const Real exact = (M_PI / 2 - alpha) / turn;
    // The gap to the wall is g(t) = 0.8 - R cos(phi), phi = alpha - atan(0.02) + turn (t* - t):
    // convex in t* - t with slope R sin(phi*) turn = 0.6 * 1.2 R at contact, so g <= tol means
    // t >= t* - tol / (0.72 R). The tolerance is relative to the bar's bounding radius
    // |half_extents| (the smaller of the two shapes).
    const Real bar_radius = Vec3(1, 0.02, 0.02).norm();
    const Real rate = 0.6 * turn * big_r;
    Real previous_t = std::numeric_limits<Real>::infinity();
    int previous_iterations = std::numeric_limits<int>::max();
    ToiOutput tightest, loosest;
    for (const Real rel : {1e-6, 1e-4, 1e-3, 1e-2, 1e-1}) {
        in.relative_tolerance = rel;
        const ToiOutput out = timeOfImpact(in);
        ASSERT_EQ(out.state, CcdState::Hit) << rel;
        EXPECT_LE(out.t, exact) << rel;  // never later than the true time of impact
        // Early by at most the tolerance over the closing rate (1e-9 relative: rounding of g).
        EXPECT_GE(out.t, exact - rel * bar_radius / rate * (1 + 1e-9)) << rel;
        EXPECT_LE(out.t, previous_t) << rel;
        EXPECT_LE(out.iterations, previous_iterations) << rel;
        previous_t = out.t;
        previous_iterations = out.iterations;
        if (rel == Real(1e-6)) tightest = out;
        loosest = out;
        RecordProperty("iterations_at_" + std::to_string(rel), out.iterations);
    }
    // The setting acts: five decades looser is strictly earlier and strictly cheaper.
    EXPECT_LT(loosest.t, tightest.t);
    EXPECT_LT(loosest.iterations, tightest.iterations);
    // The default is kToiRelativeTolerance, and an absolute `tolerance` overrides the relative.
    in.relative_tolerance = kToiRelativeTolerance;
    const ToiOutput by_default = timeOfImpact(makeInput(bar, sa, wall, in.sweep_b));
    EXPECT_EQ(timeOfImpact(in).t, by_default.t);
    in.relative_tolerance = 1e-1;
    in.tolerance = 1e-6 * bar_radius;
    EXPECT_EQ(timeOfImpact(in).t, tightest.t);
    // Bad values are bad input: Failed at t = 0.
    in.tolerance = 0;
    in.relative_tolerance = -1;
    EXPECT_EQ(timeOfImpact(in).state, CcdState::Failed);
    in.relative_tolerance = std::numeric_limits<Real>::quiet_NaN();
    EXPECT_EQ(timeOfImpact(in).state, CcdState::Failed);
}

TEST(ConservativeAdvancement, InvariantUnderOffsetScaleAndSwap) {
    const Shape bar = Shape::box(Vec3(1, 0.05, 0.1));
    const Shape pill = Shape::capsule(0.2, 0.5);
    Sweep sa;
    sa.start.position = Vec3(-2, 0.1, 0);
    sa.start.orientation = Quat(Eigen::AngleAxis<Real>(0.3, Vec3(1, 2, 3).normalized()));
    sa.translation = Vec3(3, 0.2, -0.1);
    sa.rotation = Vec3(0.5, -1.0, 2.0);
    Sweep sb;
    sb.start.position = Vec3(1, 0, 0.2);
    sb.translation = Vec3(-0.5, 0, 0);
    sb.rotation = Vec3(0, 1.5, 0);
    const ToiOutput base = timeOfImpact(makeInput(bar, sa, pill, sb));
    ASSERT_EQ(base.state, CcdState::Hit);
    ASSERT_GT(base.t, 0.1);

    // Swap: the same time, the normal reversed.
    const ToiOutput swapped = timeOfImpact(makeInput(pill, sb, bar, sa));
    ASSERT_EQ(swapped.state, CcdState::Hit);
    EXPECT_NEAR(swapped.t, base.t, 2e-4);  // both within the acceptance tolerance of contact
    EXPECT_GT(swapped.normal.dot(-base.normal), 0.99);

    // Offset by 1e6: positions are subtracted first.
    Sweep fa = sa, fb = sb;
    fa.start.position += Vec3::Constant(1e6);
    fb.start.position += Vec3::Constant(1e6);
    const ToiOutput far = timeOfImpact(makeInput(bar, fa, pill, fb));
    ASSERT_EQ(far.state, CcdState::Hit);
    EXPECT_NEAR(far.t, base.t, 1e-8);

    // Scale the whole set-up: t is dimensionless, the tolerance is relative.
    for (const Real k : {1e-4, 1e4}) {
        const Shape bar_k = Shape::box(Vec3(1, 0.05, 0.1) * k);
        const Shape pill_k = Shape::capsule(0.2 * k, 0.5 * k);
        Sweep ka = sa, kb = sb;
        ka.start.position *= k;
        ka.translation *= k;
        kb.start.position *= k;
        kb.translation *= k;
        const ToiOutput scaled = timeOfImpact(makeInput(bar_k, ka, pill_k, kb));
        ASSERT_EQ(scaled.state, CcdState::Hit) << k;
        EXPECT_NEAR(scaled.t, base.t, 1e-9) << k;
    }
}

// Largest distance of the shape from its origin (what timeOfImpact calls the bounding radius).
using cdlab_test::boundingRadius;

Shape randomShape(cdlab_test::Rng& rng) {
    switch (rng.integer(0, 2)) {
        case 0:
            return Shape::sphere(rng.uniform(0.05, 0.5));
        case 1:
            return Shape::box(rng.vec(0.01, 0.6));
        default:
            return Shape::capsule(rng.uniform(0.05, 0.3), rng.uniform(0.0, 0.6));
    }
}

// Differential test against dense sampling. Sampled first contact t_s (collide() at 4001 evenly
// spaced times) bounds the true first contact from above, so a conservative query must give
// t <= t_s; and when the query says Separated no sample may collide.
TEST(ConservativeAdvancement, NeverLaterThanSampledFirstContactOnRandomPairs) {
    cdlab_test::Rng rng(20261122);
    int hits = 0, separated = 0, failed = 0;
    const int kPairs = 300;
    const int kSamples = 4000;
    for (int i = 0; i < kPairs; ++i) {
        const Shape a = randomShape(rng);
        const Shape b = randomShape(rng);
        Sweep sa, sb;
        sa.start.position = rng.vec(-3, -1);
        sa.start.orientation = rng.rotation();
        sa.translation = rng.vec(1, 4);
        sa.rotation = rng.vec(-3, 3);
        sb.start.position = rng.vec(-0.5, 0.5);
        sb.start.orientation = rng.rotation();
        sb.translation = rng.vec(-1, 1);
        sb.rotation = rng.vec(-3, 3);
        if (i % 2 == 1) {
            // Body-frame spins as well (the engine's torque-free sweep).
            sa.spin = rng.vec(-6, 6);
            sb.spin = rng.vec(-6, 6);
        }
        ToiInput in = makeInput(a, sa, b, sb);
        in.max_iterations = 200;
        const ToiOutput out = timeOfImpact(in);
        ASSERT_TRUE(std::isfinite(out.t));
        Real t_sampled = std::numeric_limits<Real>::infinity();
        for (int k = 0; k <= kSamples; ++k) {
            const Real t = Real(k) / kSamples;
            if (isColliding(collide(a, sa.at(t), b, sb.at(t)).state)) {
                t_sampled = t;
                break;
            }
        }
        if (out.state == CcdState::Overlapped) {
            EXPECT_EQ(t_sampled, 0) << i;
            continue;
        }
        if (out.state == CcdState::Separated) {
            ++separated;
            EXPECT_EQ(t_sampled, std::numeric_limits<Real>::infinity()) << i;
            continue;
        }
        if (out.state == CcdState::Failed) ++failed;
        if (out.state == CcdState::Hit) ++hits;
        EXPECT_LE(out.t, t_sampled) << i;
        // Nothing collides on [0, t] (checked at 64 sample times).
        for (int k = 0; k <= 64; ++k) {
            const Real t = out.t * k / 64;
            EXPECT_FALSE(isColliding(collide(a, sa.at(t), b, sb.at(t)).state)) << i << " " << t;
        }
        if (out.state == CcdState::Hit) {
            // Tight: at t the shapes are within the tolerance (1e-3 * smaller radius) of contact.
            const CollideOutput c = collide(a, sa.at(out.t), b, sb.at(out.t));
            const Real tol = kToiRelativeTolerance * std::min(boundingRadius(a), boundingRadius(b));
            EXPECT_LE(c.distance, tol * (1 + 1e-9)) << i;
        }
    }
    RecordProperty("hits", hits);
    RecordProperty("separated", separated);
    RecordProperty("failed", failed);
    // Both outcomes are exercised (measured: 61 hits, 239 separated, 0 failed of 300).
    EXPECT_GT(hits, kPairs / 10);
    EXPECT_GT(separated, kPairs / 10);
    EXPECT_EQ(failed, 0);
}

// A deforming shape: its surface may move deform_speed (m per step) towards the other shape on
// top of the rigid motion, so the gap of 0.5 m between a plate closing at 0.3 m a step and a
// sphere closes by t = 0.5 / (0.3 + 0.7) at the earliest. The advancement must stop by then,
// and it cannot unless it both bounds the rate (one advance of 0.5 / 1) and takes the surface's
// displacement so far off the gap it measures on the t = 0 shapes (a second advance would pass
// the bound). Bad deform speeds fail.
//
//   plate |-> 0.3/step, surface up to 0.7/step   <- 0.5 m ->   ( sphere )
TEST(ConservativeAdvancement, DeformSpeedBoundsTheMovingSurface) {
    const Shape plate = Shape::box(Vec3(0.05, 1, 1));
    const Shape sphere = Shape::sphere(0.25);
    ToiInput in = makeInput(plate, linear(Vec3(-0.8, 0, 0), Vec3(0.3, 0, 0)), sphere,
                            linear(Vec3::Zero(), Vec3::Zero()));
    in.tolerance = 1e-9;
    const ToiOutput rigid = timeOfImpact(in);
    ASSERT_EQ(rigid.state, CcdState::Separated);  // 0.3 of the 0.5 m gap in the step
    for (const bool on_a : {true, false}) {
        ToiInput d = in;
        (on_a ? d.deform_speed_a : d.deform_speed_b) = 0.7;
        const ToiOutput out = timeOfImpact(d);
        ASSERT_EQ(out.state, CcdState::Hit) << on_a;
        EXPECT_LE(out.t, 0.5 / (0.3 + 0.7)) << on_a;
        EXPECT_GE(out.t, 0.5 / (0.3 + 0.7) - 1e-6) << on_a;
        // A slower deformation never closes the gap in the step.
        (on_a ? d.deform_speed_a : d.deform_speed_b) = 0.15;
        EXPECT_EQ(timeOfImpact(d).state, CcdState::Separated) << on_a;
    }
    using Limits = std::numeric_limits<Real>;
    for (const Real bad : {Real(-0.1), Limits::quiet_NaN(), Limits::infinity()}) {
        ToiInput d = in;
        d.deform_speed_b = bad;
        EXPECT_EQ(timeOfImpact(d).state, CcdState::Failed) << bad;
    }
}

// Regression: when the cores themselves overlap at t = 0 (a capsule's segment through a thin
// plate), the query reported Hit at t = 0 with a zero normal instead of Overlapped: the
// Overlapped branch fell through to the gap test, whose zero direction gave a gap of 0.
//
//        |#|
//   =====|#|=====   capsule along x, centred in the plate
//        |#|
TEST(ConservativeAdvancement, CoresOverlappingAtStartAreOverlapped) {
    const Shape capsule = Shape::capsule(0.05, 0.5);
    const Shape plate = Shape::box(Vec3(0.005, 1, 1));
    Sweep sa;
    sa.start.orientation = Quat(Eigen::AngleAxis<Real>(M_PI / 2, Vec3::UnitZ()));
    sa.translation = Vec3(0.1, 0, 0);
    const ToiInput in = makeInput(capsule, sa, plate, linear(Vec3(0.1, 0, 0), Vec3::Zero()));
    ASSERT_EQ(collide(capsule, sa.start, plate, in.sweep_b.start).state, ContactState::Penetrating);
    const ToiOutput out = timeOfImpact(in);
    EXPECT_EQ(out.state, CcdState::Overlapped);
    EXPECT_EQ(out.t, 0);
    EXPECT_EQ(out.distance, 0);
}

TEST(ConservativeAdvancement, OverlapCapAndBadInput) {
    const Shape s = Shape::sphere(0.5);
    ToiInput in =
        makeInput(s, linear(Vec3::Zero(), Vec3(1, 0, 0)), s, linear(Vec3(0.8, 0, 0), Vec3::Zero()));
    EXPECT_EQ(timeOfImpact(in).state, CcdState::Overlapped);

    // The iteration cap gives Failed with a safe time (no contact on [0, t]).
    const Shape bar = Shape::box(Vec3(1, 0.02, 0.02));
    const Shape wall = Shape::box(Vec3(0.05, 5, 5));
    Sweep sa;
    sa.start.orientation = Quat(Eigen::AngleAxis<Real>(M_PI / 2, Vec3::UnitZ()));
    sa.rotation = Vec3(0, 0, -1.2);
    ToiInput capped = makeInput(bar, sa, wall, linear(Vec3(0.85, 0, 0), Vec3::Zero()));
    capped.max_iterations = 2;
    const ToiOutput out = timeOfImpact(capped);
    EXPECT_EQ(out.state, CcdState::Failed);
    EXPECT_EQ(out.iterations, 2);
    EXPECT_GT(out.t, 0);
    EXPECT_FALSE(isColliding(collide(bar, sa.at(out.t), wall, capped.sweep_b.at(out.t)).state));

    ToiInput bad = in;
    bad.sweep_a.translation.x() = std::numeric_limits<Real>::quiet_NaN();
    EXPECT_EQ(timeOfImpact(bad).state, CcdState::Failed);
    bad = in;
    bad.b = nullptr;
    EXPECT_EQ(timeOfImpact(bad).state, CcdState::Failed);
}

TEST(ConservativeAdvancement, SweepSpinTurnsInTheBodyFrame) {
    // R(t rotation) q0 R(t spin): with q0 a quarter turn about z, a body spin about local x is
    // a turn about world y.
    Sweep s;
    s.start.orientation = Quat(Eigen::AngleAxis<Real>(M_PI / 2, Vec3::UnitZ()));
    s.spin = Vec3(0.8, 0, 0);
    const Pose p = s.at(0.5);
    const Quat expected = Quat(Eigen::AngleAxis<Real>(0.4, Vec3::UnitY())) * s.start.orientation;
    EXPECT_NEAR(p.orientation.angularDistance(expected), 0, 1e-12);
}

TEST(ConservativeAdvancement, SweepPoseFollowsTheRotationVector) {
    Sweep s;
    s.start.position = Vec3(1, 2, 3);
    s.translation = Vec3(2, 0, 0);
    s.rotation = Vec3(0, 0, 3 * M_PI);  // more than half a turn is kept, not wrapped
    const Pose half = s.at(0.5);
    EXPECT_NEAR((half.position - Vec3(2, 2, 3)).norm(), 0, 1e-15);
    EXPECT_NEAR(
        half.orientation.angularDistance(Quat(Eigen::AngleAxis<Real>(1.5 * M_PI, Vec3::UnitZ()))),
        0, 1e-12);
}

}  // namespace
}  // namespace collision
