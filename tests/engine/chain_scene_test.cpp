// tests/engine/chain_scene_test.cpp -- the scene's `chains:` section: what a chain loads as (its
// links appended to the bodies as kinematic bodies, joints in radians and unit axes, parents by
// name), and every bad value an error at its line and column naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "engine/scene.h"
#include "scene_error.h"

namespace engine {
namespace {

constexpr Real kDeg = std::numbers::pi_v<Real> / 180;

const std::string kWorld =
    "world: {bounds: {min: [-4, -4, -4], max: [4, 4, 4]}, time_step: 0.01}\n"
    "bodies:\n"
    "  - {name: plate, shape: box, half_extents: [0.01, 1, 1], position: [0, 1, 0], "
    "static: true}\n"
    "chains:\n";

// Line 5 of the scene is the chain's first line ("  - name: arm").
const std::string kArm =
    "  - name: arm\n"                                            // 5
    "    base: {position: [0, -1, 0], euler_deg: [0, 0, 90]}\n"  // 6
    "    links:\n"                                               // 7
    "      - name: upper\n"                                      // 8
    "        shape: capsule\n"                                   // 9
    "        radius: 0.05\n"                                     // 10
    "        half_height: 0.4\n"                                 // 11
    "        offset: {position: [0, 0.5, 0]}\n"                  // 12
    "        joint: {type: revolute, axis: [0, 0, 2], motion: {ramp: {start: 10, rate: 90}}}\n"
    "      - name: lower\n"    // 14
    "        shape: sphere\n"  // 15
    "        radius: 0.1\n"    // 16
    "        joint: {type: prismatic, axis: [0, 1, 0], origin: {position: [0, 1, 0]},\n"
    "                motion: {keyframes: [[0, 0], [1, 0.5]]}}\n"  // 18
    "      - name: side\n"                                        // 19
    "        shape: box\n"                                        // 20
    "        half_extents: [0.1, 0.1, 0.1]\n"                     // 21
    "        parent: upper\n"                                     // 22
    "        joint: {type: revolute, axis: [1, 0, 0], motion: {sine: {amplitude: 30, "
    "frequency: 2, phase_deg: 90, offset: 5}}}\n";  // 23

std::string withArm(const std::string& from, const std::string& to) {
    std::string text = kWorld + kArm;
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

TEST(ChainScene, LinksAreKinematicBodiesAfterTheBodies) {
    const Scene s = parseScene(kWorld + kArm, "test.yaml", ".");
    ASSERT_EQ(s.bodies.size(), 4u);
    ASSERT_EQ(s.chains.size(), 1u);
    const ChainSpec& c = s.chains[0];
    EXPECT_EQ(c.name, "arm");
    EXPECT_FALSE(c.collide_adjacent);
    EXPECT_EQ(c.on_impact, ChainImpact::Stop);
    ASSERT_EQ(c.links.size(), 3u);
    EXPECT_EQ(c.links[0], 1);
    EXPECT_EQ(s.bodies[1].name, "upper");
    EXPECT_EQ(s.bodies[2].name, "lower");
    EXPECT_EQ(s.bodies[3].name, "side");
    for (BodyId id : c.links) {
        EXPECT_TRUE(s.bodies[static_cast<std::size_t>(id)].kinematic);
        EXPECT_TRUE(s.bodies[static_cast<std::size_t>(id)].is_static);
    }
    EXPECT_FALSE(s.bodies[0].kinematic);
    const collision::Chain& ch = c.chain;
    EXPECT_NEAR(ch.base.position.y(), -1, 0);
    // Parents: the previous link by default, by name when given.
    EXPECT_EQ(ch.joints[0].parent, -1);
    EXPECT_EQ(ch.joints[1].parent, 0);
    EXPECT_EQ(ch.joints[2].parent, 0);
    // Revolute values in degrees become radians; prismatic stay metres; axes are unit.
    EXPECT_EQ(ch.joints[0].type, collision::JointType::Revolute);
    EXPECT_NEAR((ch.joints[0].axis - Vec3::UnitZ()).norm(), 0, 1e-15);
    EXPECT_NEAR(ch.joints[0].trajectory.value, 10 * kDeg, 1e-15);
    EXPECT_NEAR(ch.joints[0].trajectory.rate, 90 * kDeg, 1e-15);
    EXPECT_EQ(ch.joints[1].type, collision::JointType::Prismatic);
    ASSERT_EQ(ch.joints[1].trajectory.keys.size(), 2u);
    EXPECT_EQ(ch.joints[1].trajectory.keys[1].second, Real(0.5));
    EXPECT_NEAR(ch.joints[1].origin.position.y(), 1, 0);
    EXPECT_NEAR(ch.joints[2].trajectory.amplitude, 30 * kDeg, 1e-15);
    EXPECT_NEAR(ch.joints[2].trajectory.phase, 90 * kDeg, 1e-15);
    EXPECT_NEAR(ch.joints[2].trajectory.value, 5 * kDeg, 1e-15);
    // Link radius bounds the shape from the link frame's origin: 0.5 + 0.4 + 0.05.
    EXPECT_NEAR(ch.link_radius[0], 0.95, 1e-12);
    EXPECT_NEAR(c.shape_in_link[0].position.y(), 0.5, 0);
}

TEST(ChainScene, OptionsAndChainOnlyScenes) {
    Scene s = parseScene(withArm("    links:\n",
                                 "    collide_adjacent: true\n"
                                 "    on_impact: continue\n    links:\n"),
                         "test.yaml", ".");
    EXPECT_TRUE(s.chains[0].collide_adjacent);
    EXPECT_EQ(s.chains[0].on_impact, ChainImpact::Continue);
    // A scene of chains alone has bodies: its links.
    std::string text = kWorld + kArm;
    text.replace(text.find("bodies:\n"), text.find("chains:\n") - text.find("bodies:\n"), "");
    s = parseScene(text, "test.yaml", ".");
    EXPECT_EQ(s.bodies.size(), 3u);
    // Fixed joints need neither axis nor motion.
    s = parseScene(withArm("{type: revolute, axis: [1, 0, 0], motion: {sine: {amplitude: 30, "
                           "frequency: 2, phase_deg: 90, offset: 5}}}",
                           "{type: fixed, origin: {position: [0.2, 0, 0]}}"),
                   "test.yaml", ".");
    EXPECT_EQ(s.chains[0].chain.joints[2].type, collision::JointType::Fixed);
}

TEST(ChainScene, BadValuesAreErrorsAtTheirKey) {
    EXPECT_SCENE_ERROR(withArm("type: prismatic", "type: twisty"),
                       "17:23: chains[0].links[1].joint.type: ", "unknown joint type 'twisty'");
    EXPECT_SCENE_ERROR(withArm("axis: [0, 0, 2]", "axis: [0, 0, 0]"),
                       "13:39: chains[0].links[0].joint.axis: ", "must be a non-zero direction");
    EXPECT_SCENE_ERROR(withArm("[[0, 0], [1, 0.5]]", "[[0, 0], [0, 0.5]]"),
                       "18:47: chains[0].links[1].joint.motion.keyframes[1][0]: ",
                       "key times must increase strictly");
    EXPECT_SCENE_ERROR(withArm("parent: upper", "parent: elbow"),
                       "22:17: chains[0].links[2].parent: ", "no earlier link");
    EXPECT_SCENE_ERROR(withArm("parent: upper", "parent: side"),
                       "22:17: chains[0].links[2].parent: ", "no earlier link");
    EXPECT_SCENE_ERROR(withArm("name: lower", "name: plate"), "14:15: chains[0].links[1].name: ",
                       "the name 'plate' is already taken by a body");
    EXPECT_SCENE_ERROR(withArm("name: side", "name: upper"),
                       "19:15: chains[0].links[2].name: ", "already taken by chains[0].links[0]");
    EXPECT_SCENE_ERROR(withArm("shape: sphere", "shape: cone"),
                       "15:16: chains[0].links[1].shape: ", "unknown shape 'cone'");
    EXPECT_SCENE_ERROR(withArm("        radius: 0.1\n", ""),
                       "14:9: chains[0].links[1].radius: ", "required key is missing");
    EXPECT_SCENE_ERROR(withArm("radius: 0.1", "radius: -0.1"),
                       "16:17: chains[0].links[1].radius: ", "must be > 0");
    EXPECT_SCENE_ERROR(withArm("        parent: upper\n", "        position: [0, 0, 0]\n"),
                       "22:9: chains[0].links[2].position: ", "unknown key 'position'");
    EXPECT_SCENE_ERROR(withArm("type: revolute, axis: [1, 0, 0]", "type: fixed, axis: [1, 0, 0]"),
                       "23:30: chains[0].links[2].joint.axis: ", "does not apply to a fixed joint");
    EXPECT_SCENE_ERROR(
        withArm("frequency: 2,", "frequency: 0,"),
        "23:92: chains[0].links[2].joint.motion.sine.frequency: ", "must be in (0, 1000]");
    EXPECT_SCENE_ERROR(withArm("{ramp: {start: 10, rate: 90}}", "{ramp: {rate: 90}, constant: 1}"),
                       "13:58: chains[0].links[0].joint.motion: ", "exactly one of");
    EXPECT_SCENE_ERROR(withArm("    links:\n", "    on_impact: halt\n    links:\n"),
                       "7:16: chains[0].on_impact: ", "unknown value 'halt'");
    EXPECT_SCENE_ERROR(withArm("position: [0, -1, 0]", "position: [0, -9, 0]"),
                       "6:11: chains[0].base: ", "outside the world bounds");
    EXPECT_SCENE_ERROR(withArm("time_step: 0.01", "time_step: 0.01, response: impulse"),
                       "4:1: chains: ", "chains need world.response: none");
    // Two chains of one name.
    std::string two = kWorld + kArm + kArm;
    EXPECT_SCENE_ERROR(two, "24:11: chains[1].name: ", "the chain name 'arm' is already taken");
}

}  // namespace
}  // namespace engine
