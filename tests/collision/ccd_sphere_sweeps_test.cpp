// tests/collision/ccd_sphere_sweeps_test.cpp -- timeOfImpactSphereSweeps, the engine's exact
// sphere-sphere time of impact, against a bisection reference in long double on random and
// adversarial motions: same verdict, and the time never after the true first contact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "collision/ccd/ccd.h"
#include "collision/geometry/shape.h"
#include "test_random.h"

namespace {

using collision::CcdState;
using collision::Real;
using collision::Shape;
using collision::Sweep;
using collision::ToiInput;
using collision::ToiOutput;
using collision::Vec3;
using LVec = Eigen::Matrix<long double, 3, 1>;

struct Case {
    Vec3 c0a, da;
    Real ra;
    Vec3 c0b, db;
    Real rb;
    Real gap = 0;
};

ToiOutput run(const Case& k, const Vec3& rotation = Vec3::Zero()) {
    const Shape a = Shape::sphere(k.ra);
    const Shape b = Shape::sphere(k.rb);
    ToiInput in;
    in.a = &a;
    in.b = &b;
    in.sweep_a.start.position = k.c0a;
    in.sweep_a.translation = k.da;
    in.sweep_a.rotation = rotation;  // a sphere's rotation must not matter
    in.sweep_b.start.position = k.c0b;
    in.sweep_b.translation = k.db;
    in.target_gap = k.gap;
    return collision::timeOfImpactSphereSweeps(in);
}

// Gap minus target in long double: |d0 + t dv| - (ra + rb + gap), convex in t.
long double gapAt(const Case& k, long double t) {
    const LVec d0 = k.c0b.cast<long double>() - k.c0a.cast<long double>();
    const LVec dv = k.db.cast<long double>() - k.da.cast<long double>();
    return (d0 + t * dv).norm() - (static_cast<long double>(k.ra) + k.rb + k.gap);
}

// Reference: the distance is convex in t, so the first root (if any) lies in [0, t_min] where
// t_min minimises it on [0, 1]; bisection there in long double. nullopt: never reaches it.
std::optional<long double> referenceToi(const Case& k) {
    const LVec d0 = k.c0b.cast<long double>() - k.c0a.cast<long double>();
    const LVec dv = k.db.cast<long double>() - k.da.cast<long double>();
    const long double a = dv.squaredNorm();
    const long double t_min = a > 0 ? std::clamp(-d0.dot(dv) / a, 0.0L, 1.0L) : 0.0L;
    if (gapAt(k, t_min) > 0) return std::nullopt;
    if (gapAt(k, 0) <= 0) return 0.0L;
    long double lo = 0, hi = t_min;  // gap(lo) > 0 >= gap(hi)
    for (int i = 0; i < 200 && hi - lo > 0; ++i) {
        const long double mid = (lo + hi) / 2;
        if (mid == lo || mid == hi) break;
        (gapAt(k, mid) > 0 ? lo : hi) = mid;
    }
    return hi;
}

// The scale of the case's distances, for a relative grazing margin.
Real sizeOf(const Case& k) {
    return std::max({(k.c0b - k.c0a).norm(), (k.db - k.da).norm(), k.ra + k.rb + k.gap});
}

// Compares one case with the reference; returns whether it hit.
bool checkCase(const Case& k, const char* what) {
    const ToiOutput o = run(k);
    const std::optional<long double> ref = referenceToi(k);
    EXPECT_NE(o.state, CcdState::Failed) << what;
    // Within rounding of grazing the verdict may go either way; both must still be safe.
    const long double closest = [&] {
        long double m = gapAt(k, 0);
        for (int i = 1; i <= 1000; ++i) m = std::min(m, gapAt(k, i / 1000.0L));
        return m;
    }();
    const bool grazing = std::abs(closest) < 1e-6L * sizeOf(k);
    if (!ref) {
        if (!grazing) {
            EXPECT_EQ(o.state, CcdState::Separated) << what;
        }
        return false;
    }
    if (gapAt(k, 0) < -(static_cast<long double>(k.gap)) - 1e-12L * sizeOf(k)) {
        EXPECT_EQ(o.state, CcdState::Overlapped) << what;
        return true;
    }
    if (o.state == CcdState::Separated) {
        EXPECT_TRUE(grazing) << what << ": missed a contact at t = " << static_cast<double>(*ref);
        return false;
    }
    if (o.state != CcdState::Hit) return true;
    // Never after the true first contact, and close to it (the slack and the rounding of the
    // relative quantities; a double root moves with the square root of the rounding).
    EXPECT_LE(static_cast<long double>(o.t), *ref) << what;
    const Real accuracy = grazing ? 1e-4 : 1e-9;
    EXPECT_NEAR(o.t, static_cast<double>(*ref), accuracy) << what;
    EXPECT_EQ(o.iterations, 1) << what;
    return true;
}

TEST(SphereSweepToi, RandomMotionsAgreeWithBisectionAndNeverReportLate) {
    cdlab_test::Rng rng(20261126);
    int hits = 0, checked = 0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
        Case k;
        k.c0a = rng.vec(-3, 3);
        k.da = rng.vec(-6, 6);
        k.ra = rng.uniform(0.3, 1.5);
        k.c0b = rng.vec(-3, 3);
        // Roughly towards A half of the time, so hits and misses both occur often.
        k.db = rng.uniform(0, 1) < 0.5
                   ? Vec3(rng.vec(-6, 6))
                   : Vec3(k.da + (k.c0a - k.c0b) * rng.uniform(0, 2) + rng.vec(-1, 1));
        k.rb = rng.uniform(0.3, 1.5);
        k.gap = i % 2 == 0 ? 0 : rng.uniform(0, 0.1);
        // Keep the start separated (overlap at t = 0 is the adversarial set's job).
        if ((k.c0b - k.c0a).norm() <= k.ra + k.rb + k.gap) continue;
        ++checked;
        if (checkCase(k, "random")) ++hits;
    }
    // Both verdicts must occur often enough for the comparison to mean something.
    EXPECT_GT(checked, n / 4);
    EXPECT_GT(hits, checked / 5);
    EXPECT_LT(hits, 4 * checked / 5);
}

TEST(SphereSweepToi, AdversarialMotions) {
    const Vec3 o = Vec3::Zero();
    // Head-on at high speed: 1e4 m in one step, contact at t = (1e4 - 2) / 2e4.
    checkCase({Vec3(-5e3, 0, 0), Vec3(1e4, 0, 0), 1, Vec3(5e3, 0, 0), Vec3(-1e4, 0, 0), 1},
              "head-on");
    // Touching at t = 0: approaching is a Hit at 0, separating is Separated.
    const ToiOutput touch_in = run({o, o, 1, Vec3(2, 0, 0), Vec3(-1, 0, 0), 1});
    EXPECT_EQ(touch_in.state, CcdState::Hit);
    EXPECT_EQ(touch_in.t, 0);
    EXPECT_EQ(run({o, o, 1, Vec3(2, 0, 0), Vec3(1, 0, 0), 1}).state, CcdState::Separated);
    // Already overlapping.
    EXPECT_EQ(run({o, o, 1, Vec3(1.5, 0, 0), Vec3(1, 0, 0), 1}).state, CcdState::Overlapped);
    // Within the target gap but not touching: a Hit at 0 with the present gap.
    const ToiOutput within = run({o, o, 1, Vec3(2.05, 0, 0), Vec3(-1, 0, 0), 1, 0.1});
    EXPECT_EQ(within.state, CcdState::Hit);
    EXPECT_EQ(within.t, 0);
    EXPECT_NEAR(within.distance, 0.05, 1e-12);
    // Grazing: passes at exactly centre distance 2, and a near miss.
    checkCase({o, o, 1, Vec3(-5, 2, 0), Vec3(10, 0, 0), 1}, "grazing");
    checkCase({o, o, 1, Vec3(-5, 2 + 1e-9, 0), Vec3(10, 0, 0), 1}, "near miss");
    // Huge and tiny radii.
    checkCase({o, o, 1e3, Vec3(2e3, 0, 0), Vec3(-2e3, 3, 0), 1e-6}, "huge vs tiny");
    checkCase({o, o, 1e-6, Vec3(3e-6, 1e-7, 0), Vec3(-4e-6, 0, 0), 1e-6}, "tiny");
    // Far from the origin.
    const Vec3 far(1e6 + 0.1, -3e6 - 0.3, 7e6 + 0.7);
    checkCase({far, Vec3(1, 0.5, 0), 0.5, far + Vec3(3, 0.25, 0), Vec3(-2, 0, 0.1), 0.75}, "far");
    // Parallel motion: never closer, whatever the speed.
    EXPECT_EQ(run({o, Vec3(50, 0, 0), 1, Vec3(5, 0, 0), Vec3(50, 0, 0), 1}).state,
              CcdState::Separated);
    // Non-finite input fails safe at t = 0.
    const ToiOutput bad = run({o, Vec3(NAN, 0, 0), 1, Vec3(5, 0, 0), o, 1});
    EXPECT_EQ(bad.state, CcdState::Failed);
    EXPECT_EQ(bad.t, 0);
}

// The witnesses lie on the spheres at t, the normal along the centres, and the spheres' spin
// does not change the answer.
TEST(SphereSweepToi, WitnessesAndRotationInvariance) {
    const Case k{Vec3(0, 0, 0), Vec3(1, 0, 0), 0.5, Vec3(4, 0.3, 0), Vec3(-4, 0, 0), 0.25, 0.01};
    const ToiOutput plain = run(k);
    ASSERT_EQ(plain.state, CcdState::Hit);
    const ToiOutput spun = run(k, Vec3(0, 30, 5));
    EXPECT_EQ(spun.t, plain.t);
    const Vec3 ca = k.c0a + plain.t * k.da;
    const Vec3 cb = k.c0b + plain.t * k.db;
    EXPECT_NEAR((plain.point_a - ca).norm(), 0.5, 1e-12);
    EXPECT_NEAR((plain.point_b - cb).norm(), 0.25, 1e-12);
    EXPECT_NEAR(plain.normal.dot((cb - ca).normalized()), 1, 1e-12);
    // Stopped just short of the target gap, never inside it.
    EXPECT_GE(plain.distance, 0.01 - 1e-12);
    EXPECT_LT(plain.distance, 0.01 + 1e-9);
}

}  // namespace
