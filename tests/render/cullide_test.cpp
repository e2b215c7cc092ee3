// The `cullide` broad phase on render's occlusion-query oracle. This binary also runs the
// differential tests of tests/collision/broad_phase_test.cpp (compiled in beside this file) on
// cullide, with the oracle installed below before any test.
#include <gtest/gtest.h>

#include <string>

#include "broadphase/cullide.h"
#include "collision/broadphase/broad_phase.h"
#include "render/occlusion_oracle.h"

namespace {

using collision::Aabb;
using collision::ProxyPair;
using collision::ProxyVolumes;
using collision::Real;
using collision::Vec3;

class OracleEnvironment : public ::testing::Environment {
public:
    void SetUp() override { render::installOcclusionQueryOracle(); }
};
const auto* const kEnvironment = ::testing::AddGlobalTestEnvironment(new OracleEnvironment);

ProxyVolumes boxVolumes(const Vec3& lo, const Vec3& hi) {
    ProxyVolumes v;
    v.aabb = Aabb{lo, hi};
    return v;
}

// Pruning must happen, or the broad phase is only an expensive brute force: a row of separate
// cubes along x with one overlapping pair at its end.
//
//      [0] [1] [2] ... [9][10]      9 and 10 overlap by 0.2
//
TEST(Cullide, PrunesSeparatedBoxesAndKeepsTheOverlappingPair) {
    collision::CullideBroadPhase bp(render::makeOcclusionQueryOracle(256));
    for (int i = 0; i < 10; ++i) {
        const Vec3 lo(2.0 * i, 0, 0);
        bp.insert(i, boxVolumes(lo, lo + Vec3::Ones()));
    }
    bp.insert(10, boxVolumes(Vec3(18.8, 0.5, 0.5), Vec3(19.8, 1.5, 1.5)));
    std::vector<ProxyPair> pairs;
    collision::BroadPhaseCounters counters;
    bp.findPairs(pairs, counters);
    EXPECT_EQ(pairs, (std::vector<ProxyPair>{{9, 10}}));
    EXPECT_EQ(bp.potentiallyColliding(), (std::vector<collision::ProxyId>{9, 10}));
}

// Regression for the reliable variant: boxes that overlap in a sliver far thinner than a pixel
// (1e-7 of a 1e4 scene, on both screen axes of every view) share no pixel centre unless they are
// fattened by a pixel; without the fattening both were pruned and the pair was lost.
//
//      [ big 0 ]            ... 1e4 away ...           [a][b]   a and b overlap by 1e-7
//
TEST(Cullide, SubPixelSliverOverlapIsKept) {
    collision::CullideBroadPhase bp(render::makeOcclusionQueryOracle(64));
    bp.insert(0, boxVolumes(Vec3(0, 0, 0), Vec3(1, 1, 1)));
    const Vec3 c(1e4 + 0.37, 1e4 + 0.41, 1e4 + 0.29);
    const Real e = 1e-3;
    const Real sliver = 1e-7;
    bp.insert(1, boxVolumes(c - Vec3::Constant(e), c + Vec3::Constant(e)));
    const Vec3 d = c + Vec3::Constant(2 * e - sliver);
    bp.insert(2, boxVolumes(d - Vec3::Constant(e), d + Vec3::Constant(e)));
    std::vector<ProxyPair> pairs;
    collision::BroadPhaseCounters counters;
    bp.findPairs(pairs, counters);
    EXPECT_EQ(pairs, (std::vector<ProxyPair>{{1, 2}}));
}

TEST(Cullide, RegistryCreatesItOnceTheOracleIsInstalled) {
    EXPECT_TRUE(collision::hasVisibilityOracleFactory());
    EXPECT_EQ(collision::findBroadPhase("cullide")->create()->name(), "cullide");
}

}  // namespace
