// tests/collision/chain_test.cpp -- articulated chains (collision/ccd/chain.h): joint
// trajectories against their closed forms and against dense sampling (range and maxRate never
// inside / below what at() does), forward kinematics against hand-computed poses (planar
// 2-link arm, prismatic slide, fixed joint, a branch), and the per-link motion bounds against
// finite differences of forward kinematics on random chains.
#include "collision/ccd/chain.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "test_chains.h"
#include "test_random.h"

namespace collision {
namespace {

constexpr Real kPi = Real(M_PI);

JointTrajectory constant(Real q) {
    JointTrajectory j;
    j.kind = JointTrajectory::Kind::Constant;
    j.value = q;
    return j;
}

JointTrajectory ramp(Real q0, Real rate) {
    JointTrajectory j;
    j.kind = JointTrajectory::Kind::Ramp;
    j.value = q0;
    j.rate = rate;
    return j;
}

JointTrajectory sine(Real offset, Real amplitude, Real frequency, Real phase) {
    JointTrajectory j;
    j.kind = JointTrajectory::Kind::Sine;
    j.value = offset;
    j.amplitude = amplitude;
    j.frequency = frequency;
    j.phase = phase;
    return j;
}

JointTrajectory keyframes(std::vector<std::pair<Real, Real>> keys) {
    JointTrajectory j;
    j.kind = JointTrajectory::Kind::Keyframes;
    j.keys = std::move(keys);
    return j;
}

ChainJoint joint(JointType type, int parent, const Vec3& offset, const Vec3& axis,
                 const JointTrajectory& q) {
    ChainJoint j;
    j.type = type;
    j.parent = parent;
    j.origin.position = offset;
    j.axis = axis;
    j.trajectory = q;
    return j;
}

// Tolerance for poses composed from a few rotations of unit-size offsets.
constexpr Real kPoseTol = Real(1e4) * kEpsilon;

TEST(JointTrajectory, ClosedForms) {
    EXPECT_EQ(constant(0.7).at(-3), Real(0.7));
    EXPECT_NEAR(ramp(0.5, -2).at(0.25), 0.0, kPoseTol);
    EXPECT_NEAR(sine(1, 2, 0.5, kPi / 6).at(1), 1 + 2 * std::sin(kPi + kPi / 6), kPoseTol);
    const JointTrajectory k = keyframes({{0.0, 1.0}, {1.0, 3.0}, {3.0, -1.0}});
    EXPECT_NEAR(k.at(0.5), 2.0, kPoseTol);
    EXPECT_NEAR(k.at(2.0), 1.0, kPoseTol);
    EXPECT_EQ(k.at(1.0), Real(3));
    // Held outside the keys' span.
    EXPECT_EQ(k.at(-5), Real(1));
    EXPECT_EQ(k.at(0), Real(1));
    EXPECT_EQ(k.at(3), Real(-1));
    EXPECT_EQ(k.at(1e9), Real(-1));
    EXPECT_EQ(keyframes({{2.0, 4.0}}).at(0), Real(4));
    // Outside the span nothing moves; across it the steepest segment counts.
    EXPECT_EQ(k.maxRate(-3, -1), Real(0));
    EXPECT_EQ(k.maxRate(4, 9), Real(0));
    EXPECT_NEAR(k.maxRate(0.2, 0.4), 2.0, kPoseTol);
    EXPECT_NEAR(k.maxRate(0.5, 1.5), 2.0, kPoseTol);
    EXPECT_NEAR(k.maxRate(2, 2.5), 2.0, kPoseTol);
    const auto [lo, hi] = k.range(-1, 5);
    EXPECT_NEAR(lo, -1.0, kPoseTol);
    EXPECT_NEAR(hi, 3.0, kPoseTol);
    EXPECT_NEAR(sine(0, 3, 2, 0).maxRate(0, 1), 3 * 2 * 2 * kPi, kPoseTol);
    EXPECT_EQ(constant(2).maxRate(0, 1), Real(0));
}

// A random trajectory of `kind`, and its scale (a bound on |q|) for the rounding allowance.
JointTrajectory randomTrajectory(cdlab_test::Rng& rng, JointTrajectory::Kind kind) {
    switch (kind) {
        case JointTrajectory::Kind::Constant:
            return constant(rng.uniform(-3, 3));
        case JointTrajectory::Kind::Ramp:
            return ramp(rng.uniform(-3, 3), rng.uniform(-50, 50));
        case JointTrajectory::Kind::Sine:
            return sine(rng.uniform(-3, 3), rng.uniform(-4, 4), rng.uniform(-20, 20),
                        rng.uniform(-10, 10));
        case JointTrajectory::Kind::Keyframes: {
            std::vector<std::pair<Real, Real>> keys;
            Real t = rng.uniform(-1, 1);
            const int n = rng.integer(1, 12);
            for (int i = 0; i < n; ++i) {
                keys.emplace_back(t, rng.uniform(-5, 5));
                t += rng.integer(0, 3) == 0 ? rng.uniform(1e-4, 1e-3) : rng.uniform(0.01, 0.5);
            }
            return keyframes(std::move(keys));
        }
    }
    return constant(0);
}

Real magnitude(const JointTrajectory& q) {
    Real m = std::abs(q.value) + std::abs(q.amplitude) + std::abs(q.rate) * 10;
    for (const auto& k : q.keys) m = std::max(m, std::abs(k.second));
    return m;
}

// Intervals that straddle what the bounds must catch: keyframe times and the sine's extrema of
// q (sin = +-1) and of its rate (sin = 0), plus random ones of all lengths.
std::pair<Real, Real> randomInterval(cdlab_test::Rng& rng, const JointTrajectory& q) {
    Real centre = rng.uniform(-2, 4);
    const int pick = rng.integer(0, 2);
    if (pick == 1 && q.kind == JointTrajectory::Kind::Keyframes) {
        centre = q.keys[static_cast<std::size_t>(rng.integer(0, int(q.keys.size()) - 1))].first;
    } else if (pick == 1 && q.kind == JointTrajectory::Kind::Sine && q.frequency != 0) {
        // Angle k pi / 2: sin at +-1 (q's extremum) or 0 (the rate's extremum).
        const Real angle = kPi / 2 * Real(rng.integer(-40, 40));
        centre = (angle - q.phase) / (2 * kPi * q.frequency);
    }
    const Real half = std::pow(Real(10), rng.uniform(-5, 0.3));
    const Real skew = rng.uniform(-0.9, 0.9) * half;
    return {centre - half + skew, centre + half + skew};
}

TEST(JointTrajectory, RangeAndMaxRateBoundDenseSamples) {
    cdlab_test::Rng rng(17);
    constexpr int kSamples = 600;
    int straddled_extremum = 0;  // intervals whose range is wider than their ends' values
    for (int trial = 0; trial < 4000; ++trial) {
        const auto kind = static_cast<JointTrajectory::Kind>(trial % 4);
        const JointTrajectory q = randomTrajectory(rng, kind);
        const auto [t0, t1] = randomInterval(rng, q);
        const auto [lo, hi] = q.range(t0, t1);
        const Real rate = q.maxRate(t0, t1);
        // Same bounds with the ends given the other way round.
        EXPECT_EQ(q.range(t1, t0), std::make_pair(lo, hi));
        EXPECT_EQ(q.maxRate(t1, t0), rate);
        // Rounding of one at() difference: of q's terms, and of the angle or rate * t.
        const Real noise = 4 * kEpsilon * (magnitude(q) + rate * (std::abs(t0) + std::abs(t1) + 1));
        const Real h = (t1 - t0) / kSamples;
        Real prev = q.at(t0);
        Real prev_t = t0;
        Real seen_lo = prev;
        Real seen_hi = prev;
        for (int i = 0; i <= kSamples; ++i) {
            const Real t = i == kSamples ? t1 : t0 + h * i;
            const Real v = q.at(t);
            ASSERT_GE(v, lo) << "trial " << trial << " t " << t;
            ASSERT_LE(v, hi) << "trial " << trial << " t " << t;
            if (i > 0) {
                ASSERT_LE(std::abs(v - prev), rate * (t - prev_t) * (1 + 1e-9) + noise)
                    << "trial " << trial << " t " << t;
            }
            prev_t = t;
            seen_lo = std::min(seen_lo, v);
            seen_hi = std::max(seen_hi, v);
            prev = v;
        }
        const Real ends_lo = std::min(q.at(t0), q.at(t1));
        const Real ends_hi = std::max(q.at(t0), q.at(t1));
        if (seen_lo < ends_lo - noise || seen_hi > ends_hi + noise) ++straddled_extremum;
    }
    // The adversarial intervals did straddle extrema (else the test proves little).
    EXPECT_GT(straddled_extremum, 300);
}

// Keyframes that are not strictly increasing are the scene loader's to reject; here nothing
// may hang or read out of range (the assertion fires in builds that have it).
#ifndef CDLAB_ENABLE_ASSERTS
TEST(JointTrajectory, MalformedKeyframesNeverHang) {
    const JointTrajectory k =
        keyframes({{1.0, 1.0}, {0.0, 2.0}, {0.5, 3.0}, {std::nan(""), 4.0}, {2.0, 5.0}});
    for (const Real t : {-1.0, 0.25, 0.75, 1.5, 3.0}) {
        (void)k.at(t);
        (void)k.range(t, t + 1);
        (void)k.maxRate(t, t + 1);
    }
    EXPECT_EQ(k.at(std::nan("")), Real(1));
}
#endif

void expectPoseNear(const Pose& got, const Vec3& position, const Quat& orientation,
                    Real tol = kPoseTol) {
    EXPECT_LE((got.position - position).norm(), tol)
        << got.position.transpose() << " vs " << position.transpose();
    EXPECT_LE(got.orientation.angularDistance(orientation), tol);
}

Quat aboutZ(Real angle) { return Quat(Eigen::AngleAxis<Real>(angle, Vec3::UnitZ())); }

// Planar 2-link arm in the base's xy plane: link 0 turns by q0 about z at the base origin,
// link 1 by q1 about z at (L1, 0, 0) of link 0; the tip (L2, 0, 0) of link 1 is at
// base + (L1 cos q0 + L2 cos(q0 + q1), L1 sin q0 + L2 sin(q0 + q1), 0).
TEST(ChainKinematics, PlanarTwoLinkArmMatchesClosedForm) {
    const Real l1 = 2;
    const Real l2 = 1.5;
    Chain chain;
    chain.base.position = Vec3(1, -2, 3);
    chain.joints.push_back(
        joint(JointType::Revolute, -1, Vec3::Zero(), Vec3::UnitZ(), ramp(0.3, 1.7)));
    chain.joints.push_back(
        joint(JointType::Revolute, 0, Vec3(l1, 0, 0), Vec3::UnitZ(), sine(-0.4, 1.2, 0.8, 0.1)));
    chain.link_radius = {l1, l2};
    std::vector<Pose> frames;
    for (const Real t : {0.0, 0.13, 0.5, 1.0, 2.7}) {
        const Real q0 = 0.3 + 1.7 * t;
        const Real q1 = -0.4 + 1.2 * std::sin(2 * kPi * 0.8 * t + 0.1);
        chainFrames(chain, t, frames);
        ASSERT_EQ(frames.size(), 2u);
        const Vec3 elbow = chain.base.position + Vec3(l1 * std::cos(q0), l1 * std::sin(q0), 0);
        expectPoseNear(frames[0], chain.base.position, aboutZ(q0));
        expectPoseNear(frames[1], elbow, aboutZ(q0 + q1));
        const Vec3 tip = elbow + Vec3(l2 * std::cos(q0 + q1), l2 * std::sin(q0 + q1), 0);
        EXPECT_LE((frames[1].apply(Vec3(l2, 0, 0)) - tip).norm(), kPoseTol);
        for (int i = 0; i < 2; ++i) {
            // About an origin: the world frame less that origin (here exactly representable).
            const Pose about = linkFrame(chain, i, t, Vec3(1, -2, 3));
            expectPoseNear(about, frames[static_cast<std::size_t>(i)].position - Vec3(1, -2, 3),
                           frames[static_cast<std::size_t>(i)].orientation);
            const Pose one = linkFrame(chain, i, t);
            EXPECT_EQ(one.position, frames[static_cast<std::size_t>(i)].position);
            EXPECT_EQ(one.orientation.coeffs(),
                      frames[static_cast<std::size_t>(i)].orientation.coeffs());
        }
    }
}

// A slide along the joint's x axis, in a base turned 90 degrees about z (so it moves along
// world y), with a non-unit axis given (normalised by the kinematics).
TEST(ChainKinematics, PrismaticSlideMovesAlongItsAxis) {
    Chain chain;
    chain.base.position = Vec3(5, 0, 0);
    chain.base.orientation = aboutZ(kPi / 2);
    chain.joints.push_back(joint(JointType::Prismatic, -1, Vec3(0, 0, 1), Vec3(3, 0, 0),
                                 keyframes({{0.0, 0.5}, {1.0, 2.5}})));
    chain.link_radius = {0.1};
    std::vector<Pose> frames;
    for (const Real t : {-1.0, 0.0, 0.25, 1.0, 4.0}) {
        const Real q = 0.5 + 2 * std::clamp(t, Real(0), Real(1));
        chainFrames(chain, t, frames);
        expectPoseNear(frames[0], Vec3(5, q, 1), chain.base.orientation);
    }
}

// A fixed joint ignores its trajectory: the link is its parent's frame times the joint origin.
TEST(ChainKinematics, FixedJointIsTheOriginOnly) {
    Chain chain;
    chain.joints.push_back(
        joint(JointType::Revolute, -1, Vec3::Zero(), Vec3::UnitZ(), constant(kPi / 2)));
    ChainJoint fixed = joint(JointType::Fixed, 0, Vec3(1, 0, 0), Vec3::UnitX(), ramp(0, 100));
    fixed.origin.orientation = Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitX()));
    chain.joints.push_back(fixed);
    chain.link_radius = {1, 1};
    std::vector<Pose> frames;
    for (const Real t : {0.0, 0.3, 7.0}) {
        chainFrames(chain, t, frames);
        expectPoseNear(frames[1], Vec3(0, 1, 0), aboutZ(kPi / 2) * fixed.origin.orientation);
    }
}

// A branch: links 1 and 2 both hang from link 0 (a torso with two arms); each follows link 0
// and its own joint only, and a later link may name any earlier parent.
TEST(ChainKinematics, TwoChildrenOfOneLinkFollowTheirParent) {
    Chain chain;
    chain.base.position = Vec3(0, 0, 10);
    chain.joints.push_back(
        joint(JointType::Revolute, -1, Vec3::Zero(), Vec3::UnitZ(), ramp(0, kPi)));
    chain.joints.push_back(
        joint(JointType::Revolute, 0, Vec3(1, 0, 0), Vec3::UnitY(), constant(kPi / 2)));
    chain.joints.push_back(
        joint(JointType::Prismatic, 0, Vec3(-1, 0, 0), Vec3::UnitZ(), ramp(0, 1)));
    chain.joints.push_back(
        joint(JointType::Revolute, 1, Vec3(0, 0, 2), Vec3::UnitZ(), constant(0)));
    chain.link_radius = {1, 1, 1, 1};
    std::vector<Pose> frames;
    // t = 0.5: link 0 has turned by pi/2 about z, so its x axis points along world y.
    chainFrames(chain, 0.5, frames);
    ASSERT_EQ(frames.size(), 4u);
    const Quat r0 = aboutZ(kPi / 2);
    const Quat r1 = r0 * Quat(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitY()));
    expectPoseNear(frames[1], Vec3(0, 1, 10), r1);
    expectPoseNear(frames[2], Vec3(0, -1, 10.5), r0);
    // Link 3 sits 2 along link 1's z, which the turn about y maps to link 0's x = world y.
    expectPoseNear(frames[3], Vec3(0, 3, 10), r1);
}

// Random chains (1..8 links, mixed joints and trajectories, scales 1e-3..1e3, the base at the
// world origin or 1e6 from it): points of each link within link_radius of its frame origin
// (on that sphere, where the bound is tightest) never move faster than linkSpeedBound over
// the interval (finite differences over 1/256 of it), nor farther from their place at the
// interval's middle than the bound allows; linkSweptBounds holds the link's sphere throughout.
TEST(ChainBounds, SpeedAndSweptBoundsHoldOnRandomChains) {
    cdlab_test::Rng rng(2007);
    constexpr int kSteps = 256;
    int tight = 0;  // links whose sampled speed came within 2x of the bound
    int links_checked = 0;
    std::vector<Pose> frames;
    for (int trial = 0; trial < 300; ++trial) {
        const Real scale = std::pow(Real(10), rng.uniform(-3, 3));
        const Real base = trial % 2 == 0 ? Real(1e6) : Real(0);
        const Chain chain =
            cdlab_test::randomChain(rng, rng.integer(1, 8), scale, base, rng.uniform(0.1, 30));
        const Real t0 = rng.uniform(-1, 2);
        const Real t1 = t0 + std::pow(Real(10), rng.uniform(-3, 0));
        for (int link = 0; link < int(chain.joints.size()); ++link) {
            const Real bound = linkSpeedBound(chain, link, t0, t1);
            const Aabb box = linkSweptBounds(chain, link, t0, t1);
            const Real radius = chain.link_radius[static_cast<std::size_t>(link)];
            // Rounding of a world position: a few ulps of the base distance plus the chain's
            // extent, per joint on the path (at most 8), and of the joint angles (an angle q
            // is known to a few ulps of |q|, which moves the link by that times its extent).
            Real extent = radius;
            Real largest_q = 0;
            for (const ChainJoint& j : chain.joints) {
                extent += j.origin.position.norm() + scale;
                const auto [lo, hi] = j.trajectory.range(t0, t1);
                largest_q = std::max({largest_q, std::abs(lo), std::abs(hi)});
            }
            const Real noise = 64 * kEpsilon * (base + extent * (1 + largest_q));
            Vec3 local[4];
            for (Vec3& p : local) p = rng.vec(-1, 1).normalized() * radius;
            local[0] = Vec3::Zero();
            const Real tm = (t0 + t1) / 2;
            const Pose mid = linkFrame(chain, link, tm);
            Real fastest = 0;
            Pose prev = linkFrame(chain, link, t0);
            Real prev_t = t0;
            for (int k = 0; k <= kSteps; ++k) {
                const Real t = k == kSteps ? t1 : t0 + (t1 - t0) * k / kSteps;
                const Pose f = linkFrame(chain, link, t);
                for (const Vec3& p : local) {
                    const Real moved = (f.apply(p) - mid.apply(p)).norm();
                    ASSERT_LE(moved, bound * std::abs(t - tm) + noise) << trial << " " << link;
                    if (k == 0) continue;
                    const Real step = (f.apply(p) - prev.apply(p)).norm();
                    ASSERT_LE(step, bound * (t - prev_t) + noise) << trial << " " << link;
                    fastest = std::max(fastest, (step - noise) / (t - prev_t));
                }
                // The link's sphere (its geometry lies within it) inside the swept box.
                ASSERT_TRUE(box.contains(f.position - Vec3::Constant(radius)) &&
                            box.contains(f.position + Vec3::Constant(radius)))
                    << trial << " " << link;
                prev = f;
                prev_t = t;
            }
            ++links_checked;
            if (fastest > bound / 2) ++tight;
        }
    }
    // The bound is not vacuous: often within a factor 2 of the sampled speed.
    EXPECT_GT(tight, links_checked / 5) << tight << " of " << links_checked;
}

// A revolute link turning about its own frame origin: its farthest points move at rate times
// link_radius exactly, and nothing else moves it.
TEST(ChainBounds, SingleTurningLinkBoundIsRateTimesRadius) {
    Chain chain;
    chain.joints.push_back(joint(JointType::Revolute, -1, Vec3::Zero(), Vec3::UnitZ(), ramp(0, 3)));
    chain.link_radius = {2};
    // Exact but for the bound's own rounding allowance (a few ulps per joint).
    const Real slack = 64 * kEpsilon;
    EXPECT_NEAR(linkSpeedBound(chain, 0, 0, 1), 6.0, 6 * slack);
    const Aabb box = linkSweptBounds(chain, 0, 0, 1);
    EXPECT_TRUE(box.contains(Vec3(2, 0, 0)) && box.contains(Vec3(-2, 0, 0)));
    // A prismatic child of it, 1 m off the axis, sliding from -4 to -3 m over [0, 1]: its
    // points lie within 2 + 4 + 1 = 7 m of the turning axis, so 3 * 7 + 1 (the slide) = 22.
    Chain arm;
    arm.joints.push_back(joint(JointType::Revolute, -1, Vec3::Zero(), Vec3::UnitZ(), ramp(0, 3)));
    arm.joints.push_back(joint(JointType::Prismatic, 0, Vec3(0, 1, 0), Vec3::UnitX(), ramp(-4, 1)));
    arm.link_radius = {0, 2};
    EXPECT_NEAR(linkSpeedBound(arm, 1, 0, 1), 22.0, 22 * slack);
    EXPECT_EQ(linkSpeedBound(arm, 0, 0, 1), Real(0));
}

}  // namespace
}  // namespace collision
