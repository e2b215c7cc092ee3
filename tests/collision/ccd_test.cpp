// CCD queries: sphere time of impact against closed forms, and the conservative vertex-face /
// edge-edge queries against the exact ground truth of the Wang et al. 2021 sample queries
// (tests/data/ccd-sample-queries, MIT), beside the naive cubic baseline.
#include "collision/ccd/ccd.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

using collision::CcdOutput;
using collision::CcdSettings;
using collision::CcdState;
using collision::EdgeEdgeCcdInput;
using collision::Real;
using collision::Vec3;
using collision::VertexFaceCcdInput;
namespace fs = std::filesystem;

// ---------------------------------------------------------------- sample-query loading

/// One rational coordinate numerator/denominator as the nearest double. Integers are parsed
/// with strtold (64-bit mantissa); `exact` is true when both integers were parsed exactly
/// (checked by printing them back), the denominator is a power of two and the quotient is a
/// double, i.e. the double input *is* the rational input and the ground truth applies as is.
double parseRational(const std::string& num, const std::string& den, bool& exact) {
    const long double n = std::strtold(num.c_str(), nullptr);
    const long double d = std::strtold(den.c_str(), nullptr);
    auto printedBack = [](long double x, const std::string& s) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "%.0Lf", x);
        return s == buf;
    };
    const double value = static_cast<double>(n / d);
    int e = 0;
    const bool pow2 = d > 0 && std::frexp(d, &e) == 0.5L;
    exact = printedBack(n, num) && printedBack(d, den) && pow2 &&
            static_cast<long double>(value) * d == n;
    return value;
}

struct SampleQuery {
    std::array<Vec3, 4> t0{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    std::array<Vec3, 4> t1{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    bool truth = false;
    bool exact_input = true;
};

std::vector<SampleQuery> loadCsv(const fs::path& file) {
    std::vector<SampleQuery> queries;
    std::ifstream in(file);
    std::string line;
    std::vector<std::array<std::string, 7>> rows;
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        std::array<std::string, 7> cells;
        std::stringstream ss(line);
        for (std::string& c : cells) std::getline(ss, c, ',');
        rows.push_back(cells);
    }
    EXPECT_EQ(rows.size() % 8, 0u) << file;
    for (size_t q = 0; q + 8 <= rows.size(); q += 8) {
        SampleQuery sq;
        for (int r = 0; r < 8; ++r) {
            const auto& cells = rows[q + r];
            Vec3 p;
            for (int a = 0; a < 3; ++a) {
                bool exact = true;
                p[a] = static_cast<Real>(parseRational(cells[2 * a], cells[2 * a + 1], exact));
                sq.exact_input = sq.exact_input && exact;
            }
            (r < 4 ? sq.t0[r] : sq.t1[r - 4]) = p;
        }
        sq.truth = rows[q][6] == "1";
        queries.push_back(sq);
    }
    return queries;
}

/// Every sample query of one kind ("vertex-face" or "edge-edge"), by set name.
std::map<std::string, std::vector<SampleQuery>> loadKind(const std::string& kind) {
    std::map<std::string, std::vector<SampleQuery>> sets;
    const fs::path root = fs::path(CDLAB_SOURCE_DIR) / "tests/data/ccd-sample-queries";
    for (const auto& set_dir : fs::directory_iterator(root)) {
        if (!set_dir.is_directory()) continue;
        const fs::path dir = set_dir.path() / kind;
        if (!fs::is_directory(dir)) continue;
        std::vector<fs::path> files;
        for (const auto& f : fs::directory_iterator(dir)) {
            if (f.path().extension() == ".csv") files.push_back(f.path());
        }
        std::sort(files.begin(), files.end());
        auto& qs = sets[set_dir.path().filename().string()];
        for (const fs::path& f : files) {
            std::vector<SampleQuery> more = loadCsv(f);
            qs.insert(qs.end(), more.begin(), more.end());
        }
    }
    return sets;
}

struct Tally {
    int queries = 0, positives = 0, false_negatives = 0, false_positives = 0, failed = 0;
    int inexact = 0, inexact_false_negatives = 0;
};

bool reportsContact(const CcdOutput& o) {
    return o.state == CcdState::Hit || o.state == CcdState::Failed ||
           o.state == CcdState::Overlapped;
}

template <class Input, class Fn>
Tally runSet(const std::vector<SampleQuery>& qs, Fn&& fn) {
    Tally t;
    for (const SampleQuery& q : qs) {
        const CcdOutput o = fn(Input{q.t0, q.t1});
        EXPECT_TRUE(std::isfinite(o.t));
        const bool hit = reportsContact(o);
        ++t.queries;
        t.positives += q.truth;
        t.failed += o.state == CcdState::Failed;
        t.inexact += !q.exact_input;
        if (q.truth && !hit) {
            // The ground truth is for the rational input; when the double rounding changed
            // the input, a miss is counted apart (none in the shipped data: all exact).
            if (q.exact_input) {
                ++t.false_negatives;
            } else {
                ++t.inexact_false_negatives;
            }
        }
        t.false_positives += !q.truth && hit;
    }
    return t;
}

void recordTally(const std::string& name, const Tally& t) {
    ::testing::Test::RecordProperty(name + "_queries", t.queries);
    ::testing::Test::RecordProperty(name + "_false_negatives", t.false_negatives);
    ::testing::Test::RecordProperty(name + "_false_positives", t.false_positives);
    ::testing::Test::RecordProperty(name + "_inexact_inputs", t.inexact);
    std::printf("%-44s queries %5d  positives %5d  FN %4d  FP %4d  failed %d  inexact %d\n",
                name.c_str(), t.queries, t.positives, t.false_negatives, t.false_positives,
                t.failed, t.inexact);
}

// ---------------------------------------------------------------- spheres

TEST(CcdSpheres, HeadOnMatchesClosedForm) {
    // B (r = 1) moves from x = 10 to x = 0 towards A (r = 1) at rest: contact at 10 - 10t = 2.
    const CcdOutput o = collision::timeOfImpactSpheres(Vec3(0, 0, 0), Vec3(0, 0, 0), 1,
                                                       Vec3(10, 0, 0), Vec3(0, 0, 0), 1);
    ASSERT_EQ(o.state, CcdState::Hit);
    EXPECT_NEAR(o.t, 0.8, 2e-16);
    EXPECT_NEAR(o.normal.x(), 1.0, 1e-15);
}

TEST(CcdSpheres, OffsetByOneMillionGivesTheSameTime) {
    const Vec3 c0a(0.25, -0.5, 0.125), c1a(0.75, 0.5, -0.25);
    const Vec3 c0b(3.5, 1.25, 0.5), c1b(-1.5, 0.25, 0.75);
    const CcdOutput ref = collision::timeOfImpactSpheres(c0a, c1a, 0.5, c0b, c1b, 0.75);
    ASSERT_EQ(ref.state, CcdState::Hit);
    // Closed form in long double for the relative motion.
    const Eigen::Matrix<long double, 3, 1> d0 = (c0b - c0a).cast<long double>();
    const Eigen::Matrix<long double, 3, 1> dv = ((c1b - c0b) - (c1a - c0a)).cast<long double>();
    const long double a = dv.squaredNorm(), b = d0.dot(dv), c = d0.squaredNorm() - 1.5625L;
    const long double t_exact = (-b - std::sqrt(b * b - a * c)) / a;
    EXPECT_NEAR(ref.t, static_cast<double>(t_exact), 4 * 2.2e-16);
    // A 1e6 offset (exact in double for these inputs) must not change the answer at all.
    const Vec3 off(1e6, -1e6, 1e6);
    const CcdOutput moved =
        collision::timeOfImpactSpheres(c0a + off, c1a + off, 0.5, c0b + off, c1b + off, 0.75);
    ASSERT_EQ(moved.state, CcdState::Hit);
    EXPECT_EQ(moved.t, ref.t);
    // An offset that rounds the inputs changes t only by rounding of those inputs.
    const Vec3 odd(1e6 + 0.1, 3e6 + 0.3, -7e6 - 0.7);
    const CcdOutput rounded =
        collision::timeOfImpactSpheres(c0a + odd, c1a + odd, 0.5, c0b + odd, c1b + odd, 0.75);
    ASSERT_EQ(rounded.state, CcdState::Hit);
    EXPECT_NEAR(rounded.t, ref.t, 1e-9);
}

TEST(CcdSpheres, TinyAndHugeScalesGiveTheSameTime) {
    const Vec3 c0a(0.3, -0.2, 0.1), c1a(0.7, 0.4, -0.2);
    const Vec3 c0b(3.1, 1.3, 0.6), c1b(-1.2, 0.2, 0.8);
    const CcdOutput ref = collision::timeOfImpactSpheres(c0a, c1a, 0.45, c0b, c1b, 0.8);
    ASSERT_EQ(ref.state, CcdState::Hit);
    for (const Real s : {1e-4, 1e-2, 1e2, 1e4, 1e-150, 1e150}) {  // squares would under/overflow
        const CcdOutput o =
            collision::timeOfImpactSpheres(s * c0a, s * c1a, s * 0.45, s * c0b, s * c1b, s * 0.8);
        ASSERT_EQ(o.state, CcdState::Hit) << s;
        EXPECT_NEAR(o.t, ref.t, 1e-14 * ref.t) << s;
    }
}

TEST(CcdSpheres, EarlyRootIsCancellationFree) {
    // Contact almost at once with a fast approach: t = 2^-30 / 1000 exactly. The textbook
    // (-b - sqrt(D)) / a loses ~9 digits here; c / q keeps them.
    const Real gap = std::ldexp(1.0, -30);
    const CcdOutput o = collision::timeOfImpactSpheres(
        Vec3(0, 0, 0), Vec3(0, 0, 0), 0.5, Vec3(1 + gap, 0, 0), Vec3(1 + gap - 1000, 0, 0), 0.5);
    ASSERT_EQ(o.state, CcdState::Hit);
    EXPECT_NEAR(o.t, gap / 1000, 4e-16 * (gap / 1000));
}

TEST(CcdSpheres, GrazingIsAHitAndANearMissIsNot) {
    // B passes A at exactly centre distance 2 = ra + rb, at t = 0.5 (discriminant exactly 0).
    const CcdOutput graze = collision::timeOfImpactSpheres(Vec3(0, 0, 0), Vec3(0, 0, 0), 1,
                                                           Vec3(-5, 2, 0), Vec3(5, 2, 0), 1);
    ASSERT_EQ(graze.state, CcdState::Hit);
    EXPECT_NEAR(graze.t, 0.5, 1e-6);  // a double root: t moves with sqrt of the rounding
    EXPECT_NEAR(graze.normal.y(), 1.0, 1e-15);
    const CcdOutput miss = collision::timeOfImpactSpheres(
        Vec3(0, 0, 0), Vec3(0, 0, 0), 1, Vec3(-5, 2 + 1e-9, 0), Vec3(5, 2 + 1e-9, 0), 1);
    EXPECT_EQ(miss.state, CcdState::Separated);
}

TEST(CcdSpheres, ZeroRelativeVelocityOverlapTouchAndLateImpact) {
    const Vec3 v(3, -2, 1);
    // Same motion, apart: never closer.
    EXPECT_EQ(
        collision::timeOfImpactSpheres(Vec3(0, 0, 0), v, 1, Vec3(5, 0, 0), Vec3(5, 0, 0) + v, 1)
            .state,
        CcdState::Separated);
    // Same motion, overlapping: Overlapped at t = 0.
    const CcdOutput over =
        collision::timeOfImpactSpheres(Vec3(0, 0, 0), v, 1, Vec3(1, 0, 0), Vec3(1, 0, 0) + v, 1);
    EXPECT_EQ(over.state, CcdState::Overlapped);
    EXPECT_EQ(over.t, 0.0);
    // Touching at t = 0 and approaching: Hit at 0; touching and receding: Separated.
    const CcdOutput touch_in = collision::timeOfImpactSpheres(Vec3(0, 0, 0), Vec3(0, 0, 0), 1,
                                                              Vec3(2, 0, 0), Vec3(0, 0, 0), 1);
    EXPECT_EQ(touch_in.state, CcdState::Hit);
    EXPECT_EQ(touch_in.t, 0.0);
    EXPECT_EQ(collision::timeOfImpactSpheres(Vec3(0, 0, 0), Vec3(0, 0, 0), 1, Vec3(2, 0, 0),
                                             Vec3(4, 0, 0), 1)
                  .state,
              CcdState::Separated);
    // Impact only after the step: Separated.
    EXPECT_EQ(collision::timeOfImpactSpheres(Vec3(0, 0, 0), Vec3(0, 0, 0), 1, Vec3(10, 0, 0),
                                             Vec3(5, 0, 0), 1)
                  .state,
              CcdState::Separated);
    // Point spheres through each other: Hit, finite normal.
    const CcdOutput points = collision::timeOfImpactSpheres(Vec3(0, 0, 0), Vec3(0, 0, 0), 0,
                                                            Vec3(1, 0, 0), Vec3(-1, 0, 0), 0);
    EXPECT_EQ(points.state, CcdState::Hit);
    EXPECT_EQ(points.t, 0.5);
    EXPECT_TRUE(points.normal.allFinite());
    // Bad input.
    EXPECT_EQ(collision::timeOfImpactSpheres(Vec3(NAN, 0, 0), Vec3(0, 0, 0), 1, Vec3(2, 0, 0),
                                             Vec3(0, 0, 0), 1)
                  .state,
              CcdState::Failed);
}

// ---------------------------------------------------------------- sample queries

// False positives of the conservative method per set, measured (double, x86-64, this commit):
// the bound each set must not exceed. Tight-Inclusion (Wang et al. 2021) reports 85 vertex-face
// and 137 edge-edge false positives on the whole handcrafted set; this shipped subset gives
// 13 (vertex-face: cube-internal-edges 7, spikes 6) and 25 (edge-edge: cube-internal-edges 10,
// spikes 15), no Failed query. A set not listed must have none.
struct MeasuredFalsePositives {
    const char* set;
    int false_positives;
};
constexpr MeasuredFalsePositives kMeasuredVf[] = {{"erleben-cube-internal-edges", 7},
                                                  {"erleben-spikes", 6}};
constexpr MeasuredFalsePositives kMeasuredEe[] = {
    {"erleben-cube-internal-edges", 10}, {"erleben-spikes", 15}};

template <std::size_t N>
int maxFalsePositives(const MeasuredFalsePositives (&table)[N], const std::string& set) {
    for (const MeasuredFalsePositives& m : table) {
        if (set == m.set) return m.false_positives;
    }
    return 0;
}

TEST(CcdSampleQueries, ConservativeHasNoFalseNegativesNaiveHasSome) {
    CcdSettings settings;
    Tally all_vf, all_ee, naive_vf, naive_ee;
    auto add = [](Tally& sum, const Tally& t) {
        sum.queries += t.queries;
        sum.positives += t.positives;
        sum.false_negatives += t.false_negatives;
        sum.false_positives += t.false_positives;
        sum.failed += t.failed;
        sum.inexact += t.inexact;
        sum.inexact_false_negatives += t.inexact_false_negatives;
    };
    for (const auto& [set, qs] : loadKind("vertex-face")) {
        const Tally t = runSet<VertexFaceCcdInput>(qs, [&](const VertexFaceCcdInput& in) {
            return collision::vertexFaceCcd(in, settings);
        });
        recordTally("conservative_vf_" + set, t);
        EXPECT_EQ(t.false_negatives, 0) << set;
        EXPECT_EQ(t.inexact_false_negatives, 0) << set;
        EXPECT_EQ(t.failed, 0) << set;
        EXPECT_LE(t.false_positives, maxFalsePositives(kMeasuredVf, set)) << set;
        add(all_vf, t);
        add(naive_vf, runSet<VertexFaceCcdInput>(qs, collision::vertexFaceCcdNaive));
    }
    for (const auto& [set, qs] : loadKind("edge-edge")) {
        const Tally t = runSet<EdgeEdgeCcdInput>(
            qs, [&](const EdgeEdgeCcdInput& in) { return collision::edgeEdgeCcd(in, settings); });
        recordTally("conservative_ee_" + set, t);
        EXPECT_EQ(t.false_negatives, 0) << set;
        EXPECT_EQ(t.inexact_false_negatives, 0) << set;
        EXPECT_EQ(t.failed, 0) << set;
        EXPECT_LE(t.false_positives, maxFalsePositives(kMeasuredEe, set)) << set;
        add(all_ee, t);
        add(naive_ee, runSet<EdgeEdgeCcdInput>(qs, collision::edgeEdgeCcdNaive));
    }
    recordTally("conservative_vf_all", all_vf);
    recordTally("conservative_ee_all", all_ee);
    recordTally("naive_vf_all", naive_vf);
    recordTally("naive_ee_all", naive_ee);
    // The data must exercise both outcomes and every query must have loaded.
    EXPECT_EQ(all_vf.queries, 1750);
    EXPECT_EQ(all_ee.queries, 1574);
    EXPECT_GT(all_vf.positives, 0);
    EXPECT_LT(all_vf.positives, all_vf.queries);
    EXPECT_EQ(all_vf.false_negatives + all_ee.false_negatives, 0);
    // Reporting "contact" everywhere would pass the false-negative checks: the false positives
    // (and Failed, counted as contact) are bounded too, per set above and in total here.
    EXPECT_EQ(all_vf.failed + all_ee.failed, 0);
    EXPECT_LE(all_vf.false_positives, 13);
    EXPECT_LE(all_ee.false_positives, 25);
    // The naive cubic is deterministic on this data (IEEE double, no FMA contraction on x86-64
    // by default); it must miss contacts, which is the point of the conservative method.
    // Measured: 5 vertex-face and 71 edge-edge misses (1 false positive each, never Failed).
    EXPECT_EQ(naive_vf.false_negatives, 5);
    EXPECT_EQ(naive_ee.false_negatives, 71);
}

// ---------------------------------------------------------------- analytic primitive cases

VertexFaceCcdInput fallingVertex(Real z0, Real z1) {
    // Face z = 0 at rest, a vertex above its interior falling from z0 to z1.
    VertexFaceCcdInput in;
    in.t0 = {Vec3(0.2, 0.3, z0), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    in.t1 = {Vec3(0.2, 0.3, z1), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    return in;
}

TEST(CcdPrimitives, FallingVertexHitsAtTheAnalyticTimeNeverLater) {
    for (const Real z0 : {1.0, 0.5, 0.01, 1e-7}) {
        const VertexFaceCcdInput in = fallingVertex(z0, z0 - 2);
        const Real t_true = z0 / 2;
        const CcdOutput o = collision::vertexFaceCcd(in);
        ASSERT_EQ(o.state, CcdState::Hit) << z0;
        EXPECT_LE(o.t, t_true) << z0;
        EXPECT_GE(o.t_upper, t_true) << z0;
        EXPECT_GT(o.t, t_true - 1e-5) << z0;  // within the acceptance width / speed
        EXPECT_NEAR(o.u, 0.2, 1e-3);
        EXPECT_NEAR(o.v, 0.3, 1e-3);
        const CcdOutput n = collision::vertexFaceCcdNaive(in);
        ASSERT_EQ(n.state, CcdState::Hit);
        EXPECT_NEAR(n.t, t_true, 1e-15);
    }
    // Stopping short of the face, or passing beside it: no contact.
    EXPECT_EQ(collision::vertexFaceCcd(fallingVertex(1, 0.001)).state, CcdState::Separated);
    VertexFaceCcdInput beside = fallingVertex(1, -1);
    beside.t0[0].x() = beside.t1[0].x() = 0.8;  // 0.8 + 0.3 > 1: outside the triangle
    EXPECT_EQ(collision::vertexFaceCcd(beside).state, CcdState::Separated);
}

TEST(CcdPrimitives, CrossingEdgesHitAtTheAnalyticTimeNeverLater) {
    // Edge a along x at z = 0; edge b along y, falling from z = 1 to z = -3: meet at t = 0.25.
    EdgeEdgeCcdInput in;
    in.t0 = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0.5, -1, 1), Vec3(0.5, 1, 1)};
    in.t1 = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0.5, -1, -3), Vec3(0.5, 1, -3)};
    const CcdOutput o = collision::edgeEdgeCcd(in);
    ASSERT_EQ(o.state, CcdState::Hit);
    EXPECT_LE(o.t, 0.25);
    EXPECT_GE(o.t_upper, 0.25);
    EXPECT_GT(o.t, 0.25 - 1e-5);
    EXPECT_NEAR(o.u, 0.75, 1e-3);
    EXPECT_NEAR(o.v, 0.5, 1e-3);
    // Metamorphic: a 1e6 translation keeps the hit and the time (to the acceptance width).
    EdgeEdgeCcdInput moved = in;
    for (Vec3& p : moved.t0) p += Vec3(1e6, -1e6, 1e6);
    for (Vec3& p : moved.t1) p += Vec3(1e6, -1e6, 1e6);
    const CcdOutput m = collision::edgeEdgeCcd(moved);
    ASSERT_EQ(m.state, CcdState::Hit);
    EXPECT_LE(m.t, 0.25);
    EXPECT_GT(m.t, 0.25 - 1e-4);
}

// A vertex-face query built to touch: the vertex meets the face at barycentric (us, vs) at
// time ts, all drawn from `rng` with corners in [-1, 1]^3; its first contact is at or before ts
// (another may come earlier), up to the rounding of the construction.
struct ConstructedContact {
    VertexFaceCcdInput vf;
    Real ts, us, vs;
};

ConstructedContact constructedVertexFaceContact(std::mt19937& rng) {
    std::uniform_real_distribution<Real> coord(-1, 1), unit(0.05, 0.95);
    ConstructedContact c;
    c.ts = unit(rng);
    c.us = unit(rng);
    c.vs = unit(rng);
    if (c.us + c.vs > 1) {
        c.us = 1 - c.us;
        c.vs = 1 - c.vs;
    }
    auto randVec = [&] { return Vec3(coord(rng), coord(rng), coord(rng)); };
    VertexFaceCcdInput& vf = c.vf;
    for (int k = 1; k < 4; ++k) {
        vf.t0[k] = randVec();
        vf.t1[k] = randVec();
    }
    auto at = [&](const Vec3& a, const Vec3& b) { return Vec3(a + c.ts * (b - a)); };
    const Vec3 target = (1 - c.us - c.vs) * at(vf.t0[1], vf.t1[1]) +
                        c.us * at(vf.t0[2], vf.t1[2]) + c.vs * at(vf.t0[3], vf.t1[3]);
    vf.t0[0] = randVec();
    vf.t1[0] = vf.t0[0] + (target - vf.t0[0]) / c.ts;
    return c;
}

TEST(CcdPrimitives, RandomContactsAreFoundNoLaterThanConstructed) {
    // Construct a contact at a chosen (t*, u*, v*) with random motion: the first contact is at
    // or before t* (another one may come earlier), up to the rounding of the constructed input.
    std::mt19937 rng(1234);
    std::uniform_real_distribution<Real> coord(-1, 1);
    int vf_hits = 0, ee_hits = 0;
    for (int i = 0; i < 300; ++i) {
        const ConstructedContact c = constructedVertexFaceContact(rng);
        const Real ts = c.ts, us = c.us, vs = c.vs;
        auto randVec = [&] { return Vec3(coord(rng), coord(rng), coord(rng)); };
        auto at = [&](const Vec3& a, const Vec3& b) { return Vec3(a + ts * (b - a)); };
        const CcdOutput o = collision::vertexFaceCcd(c.vf);
        ASSERT_EQ(o.state, CcdState::Hit) << i;
        EXPECT_LE(o.t, ts + 1e-9) << i;
        vf_hits += o.state == CcdState::Hit;

        EdgeEdgeCcdInput ee;
        for (int k = 0; k < 3; ++k) {
            ee.t0[k] = randVec();
            ee.t1[k] = randVec();
        }
        // b0 + vs (b1 - b0) == a(ts, us) at ts: choose b0(ts), then b1(ts) on the line.
        const Vec3 pa = (1 - us) * at(ee.t0[0], ee.t1[0]) + us * at(ee.t0[1], ee.t1[1]);
        const Vec3 b0 = at(ee.t0[2], ee.t1[2]);
        const Vec3 b1 = b0 + (pa - b0) / vs;
        ee.t0[3] = randVec();
        ee.t1[3] = ee.t0[3] + (b1 - ee.t0[3]) / ts;
        const CcdOutput e = collision::edgeEdgeCcd(ee);
        ASSERT_EQ(e.state, CcdState::Hit) << i;
        EXPECT_LE(e.t, ts + 1e-9) << i;
        ee_hits += e.state == CcdState::Hit;
    }
    EXPECT_EQ(vf_hits, 300);
    EXPECT_EQ(ee_hits, 300);
}

TEST(CcdPrimitives, SlidesParallelToThePrimitiveResolveInFewBoxes) {
    // A vertex sliding across a face 1e-5 above it, and an edge sliding across another edge
    // 1e-5 above it, for the whole step; rotated off the axes so no coordinate axis separates
    // them. Per-axis bounds of F need (u, v) cells about 1e-5 wide along the whole slide (tens
    // of thousands of boxes); projected on the plane normal the gap shows at once.
    //
    //      v(0) ------------------> v(1)     1e-5 above
    //   ====================================  face (or edge b)
    const collision::Mat3 rot =
        (Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized())).toRotationMatrix();
    auto rotate = [&](std::array<Vec3, 4>& ps) {
        for (Vec3& p : ps) p = rot * p;
    };
    VertexFaceCcdInput vf;
    vf.t0 = {Vec3(-0.9, 0.1, 1e-5), Vec3(-1, -1, 0), Vec3(2, -1, 0), Vec3(-1, 2, 0)};
    vf.t1 = {Vec3(0.9, 0.2, 1e-5), Vec3(-1, -1, 0), Vec3(2, -1, 0), Vec3(-1, 2, 0)};
    rotate(vf.t0);
    rotate(vf.t1);
    const CcdOutput o = collision::vertexFaceCcd(vf);
    EXPECT_EQ(o.state, CcdState::Separated);
    RecordProperty("vertex_face_slide_boxes", o.iterations);
    EXPECT_LT(o.iterations, 200);

    EdgeEdgeCcdInput ee;
    ee.t0 = {Vec3(-1, -0.9, 1e-5), Vec3(1, -0.9, 1e-5), Vec3(0.1, -1, 0), Vec3(-0.1, 1, 0)};
    ee.t1 = {Vec3(-1, 0.9, 1e-5), Vec3(1, 0.9, 1e-5), Vec3(0.1, -1, 0), Vec3(-0.1, 1, 0)};
    rotate(ee.t0);
    rotate(ee.t1);
    const CcdOutput e = collision::edgeEdgeCcd(ee);
    EXPECT_EQ(e.state, CcdState::Separated);
    RecordProperty("edge_edge_slide_boxes", e.iterations);
    EXPECT_LT(e.iterations, 200);

    // The same vertex slide descending through the face at t = 0.5 (height 1e-5 (1 - 2t)):
    // a Hit, never later than 0.5, found as cheaply.
    VertexFaceCcdInput down = vf;
    down.t0[0] = rot * Vec3(-0.9, 0.1, 1e-5);
    down.t1[0] = rot * Vec3(0.9, 0.2, -1e-5);
    const CcdOutput d = collision::vertexFaceCcd(down);
    ASSERT_EQ(d.state, CcdState::Hit);
    EXPECT_LE(d.t, 0.5);
    EXPECT_GT(d.t, 0.5 - 1e-3);
    EXPECT_LT(d.iterations, 200);
}

TEST(CcdPrimitives, HugeCoordinatesFindTheSameContacts) {
    // Metamorphic: contacts constructed as in RandomContactsAreFoundNoLaterThanConstructed, then
    // every coordinate scaled by 2^320..2^379 (1e96..1e114, inside the accepted input range).
    // A projection of F on the raw plane normal (coordinates squared, then times F) overflows
    // to +-inf and NaN there while its rounding bound is still finite: NaN corners were skipped
    // and a box holding the contact was excluded (about a quarter of these came back
    // Separated). Every contact must still be a Hit, never later than constructed.
    if (sizeof(Real) < sizeof(double)) GTEST_SKIP() << "float coordinates cannot be this large";
    std::mt19937 rng(77);
    int hits = 0;
    constexpr int kQueries = 600;
    for (int i = 0; i < kQueries; ++i) {
        const Real scale = std::ldexp(Real(1), 320 + i % 60);
        ConstructedContact c = constructedVertexFaceContact(rng);
        const Real ts = c.ts;
        VertexFaceCcdInput& vf = c.vf;
        for (int k = 0; k < 4; ++k) {
            vf.t0[k] *= scale;  // exact: a power of two
            vf.t1[k] *= scale;
        }
        const CcdOutput o = collision::vertexFaceCcd(vf);
        EXPECT_NE(o.state, CcdState::Separated) << i;
        EXPECT_LE(o.t, ts + 1e-9) << i;
        hits += o.state == CcdState::Hit;
    }
    EXPECT_EQ(hits, kQueries);
}

TEST(CcdPrimitives, CapReturnsFailedWithASafeTime) {
    // Pathological: a vertex sliding in the face's plane, 1e-5 outside its edge for the whole
    // step (coplanar motion: the cubic is identically zero), needs many boxes near the edge.
    // Rotated off the axes, so no single axis separates the vertex from the face.
    const collision::Mat3 rot =
        (Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized())).toRotationMatrix();
    VertexFaceCcdInput in;
    in.t0 = {Vec3(-1e-5, -1, 0), Vec3(0, -2, 0), Vec3(0, 2, 0), Vec3(2, 0, 0)};
    in.t1 = {Vec3(-1e-5, 1, 0), Vec3(0, -2, 0), Vec3(0, 2, 0), Vec3(2, 0, 0)};
    for (Vec3& p : in.t0) p = rot * p;
    for (Vec3& p : in.t1) p = rot * p;
    // Truth is Separated; a near-zero curve of F this long may also exhaust the default cap,
    // which must then come back as Failed (never a hang, never a wrong Separated elsewhere).
    const CcdOutput full = collision::vertexFaceCcd(in);
    EXPECT_TRUE(full.state == CcdState::Separated || full.state == CcdState::Failed);
    RecordProperty("coplanar_near_miss_boxes", full.iterations);
    EXPECT_GT(full.iterations, 20);
    EXPECT_LE(full.iterations, CcdSettings{}.max_boxes);
    CcdSettings capped;
    capped.max_boxes = 10;
    const CcdOutput o = collision::vertexFaceCcd(in, capped);
    EXPECT_EQ(o.state, CcdState::Failed);
    EXPECT_LE(o.iterations, 10);
    EXPECT_GE(o.t, 0.0);
    EXPECT_LE(o.t, 1.0);
    // A real hit under a tiny cap: Failed, and the safe time is not after the contact.
    CcdSettings one;
    one.max_boxes = 3;
    const CcdOutput f = collision::vertexFaceCcd(fallingVertex(1, -1), one);
    EXPECT_EQ(f.state, CcdState::Failed);
    EXPECT_LE(f.t, 0.5);
    // The naive method misses this coplanar slide entirely when it touches (cubic == 0).
    VertexFaceCcdInput touching = in;
    touching.t0[0] = rot * Vec3(0.5, -1, 0);
    touching.t1[0] = rot * Vec3(0.5, 1, 0);
    EXPECT_EQ(collision::vertexFaceCcd(touching).state, CcdState::Hit);
    EXPECT_EQ(collision::vertexFaceCcd(touching).t, 0.0);
    // Axis-aligned, the coplanarity cubic is exactly zero: the naive method sees no root.
    VertexFaceCcdInput flat;
    flat.t0 = {Vec3(0.5, -1, 0), Vec3(0, -2, 0), Vec3(0, 2, 0), Vec3(2, 0, 0)};
    flat.t1 = {Vec3(0.5, 1, 0), Vec3(0, -2, 0), Vec3(0, 2, 0), Vec3(2, 0, 0)};
    EXPECT_EQ(collision::vertexFaceCcd(flat).state, CcdState::Hit);
    EXPECT_EQ(collision::vertexFaceCcdNaive(flat).state, CcdState::Separated);
}

TEST(CcdPrimitives, MinSeparationReportsNearMisses) {
    // Vertex stops 1e-3 above the face: Separated at gap 0, Hit with min_separation 2e-3.
    const VertexFaceCcdInput in = fallingVertex(1, 1e-3);
    EXPECT_EQ(collision::vertexFaceCcd(in).state, CcdState::Separated);
    CcdSettings gap;
    gap.min_separation = 2e-3;
    const CcdOutput o = collision::vertexFaceCcd(in, gap);
    // The first contact is a whole square patch of (u, v) (the L-inf ball's face is parallel
    // to the triangle): resolved by bracketing t between excluded boxes and a box that is
    // all contact, in a few hundred boxes rather than the cap.
    ASSERT_EQ(o.state, CcdState::Hit);
    EXPECT_LT(o.iterations, 2000);
    // Within 2e-3 from z = 1 - 0.999 t <= 2e-3, i.e. t >= 0.998/0.999.
    EXPECT_LE(o.t, 0.998 / 0.999);
    EXPECT_GE(o.t_upper, 0.998 / 0.999);
    EXPECT_GT(o.t, 0.998 / 0.999 - 2e-6);
}

TEST(CcdPrimitives, DegenerateInputsNeverNaNOrHang) {
    const Vec3 a(0.1, 0.2, 0.3);
    auto check = [](const CcdOutput& o) {
        EXPECT_TRUE(std::isfinite(o.t));
        EXPECT_TRUE(std::isfinite(o.u));
        EXPECT_TRUE(std::isfinite(o.v));
    };
    // Contact sets that are curves at the first contact time (collinear face, parallel edges):
    // resolved by the look-ahead bisection in t, well inside a small cap.
    CcdSettings small_cap;
    small_cap.max_boxes = 20'000;
    // Zero motion, apart and touching.
    VertexFaceCcdInput still;
    still.t0 = still.t1 = {Vec3(0.2, 0.2, 1), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    check(collision::vertexFaceCcd(still));
    EXPECT_EQ(collision::vertexFaceCcd(still).state, CcdState::Separated);
    check(collision::vertexFaceCcdNaive(still));
    still.t0[0].z() = still.t1[0].z() = 0;
    EXPECT_EQ(collision::vertexFaceCcd(still).state, CcdState::Hit);
    EXPECT_EQ(collision::vertexFaceCcd(still).t, 0.0);
    // Degenerate triangle (all three corners equal) with a vertex passing through that point,
    // and a collinear triangle crossed by the vertex.
    VertexFaceCcdInput point_face;
    point_face.t0 = {Vec3(a.x(), a.y(), 1), a, a, a};
    point_face.t1 = {Vec3(a.x(), a.y(), -1), a, a, a};
    point_face.t0[0].z() = 1;
    point_face.t1[0].z() = -1;
    point_face.t0[1] = point_face.t0[2] = point_face.t0[3] = Vec3(a.x(), a.y(), 0);
    point_face.t1[1] = point_face.t1[2] = point_face.t1[3] = Vec3(a.x(), a.y(), 0);
    const CcdOutput pf = collision::vertexFaceCcd(point_face);
    check(pf);
    EXPECT_EQ(pf.state, CcdState::Hit);
    EXPECT_LE(pf.t, 0.5);
    check(collision::vertexFaceCcdNaive(point_face));
    VertexFaceCcdInput line_face = fallingVertex(1, -1);
    line_face.t0[3] = line_face.t1[3] = Vec3(0.5, 0, 0);
    line_face.t0[0].y() = line_face.t1[0].y() = 0;  // crosses the segment
    const CcdOutput lf = collision::vertexFaceCcd(line_face, small_cap);
    check(lf);
    EXPECT_EQ(lf.state, CcdState::Hit);
    EXPECT_LE(lf.t, 0.5);
    EXPECT_GT(lf.t, 0.5 - 1e-5);
    check(collision::vertexFaceCcdNaive(line_face));

    // Parallel edges: coplanar and overlapping (touch for the whole step), and coplanar apart.
    EdgeEdgeCcdInput parallel;
    parallel.t0 = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 0, 0), Vec3(2, 0, 0)};
    parallel.t1 = parallel.t0;
    const CcdOutput par = collision::edgeEdgeCcd(parallel);
    check(par);
    EXPECT_EQ(par.state, CcdState::Hit);
    EXPECT_EQ(par.t, 0.0);
    check(collision::edgeEdgeCcdNaive(parallel));
    for (Vec3& p : parallel.t0) p.y() += (&p - &parallel.t0[0]) >= 2 ? 0.5 : 0.0;
    parallel.t1 = parallel.t0;
    EXPECT_EQ(collision::edgeEdgeCcd(parallel).state, CcdState::Separated);
    // Parallel edges approaching each other: meet at t = 0.5.
    EdgeEdgeCcdInput closing;
    closing.t0 = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(1, 0, 1)};
    closing.t1 = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, -1), Vec3(1, 0, -1)};
    const CcdOutput cl = collision::edgeEdgeCcd(closing, small_cap);
    check(cl);
    EXPECT_EQ(cl.state, CcdState::Hit);
    EXPECT_LE(cl.t, 0.5);
    EXPECT_GT(cl.t, 0.5 - 1e-5);
    check(collision::edgeEdgeCcdNaive(closing));
    // Zero-length edges (points) passing through each other.
    EdgeEdgeCcdInput points;
    points.t0 = {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(1, 1, 1)};
    points.t1 = {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(-1, -1, -1), Vec3(-1, -1, -1)};
    const CcdOutput pts = collision::edgeEdgeCcd(points);
    check(pts);
    EXPECT_EQ(pts.state, CcdState::Hit);
    EXPECT_LE(pts.t, 0.5);
    check(collision::edgeEdgeCcdNaive(points));
    // Everything at one point.
    EdgeEdgeCcdInput zero;
    zero.t0 = zero.t1 = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    check(collision::edgeEdgeCcd(zero));
    check(collision::edgeEdgeCcdNaive(zero));
    // Non-finite input: Failed at t = 0, no NaN out.
    EdgeEdgeCcdInput bad = closing;
    bad.t1[2].x() = NAN;
    const CcdOutput b = collision::edgeEdgeCcd(bad);
    EXPECT_EQ(b.state, CcdState::Failed);
    EXPECT_EQ(b.t, 0.0);
}

}  // namespace
