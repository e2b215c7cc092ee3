// The box SAT's best-axes measure (measureBoxSatBest, box_sat.h), which contact() and collide()
// use for clear overlaps, gives the full measure's best axes bit for bit (edges left unmeasured
// only when the best edge is below the best face): random poses, near- and exactly parallel
// edges, and poses scaled over eight orders of magnitude or moved far away, so the narrow phase
// answers exactly as it did with the full measure.
#include "volumes/box_sat.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
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

// The nine edge estimates as measureBoxSatBest first computed them, one edge at a time in
// scalars: the reference for boxSatEdgeEstimates, whose SSE2 form computes two edges per
// instruction.
void referenceEdgeEstimates(const Vec3& ea, const Mat3& rot, const Vec3& t, const Vec3& eb,
                            std::array<Real, 9>& hi, Real& cut, Real& max_hi) {
    alignas(16) std::array<float, 12> len2f{};
    std::array<Real, 9> unnormalised;
    std::array<bool, 9> measurable;
    for (int k = 0; k < 9; ++k) {
        const int i = k / 3;
        const int j = k % 3;
        const int i1 = (i + 1) % 3;
        const int i2 = (i + 2) % 3;
        const int j1 = (j + 1) % 3;
        const int j2 = (j + 2) % 3;
        const Real r1 = rot(i1, j);
        const Real r2 = rot(i2, j);
        const Real len2 = r1 * r1 + r2 * r2;
        const Real dist = std::abs(t[i2] * r1 - t[i1] * r2);
        const Real ra = ea[i1] * std::abs(r2) + ea[i2] * std::abs(r1);
        const Real rb = eb[j1] * std::abs(rot(i, j2)) + eb[j2] * std::abs(rot(i, j1));
        unnormalised[static_cast<std::size_t>(k)] = dist - ra - rb;
        measurable[static_cast<std::size_t>(k)] = len2 >= Real(1e-8);
        len2f[static_cast<std::size_t>(k)] = static_cast<float>(len2);
    }
    len2f[9] = len2f[10] = len2f[11] = 1.0f;
    alignas(16) std::array<float, 12> inv_len{};
    collision::boxSatRsqrt(len2f.data(), inv_len.data());
    cut = -std::numeric_limits<Real>::infinity();
    max_hi = -std::numeric_limits<Real>::infinity();
    for (std::size_t k = 0; k < 9; ++k) {
        const Real e = unnormalised[k] * static_cast<Real>(inv_len[k]);
        const Real slack = Real(1e-3) * std::abs(e);
        hi[k] = measurable[k] ? e + slack : std::numeric_limits<Real>::infinity();
        if (measurable[k]) cut = std::max(cut, e - slack);
        max_hi = std::max(max_hi, hi[k]);
    }
}

// Bitwise, NaN matching any NaN (the lanes may carry another NaN payload).
bool sameValue(Real x, Real y) { return sameBits(x, y) || (std::isnan(x) && std::isnan(y)); }

// An exact rotation of the cube's symmetry group: entries 0 and +-1, zeros of either sign.
Mat3 cubeRotation(cdlab_test::Rng& rng) {
    std::array<int, 3> perm{0, 1, 2};
    for (int k = 2; k > 0; --k) std::swap(perm[static_cast<std::size_t>(k)],
                                          perm[static_cast<std::size_t>(rng.integer(0, k))]);
    Mat3 r = Mat3::Zero();
    for (int k = 0; k < 3; ++k) {
        r(k, perm[static_cast<std::size_t>(k)]) = rng.integer(0, 1) ? Real(1) : Real(-1);
        // Negative zeros beside the ones, as a product of such matrices has.
        for (int c = 0; c < 3; ++c) {
            if (c != perm[static_cast<std::size_t>(k)] && rng.integer(0, 1)) r(k, c) = -Real(0);
        }
    }
    return r;
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

TEST(BoxSat, EdgeEstimatesEqualTheirScalarReference) {
    cdlab_test::Rng rng(20261127);
    int near_parallel = 0;
    for (int sample = 0; sample < 300000; ++sample) {
        const int kind = sample % 6;
        const Real scale = std::pow(Real(10), rng.uniform(-4, 4));
        Vec3 ea = scale * rng.vec(0.01, 1.5);
        Vec3 eb = scale * rng.vec(0.01, 1.5);
        Mat3 rot = (rng.rotation().conjugate() * rng.rotation()).toRotationMatrix();
        Vec3 t = scale * rng.uniform(0, 3) * (rng.rotation() * Vec3::UnitX());
        if (kind == 1) {
            const Real angle = std::pow(Real(10), rng.uniform(-12, -1));
            rot = rot * nearAligned(rng, angle).toRotationMatrix();
        }
        if (kind == 2) rot = nearAligned(rng, Real(0)).toRotationMatrix();
        if (kind == 3) rot = cubeRotation(rng);
        if (kind == 4) t += Vec3::Constant(Real(1e6));
        if (kind == 5 && sample % 60 == 5) {  // touching, zero and non-finite entries
            const int which = rng.integer(0, 3);
            if (which == 0) t = Vec3::Zero();
            const Real nan = std::numeric_limits<Real>::quiet_NaN();
            if (which == 1) rot(rng.integer(0, 2), rng.integer(0, 2)) = nan;
            if (which == 2) t[rng.integer(0, 2)] = std::numeric_limits<Real>::infinity();
            if (which == 3) ea[rng.integer(0, 2)] = Real(0);
        }
        std::array<Real, 9> hi;
        std::array<Real, 9> want_hi;
        Real cut = -std::numeric_limits<Real>::infinity();
        Real max_hi = -std::numeric_limits<Real>::infinity();
        Real want_cut = 0;
        Real want_max_hi = 0;
        collision::boxSatEdgeEstimates(ea, rot, t, eb, hi, cut, max_hi);
        referenceEdgeEstimates(ea, rot, t, eb, want_hi, want_cut, want_max_hi);
        for (std::size_t k = 0; k < 9; ++k) {
            ASSERT_TRUE(sameValue(hi[k], want_hi[k])) << "sample " << sample << " edge " << k;
            if (want_hi[k] == std::numeric_limits<Real>::infinity()) ++near_parallel;
        }
        ASSERT_TRUE(sameValue(cut, want_cut)) << "sample " << sample;
        ASSERT_TRUE(sameValue(max_hi, want_max_hi)) << "sample " << sample;
    }
    // Both kinds of edge were reached: measurable ones with finite bounds, near-parallel ones.
    EXPECT_GT(near_parallel, 50000);
    EXPECT_LT(near_parallel, 2000000);
}

}  // namespace
