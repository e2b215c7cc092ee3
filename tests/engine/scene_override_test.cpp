// Scene overrides (what `cdlab sweep --vary` applies): a dotted key path set before validation,
// checked exactly like the file's own values.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "engine/scene.h"

namespace {

namespace fs = std::filesystem;

const fs::path kScene = fs::path(CDLAB_SOURCE_DIR) / "tests/data/tunnel_small.yaml";

std::string errorOf(const std::vector<engine::SceneOverride>& overrides) {
    try {
        engine::loadScene(kScene, overrides);
    } catch (const engine::SceneError& e) {
        return e.what();
    }
    return "";
}

TEST(SceneOverride, SetsNestedValuesAndListEntries) {
    const engine::Scene plain = engine::loadScene(kScene);
    const engine::Scene s = engine::loadScene(
        kScene, {{"world.time_step", "0.002"}, {"bodies.0.radius", "0.25"},
                 {"broadphase", "hgrid"}, {"world.gravity", "[0, -9.81, 0]"}});
    EXPECT_EQ(plain.world.time_step, 0.01);
    EXPECT_EQ(s.world.time_step, 0.002);
    EXPECT_EQ(s.world.broad_phase, "hgrid");
    EXPECT_EQ(s.world.gravity.y(), -9.81);
    EXPECT_EQ(s.bodies[0].shape.radius, 0.25);
    EXPECT_EQ(plain.bodies[0].shape.radius, 0.05);
    EXPECT_EQ(s.bodies.size(), plain.bodies.size());
}

TEST(SceneOverride, LaterOverridesWinAndMissingMapsAreCreated) {
    const engine::Scene s = engine::loadScene(
        kScene, {{"world.time_step", "0.5"}, {"world.time_step", "0.003"}, {"draw.hud", "false"}});
    EXPECT_EQ(s.world.time_step, 0.003);
    EXPECT_FALSE(s.draw.hud);
}

TEST(SceneOverride, CcdToleranceAndTargetGapAreSweepable) {
    // What `cdlab sweep --vary world.ccd_tolerance=...` sets; validated like the file's keys.
    const engine::Scene s = engine::loadScene(
        kScene, {{"world.ccd_tolerance", "0.02"}, {"world.ccd_target_gap", "0.005"}});
    EXPECT_EQ(s.world.ccd_tolerance, engine::Real(0.02));
    EXPECT_EQ(s.world.ccd_target_gap, engine::Real(0.005));
    const std::string err = errorOf({{"world.ccd_tolerance", "0"}});
    EXPECT_NE(err.find("world.ccd_tolerance: must be > 0 and <= 1"), std::string::npos) << err;
}

TEST(SceneOverride, BadOverridesAreRejectedWithTheKeyPath) {
    // Validation is the file's own: range, unknown keys, types.
    EXPECT_NE(errorOf({{"world.time_step", "0"}}).find("world.time_step"), std::string::npos);
    EXPECT_NE(errorOf({{"world.frobnicate", "1"}}).find("frobnicate"), std::string::npos);
    EXPECT_NE(errorOf({{"bodies.0.radius", "[1, 2]"}}).find("bodies[0].radius"),
              std::string::npos);
    // Paths that cannot be followed.
    EXPECT_NE(errorOf({{"world.time_step.x", "1"}}).find("below a value"), std::string::npos);
    EXPECT_NE(errorOf({{"bodies.3.radius", "1"}}).find("not an index"), std::string::npos);
    EXPECT_NE(errorOf({{"bodies.first.radius", "1"}}).find("not an index"), std::string::npos);
    EXPECT_NE(errorOf({{"world..time_step", "1"}}).find("empty key"), std::string::npos);
    EXPECT_NE(errorOf({{"world.time_step", "[1, 2"}}).find("malformed YAML value"),
              std::string::npos);
    // Every message names the file.
    EXPECT_EQ(errorOf({{"world.time_step", "0"}}).rfind(kScene.string(), 0), 0u);
}

// Regression: errors about an override's value were reported at FILE:1:1 (the line and column of
// the value's own text), pointing into the file at a line that has nothing to do with them.
TEST(SceneOverride, ErrorsNameTheOptionNotALineOfTheFile) {
    const std::string file = kScene.string();
    EXPECT_EQ(errorOf({{"world.frames", "abc"}}),
              file + ": --set world.frames=abc: world.frames: expected an integer, got 'abc'");
    EXPECT_EQ(errorOf({{"bodies.0.position", "[1, x, 2]"}}),
              file + ": --set bodies.0.position=[1, x, 2]: bodies[0].position[1]: expected a "
                     "number, got 'x'");
    EXPECT_EQ(errorOf({{"world..x", "1"}}),
              file + ": --set world..x=1: world..x: empty key in the path");
    // The option is the one that gave the override (sweep passes --vary).
    EXPECT_EQ(errorOf({{"world.time_step", "-1", "--vary"}}).rfind(
                  file + ": --vary world.time_step=-1: world.time_step: must be > 0", 0),
              0u);
    // Inside a value that replaces a whole mapping, the error still names the option.
    EXPECT_EQ(errorOf({{"bodies.0", "{shape: sphere, radius: -1, position: [0, 0, 0]}"}}).rfind(
                  file + ": --set bodies.0={shape: sphere, radius: -1, position: [0, 0, 0]}: "
                         "bodies[0].radius: must be > 0",
                  0),
              0u);
}

}  // namespace
