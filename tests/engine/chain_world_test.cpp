// tests/engine/chain_world_test.cpp -- chains in the World: links posed by the chain's forward
// kinematics every step, parent-child pairs dropped unless collide_adjacent, the continuous
// stage's time of impact with on_impact stop (the chain halts, never overlapping the obstacle
// at any sampled time before) and continue (report only), a dynamic body hit by a link, and
// tunnelling with ccd off.
//
// The test chain: one bar (a capsule 0.9 m long, 5 cm radius, from 5 cm to 95 cm along the
// link's x) turning about z at the origin at 800 deg/s from angle 0; a thin static plate (2 cm)
// in the plane x = 0 over y in [0.6, 1]. At dt = 1/30 s the bar turns 26.7 deg a step: its tip
// moves 0.44 m, and the plate (with the bar's diameter) is 0.12 m thick. The steps leave the
// bar at 80 deg and 106.7 deg around the plate: 10 cm and 18 cm from it where it spans it.
//
//        y ^  plate |
//          |        |  /bar, turning counter-clockwise
//          |        | /
//          o--------+-----> x
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "collision/ccd/chain.h"
#include "collision/debug_draw.h"
#include "collision/narrowphase/narrow_phase.h"
#include "engine/scene.h"
#include "engine/world.h"

namespace engine {
namespace {

const std::string kBarScene =
    "world: {bounds: {min: [-4, -4, -4], max: [4, 4, 4]}, time_step: 0.03333333333333333, "
    "steps_per_frame: 1, frames: 20, ccd: CCD}\n"
    "bodies:\n"
    "  - {name: plate, shape: box, half_extents: [0.01, 0.2, 0.5], position: [0, 0.8, 0], "
    "static: true}\n"
    "chains:\n"
    "  - name: arm\n"
    "    on_impact: IMPACT\n"
    "    links:\n"
    "      - name: bar\n"
    "        shape: capsule\n"
    "        radius: 0.05\n"
    "        half_height: 0.45\n"
    "        offset: {position: [0.5, 0, 0], euler_deg: [0, 0, -90]}\n"
    "        joint: {type: revolute, axis: [0, 0, 1], motion: {ramp: {rate: 800}}}\n";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

Scene barScene(bool ccd, const std::string& impact = "stop") {
    std::string text = replaced(kBarScene, "CCD", ccd ? "conservative_advancement" : "off");
    text = replaced(text, "IMPACT", impact);
    return parseScene(text, "bar.yaml", ".");
}

// The body pose of link `l` of chain `c` at time t, from the chain model alone.
Pose linkPose(const ChainSpec& c, std::size_t l, Real t) {
    std::vector<Pose> frames;
    collision::chainFrames(c.chain, t, frames);
    return frames[l] * c.shape_in_link[l];
}

bool overlaps(const World& w, BodyId a, const Pose& pose_a, BodyId b) {
    const Body& ba = w.bodies()[static_cast<std::size_t>(a)];
    const Body& bb = w.bodies()[static_cast<std::size_t>(b)];
    return collision::isColliding(collision::collide(ba.shape, pose_a, bb.shape, bb.pose()).state);
}

bool hasPair(std::span<const collision::ProxyPair> pairs, BodyId a, BodyId b) {
    return std::any_of(pairs.begin(), pairs.end(), [&](const collision::ProxyPair& p) {
        return static_cast<BodyId>(p.a) == std::min(a, b) &&
               static_cast<BodyId>(p.b) == std::max(a, b);
    });
}

TEST(ChainWorld, LinksFollowTheForwardKinematicsEveryStep) {
    // The shipped arm (six links on revolute joints of every trajectory kind), ccd off.
    const Scene scene =
        loadScene(std::filesystem::path(CDLAB_SOURCE_DIR) / "scenes/arm_discrete.yaml");
    World w = makeWorld(scene);
    const ChainSpec& c = w.chains()[0];
    ASSERT_EQ(c.links.size(), 6u);
    for (int step = 0; step <= 30; ++step) {
        if (step > 0) w.step();
        EXPECT_EQ(w.chainTime(0), w.time());
        for (std::size_t l = 0; l < c.links.size(); ++l) {
            const Body& b = w.bodies()[static_cast<std::size_t>(c.links[l])];
            const Pose p = linkPose(c, l, w.time());
            // Bit-equal: the world poses each link from chainFrames at the step's end time.
            EXPECT_EQ(b.position, p.position) << "step " << step << " link " << l;
            EXPECT_EQ(b.orientation.coeffs(), p.orientation.coeffs());
            EXPECT_EQ(b.linear_momentum, Vec3::Zero());
            EXPECT_EQ(b.angular_momentum, Vec3::Zero());
        }
    }
}

// Two links hinged at x = 0.9: their capsules overlap at the hinge at every time.
std::string hinge(bool adjacent) {
    return std::string(
               "world: {bounds: {min: [-4, -4, -4], max: [4, 4, 4]}, time_step: 0.01}\n"
               "chains:\n"
               "  - name: pair\n") +
           (adjacent ? "    collide_adjacent: true\n" : "") +
           "    links:\n"
           "      - {name: a, shape: capsule, radius: 0.1, half_height: 0.4, offset: {position: "
           "[0.5, 0, 0], euler_deg: [0, 0, 90]}, joint: {type: revolute, axis: [0, 0, 1], "
           "motion: {ramp: {rate: 90}}}}\n"
           "      - {name: b, shape: capsule, radius: 0.1, half_height: 0.4, offset: {position: "
           "[0.4, 0, 0], euler_deg: [0, 0, 90]}, joint: {type: revolute, axis: [0, 0, 1], "
           "origin: {position: [0.9, 0, 0]}, motion: {sine: {amplitude: 40, frequency: 1}}}}\n"
           "      - {name: c, shape: sphere, radius: 0.2, parent: a, joint: {type: fixed, "
           "origin: {position: [0.5, 0, 0]}}}\n";
}

TEST(ChainWorld, ParentChildPairsAreDroppedUnlessCollideAdjacent) {
    for (const bool adjacent : {false, true}) {
        World w = makeWorld(parseScene(hinge(adjacent), "hinge.yaml", "."));
        EXPECT_EQ(w.pairAllowed(0, 1), adjacent);
        EXPECT_EQ(w.pairAllowed(0, 2), adjacent);  // c hangs from a
        EXPECT_TRUE(w.pairAllowed(1, 2));          // siblings are not adjacent
        for (int step = 0; step < 20; ++step) {
            w.step();
            EXPECT_EQ(hasPair(w.flaggedPairs(), 0, 1), adjacent) << step;
            EXPECT_EQ(hasPair(w.collidingPairs(), 0, 1), adjacent) << step;
            EXPECT_EQ(hasPair(w.flaggedPairs(), 0, 2), adjacent) << step;
            // b never gets coloured by a: without collide_adjacent it is paired with nothing
            // it touches (c, its sibling, is 0.4 m from the hinge and out of reach at 40 deg).
            if (!adjacent) {
                EXPECT_NE(w.states()[1], BodyState::Colliding) << step;
            }
        }
    }
}

TEST(ChainWorld, StopHaltsTheChainAtItsTimeOfImpactWithoutOverlapBefore) {
    World w = makeWorld(barScene(true, "stop"));
    const ChainSpec c = w.chains()[0];
    const BodyId bar = c.links[0];
    const BodyId plate = 0;
    const Real dt = w.settings().time_step;
    int hit_step = -1;
    ToiEvent hit;
    for (int step = 1; step <= 20; ++step) {
        const Real t0 = w.time();
        const bool was_halted = w.chainHalted(0);
        w.step();
        if (!was_halted && w.chainHalted(0)) {
            hit_step = step;
            ASSERT_EQ(w.toiEvents().size(), 1u);
            hit = w.toiEvents()[0];
            EXPECT_EQ(std::min(hit.a, hit.b), plate);
            EXPECT_FALSE(hit.failed);
            // The clock halted at the event's time; the bar stays at the event's pose.
            EXPECT_NEAR(w.chainTime(0), t0 + hit.t * dt, 1e-12);
            const Pose at = hit.a == bar ? hit.pose_a : hit.pose_b;
            EXPECT_EQ(w.bodies()[static_cast<std::size_t>(bar)].position, at.position);
        }
        // Independent check: the bar's own pose from the chain model at 64 sampled times of
        // the step, up to the chain's clock, never overlaps the plate (collision::collide).
        const Real end = w.chainTime(0);
        for (int k = 0; k <= 64 && !was_halted; ++k) {
            const Real t = t0 + (end - t0) * Real(k) / 64;
            EXPECT_FALSE(overlaps(w, bar, linkPose(c, 0, t), plate)) << "t = " << t;
        }
        EXPECT_FALSE(hasPair(w.collidingPairs(), bar, plate)) << step;
    }
    ASSERT_GT(hit_step, 0) << "the bar never hit the plate";
    // Halted for good: no more clock, no more events, the same pose.
    const Pose final_pose = w.bodies()[static_cast<std::size_t>(bar)].pose();
    const Real halted_at = w.chainTime(0);
    for (int step = 0; step < 10; ++step) w.step();
    EXPECT_EQ(w.chainTime(0), halted_at);
    EXPECT_TRUE(w.toiEvents().empty());
    EXPECT_EQ(w.bodies()[static_cast<std::size_t>(bar)].position, final_pose.position);
    // The halt is just short of contact (the target gap, about 1 mm): a fiftieth of a step
    // later (5 mm at the plate's edge) the bar overlaps the plate.
    EXPECT_TRUE(overlaps(w, bar, linkPose(c, 0, halted_at + dt * 2e-2), plate));
}

TEST(ChainWorld, ContinueReportsTheImpactAndKeepsTheTrajectory) {
    World w = makeWorld(barScene(true, "continue"));
    const BodyId bar = w.chains()[0].links[0];
    int events = 0;
    for (int step = 1; step <= 20; ++step) {
        w.step();
        events += static_cast<int>(w.toiEvents().size());
        EXPECT_FALSE(w.chainHalted(0));
        EXPECT_EQ(w.chainTime(0), w.time());
    }
    EXPECT_GE(events, 1);
    // Past the plate: the bar turned 800 deg/s * 20/30 s = 533 deg, to 173 deg.
    EXPECT_LT(w.bodies()[static_cast<std::size_t>(bar)].position.x(), 0);
}

// Steps in which the bar's tip crosses the plate (x = 0 at y in the plate's span) while the
// discrete pipeline confirmed no contact at either end of the step.
int missedCrossings(World& w, int steps) {
    const BodyId bar = w.chains()[0].links[0];
    int missed = 0;
    for (int step = 0; step < steps; ++step) {
        const Vec3 tip(0, 0.45, 0);  // the capsule's end, body frame
        const Vec3 before = w.bodies()[static_cast<std::size_t>(bar)].pose().apply(tip);
        const bool touching_before = hasPair(w.collidingPairs(), 0, bar);
        w.step();
        const Vec3 after = w.bodies()[static_cast<std::size_t>(bar)].pose().apply(tip);
        const bool crossed = before.x() > 0 && after.x() < 0 && after.y() > 0.6;
        if (crossed && !touching_before && !hasPair(w.collidingPairs(), 0, bar)) ++missed;
    }
    return missed;
}

TEST(ChainWorld, WithoutCcdTheBarTunnelsWithCcdItDoesNot) {
    World off = makeWorld(barScene(false));
    EXPECT_GT(missedCrossings(off, 20), 0);
    World on = makeWorld(barScene(true));
    EXPECT_EQ(missedCrossings(on, 20), 0);
    EXPECT_TRUE(on.chainHalted(0));
}

TEST(ChainWorld, RunsAreBitIdentical) {
    const Scene scene = loadScene(std::filesystem::path(CDLAB_SOURCE_DIR) / "scenes/arm.yaml");
    World a = makeWorld(scene);
    World b = makeWorld(scene);
    for (int step = 0; step < 40; ++step) {
        a.step();
        b.step();
        ASSERT_EQ(a.stateHash(), b.stateHash()) << step;
    }
    EXPECT_TRUE(a.chainHalted(0));
}

TEST(ChainWorld, ALinkHitsADynamicBallLikeAnInfinitelyHeavyBody) {
    // A ball at rest in the bar's path, ccd on, on_impact: continue: the link is infinitely
    // heavy and moves with its trajectory, so the elastic impulse (response: none) sends the
    // ball off at twice the link's normal speed at the contact, away from the bar.
    std::string text = replaced(kBarScene, "CCD", "conservative_advancement");
    text = replaced(text, "IMPACT", "continue");
    text = replaced(text, "static: true}\n",
                    "static: true}\n  - {name: ball, shape: sphere, radius: 0.05, "
                    "position: [0.35, 0.35, 0]}\n");
    World w = makeWorld(parseScene(text, "ball.yaml", "."));
    const BodyId ball = 1;
    bool hit = false;
    for (int step = 0; step < 6 && !hit; ++step) {
        w.step();
        for (const ToiEvent& e : w.toiEvents()) hit = hit || e.a == ball || e.b == ball;
    }
    ASSERT_TRUE(hit);
    const Vec3 v = w.bodies()[static_cast<std::size_t>(ball)].velocity();
    // The bar turns counter-clockwise at 14 rad/s; at radius 0.45 m its surface moves at
    // about 6.3 m/s along (-1, 1)/sqrt 2: the ball leaves at about twice that.
    EXPECT_GT(v.norm(), 10);
    EXPECT_LT(v.norm(), 16);
    EXPECT_GT(v.dot(Vec3(-1, 1, 0)), 0);
}

// Records the lines drawn.
struct LineRecorder final : collision::DebugDraw {
    std::vector<std::pair<Vec3, Vec3>> lines;
    void drawLine(const Vec3& a, const Vec3& b, const collision::Color&) override {
        lines.emplace_back(a, b);
    }
};

TEST(ChainWorld, SkeletonJoinsEachJointToItsParents) {
    World w = makeWorld(parseScene(hinge(false), "hinge.yaml", "."));
    for (int step = 0; step < 7; ++step) w.step();
    LineRecorder rec;
    w.drawChainSkeletons(rec, collision::Color{});
    // a's joint sits on the base (zero length, skipped); b's and c's hang from a's frame.
    ASSERT_EQ(rec.lines.size(), 2u);
    std::vector<Pose> frames;
    collision::chainFrames(w.chains()[0].chain, w.time(), frames);
    EXPECT_EQ(rec.lines[0].first, frames[0].position);
    EXPECT_EQ(rec.lines[0].second, frames[1].position);
    EXPECT_NEAR((rec.lines[1].second - frames[0].apply(Vec3(0.5, 0, 0))).norm(), 0, 1e-12);
}

}  // namespace
}  // namespace engine
