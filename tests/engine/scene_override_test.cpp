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

}  // namespace
