// tests/collision/ccd_articulated_test.cpp -- articulated time of impact
// (timeOfImpactArticulated) against a brute-force reference: 4096 samples of collide() along the
// step, then bisection between the last sample apart and the first touching. Random arms
// (2..6 links of capsules, boxes, spheres and hulls) sweeping past static and moving boxes,
// spheres and thin plates: never later than the reference, never Separated when it finds
// contact, and within the tolerance of contact when it reports a Hit. Adversarial cases: a
// joint turning several times per step through a plate that both step ends clear, touching and
// overlapping at s = 0, grazing, a long chain's tip, scales 1e-3..1e3 far from the origin, zero
// motion, prismatic-only chains, link against link, the iteration cap.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "collision/ccd/chain.h"
#include "collision/geometry/convex_hull.h"
#include "collision/geometry/shape.h"
#include "collision/narrowphase/narrow_phase.h"
#include "test_chains.h"
#include "test_random.h"
#include "test_shapes.h"

namespace collision {
namespace {

constexpr Real kPi = Real(M_PI);

// How much later than the reference a time of impact may be, as a fraction of the step: the
// rounding of the gap (relative to the scene's size, a few 1e-16) turned into time, far below
// this; the reference's bisection stops at 1e-13.
constexpr Real kTimeSlack = Real(1e-9);

// The query places both sides about the first chain's base (chain.h); the reference does the
// same, so that it is as exact as the query far from the world origin.
Vec3 originOf(const ArticulatedToiInput& in) {
    if (in.side_a.chain != nullptr) return in.side_a.chain->base.position;
    if (in.side_b.chain != nullptr) return in.side_b.chain->base.position;
    return in.side_a.sweep.start.position;
}

Pose sidePoseAt(const ArticulatedToiInput& in, const ArticulatedSide& side, Real s) {
    const Vec3 origin = originOf(in);
    if (side.chain == nullptr) {
        Sweep shifted = side.sweep;
        shifted.start.position -= origin;
        return shifted.at(s);
    }
    return linkFrame(*side.chain, side.link, in.t0 + s * (in.t1 - in.t0), origin) *
           side.shape_in_link;
}

ContactState contactAt(const ArticulatedToiInput& in, Real s) {
    return collide(*in.side_a.shape, sidePoseAt(in, in.side_a, s), *in.side_b.shape,
                   sidePoseAt(in, in.side_b, s))
        .state;
}

// Brute force: the first of 4096 samples in contact, then bisection between it and the sample
// before (apart) down to 1e-13 of the step (or Real's resolution). Returns the earliest step fraction seen in contact,
// or a negative number when no sample touches.
Real referenceFirstContact(const ArticulatedToiInput& in, int samples = 4096) {
    const ToiOutput r = firstContactSampled(in, samples);
    EXPECT_NE(r.state, CcdState::Failed);
    if (r.state == CcdState::Separated || r.state == CcdState::Failed) return -1;
    if (r.t == 0) return 0;
    Real lo = r.t - std::clamp(in.t_max, Real(0), Real(1)) / samples;
    Real hi = r.t;
    // 1e-13 of the step, or the resolution of Real there (float), at most 64 halvings.
    for (int i = 0; i < 64 && hi - lo > std::max(Real(1e-13), 4 * kEpsilon * hi); ++i) {
        const Real mid = (lo + hi) / 2;
        if (contactAt(in, mid) == ContactState::Separated) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return hi;
}

Shape randomHull(cdlab_test::Rng& rng, Real size) {
    std::vector<Vec3> points;
    for (int i = 0; i < 12; ++i) points.push_back(rng.vec(-1, 1) * size);
    return Shape::convexHull(std::make_shared<ConvexPolytope>(computeConvexHull(points).hull));
}

Shape randomShape(cdlab_test::Rng& rng, Real size) {
    switch (rng.integer(0, 3)) {
        case 0:
            return Shape::sphere(size * rng.uniform(0.3, 1));
        case 1:
            return Shape::box(rng.vec(0.2, 1) * size);
        case 2:
            return Shape::capsule(size * rng.uniform(0.1, 0.4), size * rng.uniform(0.3, 1));
        default:
            return randomHull(rng, size);
    }
}

// The sides' shapes must outlive the input; a case owns them.
struct Case {
    Chain chain;
    std::vector<Shape> link_shapes;
    std::vector<Pose> shape_in_link;
    Shape obstacle;
    Sweep obstacle_sweep;
    Real t0 = 0;
    Real t1 = 0;

    ArticulatedToiInput input(int link) const {
        ArticulatedToiInput in;
        in.side_a.shape = &link_shapes[static_cast<std::size_t>(link)];
        in.side_a.chain = &chain;
        in.side_a.link = link;
        in.side_a.shape_in_link = shape_in_link[static_cast<std::size_t>(link)];
        in.side_b.shape = &obstacle;
        in.side_b.sweep = obstacle_sweep;
        in.t0 = t0;
        in.t1 = t1;
        return in;
    }
};

// An arm of `links` links (scale `scale`, base `base` from the world origin) with a shape on
// each link, and an obstacle (box, sphere, thin plate) placed near where a random link passes
// at a random time of the step, sometimes moving itself.
Case randomCase(cdlab_test::Rng& rng, int links, Real scale, Real base) {
    Case c;
    c.chain = cdlab_test::randomChain(rng, links, scale, base, rng.uniform(0.5, 20));
    for (int i = 0; i < links; ++i) {
        c.link_shapes.push_back(randomShape(rng, scale * Real(0.4)));
        Pose p;
        p.position = rng.vec(-0.3, 0.3) * scale;
        p.orientation = rng.rotation();
        c.shape_in_link.push_back(p);
        c.chain.link_radius[static_cast<std::size_t>(i)] =
            p.position.norm() + cdlab_test::boundingRadius(c.link_shapes.back());
    }
    c.t0 = rng.uniform(-0.5, 1);
    c.t1 = c.t0 + rng.uniform(0.05, 0.6);
    switch (rng.integer(0, 2)) {
        case 0:
            c.obstacle = Shape::box(rng.vec(0.2, 1) * scale);
            break;
        case 1:
            c.obstacle = Shape::sphere(scale * rng.uniform(0.2, 1));
            break;
        default:
            c.obstacle = Shape::box(Vec3(0.01, rng.uniform(0.5, 2), rng.uniform(0.5, 2)) * scale);
    }
    const int near = rng.integer(0, links - 1);
    const Real when = c.t0 + (c.t1 - c.t0) * rng.uniform(0, 1);
    c.obstacle_sweep.start.position =
        linkFrame(c.chain, near, when).position + rng.vec(-0.8, 0.8) * scale;
    c.obstacle_sweep.start.orientation = rng.rotation();
    if (rng.integer(0, 3) == 0) {
        c.obstacle_sweep.translation = rng.vec(-1, 1) * scale;
        c.obstacle_sweep.rotation = rng.vec(-2, 2);
    }
    return c;
}

// What every query must satisfy against the reference; returns the reference time (< 0: none).
Real checkAgainstReference(const ArticulatedToiInput& in, const ToiOutput& out,
                           const std::string& what) {
    const Real ref = referenceFirstContact(in);
    if (ref >= 0) {
        // (b) no misses, (a) never later than first contact.
        EXPECT_NE(out.state, CcdState::Separated) << what << " reference " << ref;
        EXPECT_LE(out.t, ref + kTimeSlack) << what;
    }
    if (out.state == CcdState::Hit) {
        // A Hit is within the tolerance of contact: not an early give-up.
        const Real tol =
            in.relative_tolerance * std::min(cdlab_test::boundingRadius(*in.side_a.shape),
                                             cdlab_test::boundingRadius(*in.side_b.shape));
        const CollideOutput c = collide(*in.side_a.shape, sidePoseAt(in, in.side_a, out.t),
                                        *in.side_b.shape, sidePoseAt(in, in.side_b, out.t));
        EXPECT_LE(c.distance, in.target_gap + tol * (1 + 1e-6)) << what;
    }
    if (out.state == CcdState::Failed || out.state == CcdState::Hit) {
        // Safe: apart (or just touching) at every sample before t.
        EXPECT_TRUE(ref < 0 || out.t <= ref + kTimeSlack) << what;
    }
    return ref;
}

TEST(ArticulatedToi, RandomArmsNeverLaterThanSampledFirstContact) {
    cdlab_test::Rng rng(20070805);
    int hits = 0;
    int separated = 0;
    int queries = 0;
    for (int trial = 0; trial < 70; ++trial) {
        const Real scale = std::pow(Real(10), Real(trial % 7 - 3));  // 1e-3 .. 1e3
        const Real base = trial % 2 == 0 ? Real(0) : Real(1e6) * std::max(scale, Real(1e-2));
        const Case c = randomCase(rng, rng.integer(2, 6), scale, base);
        for (int link = 0; link < int(c.chain.joints.size()); ++link) {
            ArticulatedToiInput in = c.input(link);
            if (trial % 3 == 0) in.relative_tolerance = Real(1e-6);
            const ToiOutput out = timeOfImpactArticulated(in);
            const Real ref = checkAgainstReference(
                in, out, "trial " + std::to_string(trial) + " link " + std::to_string(link));
            ++queries;
            if (ref > 0) ++hits;
            if (out.state == CcdState::Separated) ++separated;
        }
    }
    // Both outcomes occur often enough for the comparison to mean something.
    EXPECT_GT(hits, queries / 8) << hits << " of " << queries;
    EXPECT_GT(separated, queries / 8) << separated << " of " << queries;
}

// One link of length 1 (a capsule from the joint to x = 1) turning about z at 3 turns per
// step, from pointing along -x back to -x; a thin plate at x = 0.7 lies in the tip's path.
// Both step ends are clear of it, so a step-end check misses it; the query must not.
//
//      y
//      |      |#|  plate, x in [0.69, 0.71], |y| <= 0.05
//  <---o------|#|---> x        the arm sweeps the full circle of radius 1 several times
struct SpinningArm {
    Chain chain;
    Shape arm = Shape::capsule(0.02, 0.5);
    Pose arm_in_link;
    Shape plate = Shape::box(Vec3(0.01, 0.05, 0.5));
    Sweep plate_sweep;

    SpinningArm() {
        ChainJoint j;
        j.axis = Vec3::UnitZ();
        j.trajectory.kind = JointTrajectory::Kind::Ramp;
        j.trajectory.value = kPi;
        j.trajectory.rate = 6 * kPi;  // per second; the step is [0, 1]
        chain.joints.push_back(j);
        chain.link_radius = {0.52};
        // The capsule runs along local y: turn it onto x, centred half-way along the arm.
        arm_in_link.position = Vec3(0.5, 0, 0);
        arm_in_link.orientation = Quat(Eigen::AngleAxis<Real>(-kPi / 2, Vec3::UnitZ()));
        plate_sweep.start.position = Vec3(0.7, 0, 0);
    }

    ArticulatedToiInput input() const {
        ArticulatedToiInput in;
        in.side_a.shape = &arm;
        in.side_a.chain = &chain;
        in.side_a.link = 0;
        in.side_a.shape_in_link = arm_in_link;
        in.side_b.shape = &plate;
        in.side_b.sweep = plate_sweep;
        in.t0 = 0;
        in.t1 = 1;
        return in;
    }
};

TEST(ArticulatedToi, JointTurningThroughAPlateWithinOneStepIsAHit) {
    const SpinningArm s;
    const ArticulatedToiInput in = s.input();
    ASSERT_EQ(contactAt(in, 0), ContactState::Separated);
    ASSERT_EQ(contactAt(in, 1), ContactState::Separated);
    const ToiOutput out = timeOfImpactArticulated(in);
    ASSERT_EQ(out.state, CcdState::Hit);
    const Real ref = checkAgainstReference(in, out, "spinning arm");
    // Closed form: the arm first meets the plate's lower near corner (0.69, -0.05) when its
    // line comes within the capsule radius, angle 2 pi - atan(0.05/0.69) - asin(0.02/|c|),
    // reached from pi at 6 pi per step.
    const Real corner = std::hypot(Real(0.69), Real(0.05));
    const Real angle = 2 * kPi - std::atan2(Real(0.05), Real(0.69)) - std::asin(0.02 / corner);
    const Real exact = (angle - kPi) / (6 * kPi);
    EXPECT_NEAR(ref, exact, 1e-9);
    EXPECT_LE(out.t, exact);
    EXPECT_GT(out.t, exact - 1e-3);  // stopped within the tolerance, not far before
}

// The same query with the arm and plate scaled by 1e-3..1e3 and translated 1e6 (in units of
// the scale) away: the time of impact is the same up to rounding, never after the reference.
TEST(ArticulatedToi, ScaleAndFarOffsetLeaveTheTimeUnchanged) {
    const SpinningArm unit;
    const Real t_unit = timeOfImpactArticulated(unit.input()).t;
    for (const Real k : {Real(1e-3), Real(1e-1), Real(10), Real(1e3)}) {
        for (const Real offset : {Real(0), Real(1e6)}) {
            SpinningArm s;
            s.chain.base.position = Vec3(offset, -offset, offset / 2) * k;
            s.chain.link_radius[0] *= k;
            s.arm = cdlab_test::scaledShape(s.arm, k);
            s.arm_in_link.position *= k;
            s.plate = cdlab_test::scaledShape(s.plate, k);
            s.plate_sweep.start.position = s.plate_sweep.start.position * k + s.chain.base.position;
            const ArticulatedToiInput in = s.input();
            const ToiOutput out = timeOfImpactArticulated(in);
            ASSERT_EQ(out.state, CcdState::Hit) << k << " " << offset;
            EXPECT_NEAR(out.t, t_unit, 1e-6) << k << " " << offset;
            checkAgainstReference(in, out, "scaled " + std::to_string(k));
        }
    }
}

// The sides swapped (the link as B): the same time, the normal reversed.
TEST(ArticulatedToi, SwappingSidesGivesTheSameTime) {
    const SpinningArm s;
    const ArticulatedToiInput in = s.input();
    ArticulatedToiInput swapped = in;
    std::swap(swapped.side_a, swapped.side_b);
    const ToiOutput a = timeOfImpactArticulated(in);
    const ToiOutput b = timeOfImpactArticulated(swapped);
    ASSERT_EQ(b.state, CcdState::Hit);
    EXPECT_NEAR(a.t, b.t, 1e-9);
    EXPECT_LE((a.normal + b.normal).norm(), 1e-6);
    checkAgainstReference(swapped, b, "swapped");
}

// The cap: with 3 distance queries the spinning arm cannot reach the plate: Failed, at a time
// before the first contact, with the pair apart there.
TEST(ArticulatedToi, IterationCapReturnsFailedAtASafeTime) {
    const SpinningArm s;
    ArticulatedToiInput in = s.input();
    in.max_iterations = 3;
    const ToiOutput out = timeOfImpactArticulated(in);
    ASSERT_EQ(out.state, CcdState::Failed);
    EXPECT_EQ(out.iterations, 3);
    EXPECT_GT(out.t, 0);
    EXPECT_EQ(contactAt(in, out.t), ContactState::Separated);
    checkAgainstReference(in, out, "capped");
}

// A link sphere (radius 0.5 at its frame origin, base at x = 1) and a box whose face is at
// x = 1.5: touching at s = 0 is a Hit at 0; pushed 0.1 further in, or past the sphere's
// centre (the cores overlap), Overlapped.
TEST(ArticulatedToi, TouchingAtStartIsAHitAtZeroAndOverlapIsOverlapped) {
    Chain chain;
    chain.base.position = Vec3(1, 0, 0);
    ChainJoint j;
    j.trajectory.kind = JointTrajectory::Kind::Ramp;
    j.trajectory.rate = 1;
    chain.joints.push_back(j);
    chain.link_radius = {0.5};
    const Shape ball = Shape::sphere(0.5);
    const Shape wall = Shape::box(Vec3(0.5, 1, 1));
    for (const Real inset : {Real(0), Real(0.1), Real(0.6)}) {  // 0.6: centre inside
        ArticulatedToiInput in;
        in.side_a.shape = &ball;
        in.side_a.chain = &chain;
        in.side_a.link = 0;
        in.side_b.shape = &wall;
        in.side_b.sweep.start.position = Vec3(2 - inset, 0, 0);
        in.t1 = 0.1;
        const ToiOutput out = timeOfImpactArticulated(in);
        EXPECT_EQ(out.t, 0);
        EXPECT_EQ(out.state, inset == 0 ? CcdState::Hit : CcdState::Overlapped);
        EXPECT_EQ(firstContactSampled(in, 16).state, out.state);
    }
}

// A 2-link planar arm whose tip ball (radius 0.1 at distance 1 from the turning axis) passes
// a ball of radius 0.2 at distance 1.3 + gap from the axis: gap 0 grazes (Hit or, near the
// grazing point, Failed; never Separated, never after it); gap 0.05 clears (Separated).
TEST(ArticulatedToi, GrazingIsNeverMissedAndAClearPassIsSeparated) {
    for (const Real gap : {Real(0), Real(0.05)}) {
        Chain chain;
        ChainJoint j0;
        j0.trajectory.kind = JointTrajectory::Kind::Ramp;
        j0.trajectory.rate = 2;  // rad per second, over [0, 1]
        chain.joints.push_back(j0);
        ChainJoint j1;
        j1.type = JointType::Fixed;
        j1.parent = 0;
        j1.origin.position = Vec3(1, 0, 0);
        chain.joints.push_back(j1);
        chain.link_radius = {1, 0.1};
        const Shape tip = Shape::sphere(0.1);
        const Shape ball = Shape::sphere(0.2);
        ArticulatedToiInput in;
        in.side_a.shape = &tip;
        in.side_a.chain = &chain;
        in.side_a.link = 1;
        in.side_b.shape = &ball;
        in.side_b.sweep.start.position = Vec3(std::cos(1.0), std::sin(1.0), 0) * (1.3 + gap);
        in.t1 = 1;
        in.max_iterations = 1000;
        const ToiOutput out = timeOfImpactArticulated(in);
        if (gap == 0) {
            EXPECT_NE(out.state, CcdState::Separated);
            EXPECT_LE(out.t, 0.5 + kTimeSlack);
        } else {
            EXPECT_EQ(out.state, CcdState::Separated);
        }
        checkAgainstReference(in, out, "grazing " + std::to_string(gap));
    }
}

// The tip of a 12-link chain, each joint turning slowly (0.3 rad/s about z), sweeps far faster
// than any joint: a plate across its path must be found no later than the reference.
TEST(ArticulatedToi, LongChainTipHitsAPlate) {
    Chain chain;
    for (int i = 0; i < 12; ++i) {
        ChainJoint j;
        j.parent = i - 1;
        j.origin.position = i == 0 ? Vec3::Zero() : Vec3(0.5, 0, 0);
        j.trajectory.kind = JointTrajectory::Kind::Ramp;
        j.trajectory.rate = 0.3;
        chain.joints.push_back(j);
        chain.link_radius.push_back(0.1);
    }
    const Shape tip = Shape::sphere(0.1);
    const Shape plate = Shape::box(Vec3(0.01, 2, 2));
    std::vector<Pose> frames;
    chainFrames(chain, 0, frames);
    const Vec3 tip0 = frames.back().position;  // (5.5, 0, 0) at t = 0
    ArticulatedToiInput in;
    in.side_a.shape = &tip;
    in.side_a.chain = &chain;
    in.side_a.link = 11;
    in.side_b.shape = &plate;
    in.side_b.sweep.start.position = tip0 + Vec3(-1, 1.5, 0);
    in.side_b.sweep.start.orientation = Quat(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitZ()));
    in.t1 = 1;
    in.max_iterations = 200;
    const ToiOutput out = timeOfImpactArticulated(in);
    const Real ref = checkAgainstReference(in, out, "long chain");
    ASSERT_GT(ref, 0);
    EXPECT_EQ(out.state, CcdState::Hit);
}

// No motion at all: a clear pair is Separated after one distance query, a touching one a Hit.
TEST(ArticulatedToi, ZeroMotionIsSeparatedAtOnce) {
    Chain chain;
    chain.joints.push_back(ChainJoint{});
    chain.link_radius = {1};
    const Shape box = Shape::box(Vec3(0.5, 0.5, 0.5));
    ArticulatedToiInput in;
    in.side_a.shape = &box;
    in.side_a.chain = &chain;
    in.side_a.link = 0;
    in.side_b.shape = &box;
    in.side_b.sweep.start.position = Vec3(1.5, 0, 0);
    in.t0 = 3;
    in.t1 = 3.1;
    ToiOutput out = timeOfImpactArticulated(in);
    EXPECT_EQ(out.state, CcdState::Separated);
    EXPECT_EQ(out.iterations, 1);
    EXPECT_EQ(out.t, 1);
    in.side_b.sweep.start.position = Vec3(1, 0, 0);
    out = timeOfImpactArticulated(in);
    EXPECT_EQ(out.state, CcdState::Hit);
    EXPECT_EQ(out.t, 0);
}

// Prismatic joints only: two slides along x (0.5 m/s each) push a unit box at a plate at
// x = 3 whose face is at 2.99; the box's face starts at 0.5 and closes at 1 m/s:
// contact at t = 2.49 s of the step [0, 4].
TEST(ArticulatedToi, PrismaticOnlyChainMatchesClosedForm) {
    Chain chain;
    for (int i = 0; i < 2; ++i) {
        ChainJoint j;
        j.type = JointType::Prismatic;
        j.parent = i - 1;
        j.axis = Vec3::UnitX();
        j.trajectory.kind = JointTrajectory::Kind::Ramp;
        j.trajectory.rate = 0.5;
        chain.joints.push_back(j);
        chain.link_radius.push_back(1);
    }
    const Shape box = Shape::box(Vec3(0.5, 0.5, 0.5));
    const Shape plate = Shape::box(Vec3(0.01, 1, 1));
    ArticulatedToiInput in;
    in.side_a.shape = &box;
    in.side_a.chain = &chain;
    in.side_a.link = 1;
    in.side_b.shape = &plate;
    in.side_b.sweep.start.position = Vec3(3, 0, 0);
    in.t1 = 4;
    const ToiOutput out = timeOfImpactArticulated(in);
    ASSERT_EQ(out.state, CcdState::Hit);
    const Real exact = 2.49 / 4;
    EXPECT_LE(out.t, exact);
    EXPECT_GT(out.t, exact - 1e-3);  // tolerance 5e-4 m at 4 m per step
    EXPECT_LE(out.iterations, 3);    // a pure translation along n converges at once
    checkAgainstReference(in, out, "prismatic");
}

// Link against link, of two chains and of one: two arms swinging into each other, and one arm
// folding its third link back onto its first (links of one chain need no adjacency here).
TEST(ArticulatedToi, LinkAgainstLinkOfTwoChainsAndOfOneChain) {
    cdlab_test::Rng rng(1996);
    int hits = 0;
    for (int trial = 0; trial < 100; ++trial) {
        Case a = randomCase(rng, 3, 1, 0);
        Case b = randomCase(rng, 3, 1, 0);
        b.chain.base.position = a.chain.base.position + rng.vec(-0.6, 0.6);
        a.t1 = a.t0 + 1;
        b.t0 = a.t0;
        b.t1 = a.t1;
        ArticulatedToiInput two = a.input(2);
        two.side_b.shape = &b.link_shapes[1];
        two.side_b.chain = &b.chain;
        two.side_b.link = 1;
        two.side_b.shape_in_link = b.shape_in_link[1];
        const ToiOutput out2 = timeOfImpactArticulated(two);
        if (checkAgainstReference(two, out2, "two chains " + std::to_string(trial)) > 0) ++hits;
        ArticulatedToiInput one = a.input(0);
        one.side_b = a.input(2).side_a;
        const ToiOutput out1 = timeOfImpactArticulated(one);
        if (checkAgainstReference(one, out1, "one chain " + std::to_string(trial)) > 0) ++hits;
    }
    EXPECT_GT(hits, 10) << hits << " of 200";
}

TEST(ArticulatedToi, BadInputIsFailedAtZero) {
    const SpinningArm s;
    ArticulatedToiInput in = s.input();
    in.side_a.link = 1;
    EXPECT_EQ(timeOfImpactArticulated(in).state, CcdState::Failed);
    in = s.input();
    in.t1 = -1;
    EXPECT_EQ(timeOfImpactArticulated(in).state, CcdState::Failed);
    in = s.input();
    in.side_b.shape = nullptr;
    EXPECT_EQ(timeOfImpactArticulated(in).state, CcdState::Failed);
    // A NaN in a trajectory: Failed, never a hang or a Separated.
    SpinningArm bad;
    bad.chain.joints[0].trajectory.rate = std::nan("");
    const ToiOutput out = timeOfImpactArticulated(bad.input());
    EXPECT_EQ(out.state, CcdState::Failed);
    EXPECT_EQ(out.t, 0);
}

}  // namespace
}  // namespace collision
