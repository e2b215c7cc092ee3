// --check-broadphase's report: equal pair sets pass; a difference names missed and extra pairs.
#include "broadphase_check.h"

#include <gtest/gtest.h>

namespace app {
namespace {

using collision::ProxyPair;

TEST(BroadPhaseCheck, EqualSetsPassAndDifferencesAreNamed) {
    std::vector<engine::Body> bodies(4);
    for (int i = 0; i < 4; ++i) bodies[i].name = std::string("b").append(std::to_string(i));
    const std::vector<ProxyPair> reference = {{0, 1}, {1, 2}, {2, 3}};
    EXPECT_EQ(describePairMismatch("sap", "brute", reference, reference, bodies), "");
    const std::vector<ProxyPair> got = {{0, 1}, {0, 3}, {2, 3}};
    const std::string report = describePairMismatch("sap", "brute", got, reference, bodies);
    EXPECT_NE(report.find("'sap' reports 3 pairs, reference 'brute' reports 3"),
              std::string::npos)
        << report;
    EXPECT_NE(report.find("missed (1): (1 b1, 2 b2)"), std::string::npos) << report;
    EXPECT_NE(report.find("extra (1): (0 b0, 3 b3)"), std::string::npos) << report;
}

TEST(BroadPhaseCheck, CheckerAgreesWithEveryBroadPhaseOnARandomWorld) {
    for (const collision::BroadPhaseEntry& e : collision::broadPhaseRegistry()) {
        if (e.needs_render_context) continue;  // cullide_tests, with render's oracle
        engine::WorldSettings s;
        s.broad_phase = std::string(e.name);
        engine::World world(s);
        for (int i = 0; i < 30; ++i) {
            engine::MassProperties m;
            m.mass = 1;
            engine::Body b = engine::makeBody("s", collision::Shape::sphere(0.6), m);
            b.position = collision::Vec3(i % 5, (i / 5) % 3, i % 2) * 0.9;
            b.linear_momentum = collision::Vec3(i % 3 - 1, i % 2, 0.5);
            world.addBody(b);
        }
        world.detect();
        BroadPhaseChecker checker{std::string(e.name)};
        for (int step = 0; step < 50; ++step) {
            ASSERT_EQ(checker.check(world), "") << e.name << " step " << step;
            world.step();
        }
    }
}

}  // namespace
}  // namespace app
