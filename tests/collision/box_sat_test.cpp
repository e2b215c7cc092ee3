// The box SAT's best-axes measure (measureBoxSatBest, box_sat.h), which contact() and collide()
// use for clear overlaps, gives the full measure's best axes bit for bit (edges left unmeasured
// only when the best edge is below the best face): random poses, near- and exactly parallel
// edges, and poses scaled over eight orders of magnitude or moved far away, so the narrow phase
// answers exactly as it did with the full measure.
#include "volumes/box_sat.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "test_random.h"

namespace {

using collision::BoxSatMeasure;
using collision::Mat3;
using collision::Quat;
using collision::Real;
using collision::Vec3;

bool sameBits(Real x, Real y) { return std::memcmp(&x, &y, sizeof(Real)) == 0; }

// Every field measureBoxSatBest promises, compared bit for bit.
void expectSameBestAxes(const BoxSatMeasure& full, const BoxSatMeasure& best, int sample) {
    EXPECT_TRUE(sameBits(full.face_sep, best.face_sep)) << sample;
    EXPECT_EQ(full.face_box, best.face_box) << sample;
    EXPECT_EQ(full.face_axis, best.face_axis) << sample;
    if (best.edge_sep == -std::numeric_limits<Real>::infinity()) {
        // Edges left unmeasured: the measure's best edge is below the best face.
        EXPECT_LT(full.edge_sep, full.face_sep) << sample;
    } else {
        EXPECT_TRUE(sameBits(full.edge_sep, best.edge_sep)) << sample;
        EXPECT_EQ(full.edge_a, best.edge_a) << sample;
        EXPECT_EQ(full.edge_b, best.edge_b) << sample;
        for (int k = 0; k < 3; ++k) {
            EXPECT_TRUE(sameBits(full.edge_axis[k], best.edge_axis[k])) << sample;
        }
    }
    EXPECT_TRUE(sameBits(full.max_sep, best.max_sep)) << sample;
    EXPECT_TRUE(sameBits(full.err_bound, best.err_bound)) << sample;
    EXPECT_TRUE(full.per_axis);
    EXPECT_FALSE(best.per_axis);
}

// A rotation `angle` radians off an axis-aligned one (angle 0: exactly parallel edges).
Quat nearAligned(cdlab_test::Rng& rng, Real angle) {
    const Quat aligned(Eigen::AngleAxis<Real>(Real(M_PI / 2) * rng.integer(0, 3),
                                              Vec3::Unit(rng.integer(0, 2))));
    const Vec3 axis = rng.vec(-1, 1).normalized();
    return (aligned * Quat(Eigen::AngleAxis<Real>(angle, axis))).normalized();
}

TEST(BoxSat, BestAxesMeasureMatchesTheFullMeasureBitForBit) {
    cdlab_test::Rng rng(20261126);
    int edge_best = 0;
    int penetrating = 0;
    int edges_skipped = 0;
    int not_clear = 0;
    for (int sample = 0; sample < 200000; ++sample) {
        const int kind = sample % 4;
        const Real scale = kind == 3 ? std::pow(Real(10), rng.uniform(-4, 4)) : Real(1);
        const Vec3 ea = scale * rng.vec(0.01, 1.5);
        const Vec3 eb = scale * rng.vec(0.01, 1.5);
        Quat qa = rng.rotation();
        Quat qb = rng.rotation();
        if (kind == 1) qb = qa * nearAligned(rng, std::pow(Real(10), rng.uniform(-12, -1)));
        if (kind == 2) qb = qa * nearAligned(rng, Real(0));
        const Vec3 offset = kind == 0 && sample % 8 == 0 ? Vec3::Constant(1e6) : Vec3::Zero();
        const Vec3 pa = offset + scale * rng.vec(-1, 1);
        const Vec3 pb = pa + scale * rng.uniform(0, 3) * (rng.rotation() * Vec3::UnitX());
        const Mat3 ra = qa.toRotationMatrix();
        const Mat3 rot = ra.transpose() * qb.toRotationMatrix();
        const Vec3 t = ra.transpose() * (pb - pa);
        const BoxSatMeasure full = collision::measureBoxSat(ea, rot, t, eb);
        const BoxSatMeasure best = collision::measureBoxSatBest(ea, rot, t, eb);
        expectSameBestAxes(full, best, sample);
        // Stopping early for callers that act only on a clear overlap: the same decision, and
        // the same numbers when it is one.
        const Real tolerance = Real(64) * collision::kEpsilon * scale;
        const BoxSatMeasure clear = collision::measureBoxSatBest(ea, rot, t, eb, -tolerance);
        const bool full_clear = full.max_sep + full.err_bound < -tolerance;
        EXPECT_EQ(clear.max_sep + clear.err_bound < -tolerance, full_clear) << sample;
        if (full_clear) expectSameBestAxes(full, clear, sample);
        if (!full_clear) ++not_clear;
        if (full.edge_sep > full.face_sep) ++edge_best;
        if (full.max_sep < 0) ++penetrating;
        if (best.edge_sep == -std::numeric_limits<Real>::infinity()) ++edges_skipped;
        if (::testing::Test::HasFailure()) break;
    }
    // The samples reach both kinds of best axis and both outcomes.
    EXPECT_GT(edge_best, 10000);
    EXPECT_GT(penetrating, 20000);
    EXPECT_LT(penetrating, 180000);
    EXPECT_GT(edges_skipped, 10000);
    EXPECT_GT(not_clear, 20000);
    EXPECT_LT(edges_skipped, 190000);
}

}  // namespace
