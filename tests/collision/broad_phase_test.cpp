// Differential tests: every broad phase in the registry reports exactly its brute-force
// reference's pair set on every frame of random and adversarial coherent-motion scenes,
// including touching and zero-size boxes and proxies leaving and re-entering. collision_tests
// runs them on every broad phase that needs no rendering context; cullide_tests compiles this
// same file, installs render's occlusion-query oracle and runs them on those that do.
#include "collision/broadphase/broad_phase.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <set>
#include <string_view>

#include "broadphase/hgrid.h"
#include "collision/debug_draw.h"
#include "collision/visibility_oracle.h"
#include "broad_phase_scenes.h"
#include "test_random.h"

namespace collision {
namespace {

using namespace cdlab_test;

// Runs `name` and its reference side by side through the same frames, inserts and removes.
void expectEqualsReference(const BroadPhaseEntry& entry, Layout layout, int n, int frames,
                           std::uint64_t seed) {
    SCOPED_TRACE(std::string(entry.name) + " on " + layoutName(layout));
    const BroadPhaseEntry* ref_entry = findBroadPhase(entry.reference);
    ASSERT_NE(ref_entry, nullptr);
    std::unique_ptr<BroadPhase> fast = entry.create();
    std::unique_ptr<BroadPhase> ref = ref_entry->create();
    Rng rng(seed);
    std::vector<MovingBox> boxes = makeScene(layout, n, rng);
    for (int i = 0; i < n; ++i) {
        fast->insert(i, boxes[i].volumes());
        ref->insert(i, boxes[i].volumes());
    }
    std::vector<ProxyPair> fast_pairs;
    std::vector<ProxyPair> ref_pairs;
    std::int64_t total_pairs = 0;
    int frames_with_pairs = 0;
    for (int frame = 0; frame < frames; ++frame) {
        if (frame > 0) {
            advance(boxes, layout);
            // Bodies leave and re-enter: a few proxies removed, a few re-inserted.
            for (int i = 0; i < n; ++i) {
                MovingBox& b = boxes[i];
                if (b.present && rng.integer(0, 40) == 0) {
                    b.present = false;
                    fast->remove(i);
                    ref->remove(i);
                } else if (!b.present && rng.integer(0, 5) == 0) {
                    b.present = true;
                    fast->insert(i, b.volumes());
                    ref->insert(i, b.volumes());
                } else if (b.present) {
                    fast->move(i, b.volumes());
                    ref->move(i, b.volumes());
                }
            }
        }
        BroadPhaseCounters fc;
        BroadPhaseCounters rc;
        fast->findPairs(fast_pairs, fc);
        ref->findPairs(ref_pairs, rc);
        ASSERT_EQ(fast_pairs, ref_pairs) << "frame " << frame;
        ASSERT_EQ(fast->validate(), "") << "frame " << frame;
        ASSERT_TRUE(std::is_sorted(fast_pairs.begin(), fast_pairs.end()));
        for (const ProxyPair& p : fast_pairs) ASSERT_LT(p.a, p.b);
        total_pairs += static_cast<std::int64_t>(fast_pairs.size());
        frames_with_pairs += !fast_pairs.empty();
    }
    // The scene must exercise the broad phase: pairs appear, and not on every frame the same.
    EXPECT_GT(total_pairs, 0);
    EXPECT_GT(frames_with_pairs, 0);
}

class BroadPhaseDifferential : public ::testing::TestWithParam<Layout> {};

TEST_P(BroadPhaseDifferential, EveryBroadPhaseEqualsItsReferenceOnEveryFrame) {
    for (const BroadPhaseEntry& entry : testedBroadPhases()) {
        expectEqualsReference(entry, GetParam(), 120, 150, 42);
    }
}

INSTANTIATE_TEST_SUITE_P(Layouts, BroadPhaseDifferential,
                         ::testing::Values(Layout::Uniform, Layout::Clustered, Layout::MixedSizes,
                                           Layout::Coincident, Layout::FarFromOrigin,
                                           Layout::Lattice, Layout::ZeroSize),
                         [](const auto& param_info) {
                             std::string s = layoutName(param_info.param);
                             std::erase(s, '-');
                             return s;
                         });

// The differential scenes above insert or remove proxies on almost every frame. Here the
// membership stays fixed for long runs, so state kept between frames (SAP's sorted endpoint
// lists) and orders that only a float key decides (hgrid sorts by float(min x), then fixes its
// columns) are exercised: coherent motion, then frames where every box jumps, then all boxes on
// a few min-x values (exact ties), then 1e-3 boxes within 0.01 of (1e6, 1e6, 1e6), where
// float(min x) ties for most of them, then coherent motion again.
TEST(BroadPhaseDifferential, FixedMembershipThroughJumpsTiesAndFloatTies) {
    constexpr int kBoxes = 400;
    for (const BroadPhaseEntry& entry : testedBroadPhases()) {
        SCOPED_TRACE(std::string(entry.name));
        const BroadPhaseEntry* ref_entry = findBroadPhase(entry.reference);
        ASSERT_NE(ref_entry, nullptr);
        std::unique_ptr<BroadPhase> fast = entry.create();
        std::unique_ptr<BroadPhase> ref = ref_entry->create();
        Rng rng(7);
        std::vector<MovingBox> boxes = makeScene(Layout::Uniform, kBoxes, rng);
        for (int i = 0; i < kBoxes; ++i) {
            fast->insert(i, boxes[i].volumes());
            ref->insert(i, boxes[i].volumes());
        }
        std::vector<ProxyPair> fast_pairs, ref_pairs;
        std::int64_t total_pairs = 0;
        for (int frame = 0; frame < 110; ++frame) {
            const int phase = frame / 20;  // 0 coherent, 1 jumps, 2 ties, 3 far, 4-5 coherent
            if (phase == 3) {
                for (MovingBox& b : boxes) {
                    // Half the frames within 0.002: some columns hold ~100 float-tied boxes.
                    const Real spread = frame < 70 ? Real(0.01) : Real(0.002);
                    b.center = Vec3::Constant(Real(1e6)) + rng.vec(-spread, spread);
                    b.half_extents = rng.vec(Real(1e-4), Real(1e-3));
                }
            } else if (frame == 80) {
                boxes = makeScene(Layout::Uniform, kBoxes, rng);  // back near the origin
            } else if (phase == 1) {
                for (MovingBox& b : boxes) b.center = rng.vec(-10, 10);
            } else if (phase == 2) {
                for (MovingBox& b : boxes) {  // min x = an integer, exactly
                    b.half_extents = Vec3::Constant(Real(0.5));
                    b.center.x() = Real(rng.integer(-4, 4)) + Real(0.5);
                    b.orientation = Quat::Identity();
                }
            } else if (frame > 0) {
                advance(boxes, Layout::Uniform);
            }
            for (int i = 0; i < kBoxes; ++i) {
                fast->move(i, boxes[i].volumes());
                ref->move(i, boxes[i].volumes());
            }
            BroadPhaseCounters fc, rc;
            fast->findPairs(fast_pairs, fc);
            ref->findPairs(ref_pairs, rc);
            ASSERT_EQ(fast_pairs, ref_pairs) << "frame " << frame;
            ASSERT_EQ(fast->validate(), "") << "frame " << frame;
            total_pairs += static_cast<std::int64_t>(ref_pairs.size());
        }
        EXPECT_GT(total_pairs, 110 * kBoxes / 4);  // the scene is dense enough to test something
    }
}

// hgrid2 splits the work between two threads only from HierarchicalGrid's 4096 proxies on, so
// the scenes above (120 and 400 boxes) run it on one. Here it runs both lanes: 5000 boxes,
// with removals and re-insertions, against brute force on every frame.
TEST(BroadPhaseDifferential, TwoThreadHgridEqualsItsReferenceAboveItsThreshold) {
    const BroadPhaseEntry* entry = findBroadPhase("hgrid2");
    ASSERT_NE(entry, nullptr);
    EXPECT_EQ(entry->threads, 2);
    for (const Layout layout : {Layout::Uniform, Layout::MixedSizes, Layout::FarFromOrigin}) {
        expectEqualsReference(*entry, layout, 5000, 4, 11);
    }
}

// hgrid plans its levels both ways (one level, or levels 8x apart) and keeps the cheaper
// estimate. A few huge boxes among many small ones is the case the hierarchy exists for: in one
// level, columns as wide as the huge boxes would make every small box meet hundreds of others
// in x. The counted volume tests (not time) must stay near linear, and the pairs exact.
TEST(BroadPhaseDifferential, HierarchicalGridKeepsFewHugeAmongManySmallNearLinear) {
    Rng rng(5);
    constexpr int kSmall = 4000;
    constexpr int kHuge = 12;
    for (const char* name : {"hgrid", "hgrid2"}) {
        SCOPED_TRACE(name);
        std::unique_ptr<BroadPhase> fast = findBroadPhase(name)->create();
        std::unique_ptr<BroadPhase> ref = findBroadPhase("brute")->create();
        for (int i = 0; i < kSmall + kHuge; ++i) {
            const Real half = i < kHuge ? Real(60) : Real(0.5);
            const Vec3 c = rng.vec(0, 30);
            ProxyVolumes v;
            v.aabb = Aabb{c - Vec3::Constant(half), c + Vec3::Constant(half)};
            fast->insert(i, v);
            ref->insert(i, v);
        }
        std::vector<ProxyPair> fast_pairs, ref_pairs;
        BroadPhaseCounters fc, rc;
        fast->findPairs(fast_pairs, fc);
        ref->findPairs(ref_pairs, rc);
        ASSERT_EQ(fast_pairs, ref_pairs);
        EXPECT_EQ(fast->validate(), "");
        // Pairs: every huge box with every box (kHuge * 4000), plus the small boxes' own.
        EXPECT_GT(fast_pairs.size(), std::size_t(kHuge * kSmall));
        // One level (columns 120 wide, one column) would test about 4000 * 4000 / 2 small-small
        // candidates in x alone; the levels test the huge boxes against everything plus a few
        // per small box.
        EXPECT_LT(fc.volume_tests, 3 * kHuge * (kSmall + kHuge) + 64 * kSmall) << fc.volume_tests;

        // Sizes spread evenly over four decades instead (one level is planned there): the
        // pairs are still exact, frame after frame.
        std::unique_ptr<BroadPhase> spread = findBroadPhase(name)->create();
        std::unique_ptr<BroadPhase> spread_ref = findBroadPhase("brute")->create();
        std::vector<Vec3> centre(kSmall), half(kSmall);
        for (int i = 0; i < kSmall; ++i) {
            centre[i] = rng.vec(0, 60);
            half[i] = Vec3::Constant(Real(0.01) * std::pow(Real(10), rng.uniform(0, 4)));
        }
        for (int frame = 0; frame < 3; ++frame) {
            for (int i = 0; i < kSmall; ++i) {
                centre[i] += Vec3::Constant(Real(0.05));
                ProxyVolumes v;
                v.aabb = Aabb{centre[i] - half[i], centre[i] + half[i]};
                if (frame == 0) {
                    spread->insert(i, v);
                    spread_ref->insert(i, v);
                } else {
                    spread->move(i, v);
                    spread_ref->move(i, v);
                }
            }
            spread->findPairs(fast_pairs, fc);
            spread_ref->findPairs(ref_pairs, rc);
            ASSERT_EQ(fast_pairs, ref_pairs) << "frame " << frame;
            EXPECT_EQ(spread->validate(), "");
            EXPECT_GT(ref_pairs.size(), std::size_t(kSmall));
        }
    }
}

// Terdiman's BoxPruning scene ("Box pruning revisited", 2017: 10,000 boxes, integer centres in
// +-2048, half extents 0-127 from MSVC's rand(), seed 42): the largest extent of all but 17 boxes
// is over 32, an eighth of the largest, so those 17 would make a level of their own and visit
// the one holding the rest as guests, whose columns would then be swept with a list of their
// own members. That pass costs more than the hierarchy saves: one level is planned, and the
// legend says why. hgrid-levels keeps Mirtich's hierarchy (cells halving per level) on the same
// boxes, with the same pairs.
TEST(BroadPhaseDifferential, HierarchicalGridPlansOneLevelForTerdimansScene) {
    struct LevelCount : DebugDraw {
        void drawLine(const Vec3&, const Vec3&, const Color&) override {}
        void drawAabb(const Aabb&, const Color&) override {}
        void legend(std::string_view label, const Color&) override {
            if (label.starts_with("hgrid level ")) {
                ++levels;
            } else {
                notes.emplace_back(label);
            }
        }
        int levels = 0;
        std::vector<std::string> notes;
    };
    std::uint32_t state = 42;
    const auto msvcRand = [&state] {
        state = state * 214013u + 2531011u;
        return int((state >> 16) & 0x7fffu);
    };
    std::unique_ptr<BroadPhase> grid = findBroadPhase("hgrid")->create();
    std::unique_ptr<BroadPhase> ref = findBroadPhase("brute")->create();
    std::vector<ProxyVolumes> grid_volumes;
    for (int i = 0; i < 10000; ++i) {
        Vec3 c, e;
        for (int k = 0; k < 3; ++k) c[k] = Real((msvcRand() & 4095) - 2048);
        for (int k = 0; k < 3; ++k) e[k] = Real(msvcRand() & 127);
        ProxyVolumes v;
        v.aabb = Aabb{c - e, c + e};
        grid->insert(i, v);
        ref->insert(i, v);
        grid_volumes.push_back(v);
    }
    std::vector<ProxyPair> pairs, ref_pairs;
    BroadPhaseCounters counters, ref_counters;
    grid->findPairs(pairs, counters);
    ref->findPairs(ref_pairs, ref_counters);
    EXPECT_EQ(pairs.size(), 11811u);  // Terdiman's count for this scene
    ASSERT_EQ(pairs, ref_pairs);
    EXPECT_EQ(grid->validate(), "");
    LevelCount draw;
    grid->draw(draw, Aabb{Vec3::Constant(-2175), Vec3::Constant(2175)});
    EXPECT_EQ(draw.levels, 1);
    ASSERT_EQ(draw.notes.size(), 1u);
    EXPECT_TRUE(draw.notes[0].starts_with("one level, not 2 by size: est. ")) << draw.notes[0];

    std::unique_ptr<BroadPhase> levels = findBroadPhase("hgrid-levels")->create();
    for (int i = 0; i < 10000; ++i) levels->insert(i, grid_volumes[std::size_t(i)]);
    std::vector<ProxyPair> level_pairs;
    BroadPhaseCounters level_counters;
    levels->findPairs(level_pairs, level_counters);
    EXPECT_EQ(level_pairs, ref_pairs);
    EXPECT_EQ(levels->validate(), "");
    LevelCount level_draw;
    levels->draw(level_draw, Aabb{Vec3::Constant(-2175), Vec3::Constant(2175)});
    EXPECT_GE(level_draw.levels, 5);  // extents 2 to 254: cells halving from 254
    EXPECT_TRUE(level_draw.notes.empty());
}

TEST(BroadPhaseDifferential, LatticeSceneReallyTouches) {
    // Guards the adversarial scene itself: exact face/edge/corner contacts must occur, else the
    // touching cases above test nothing.
    Rng rng(42);
    std::vector<MovingBox> boxes = makeScene(Layout::Lattice, 120, rng);
    int exact_touches = 0;
    for (int frame = 0; frame < 20; ++frame) {
        advance(boxes, Layout::Lattice);
        for (std::size_t i = 0; i < boxes.size(); ++i) {
            for (std::size_t j = i + 1; j < boxes.size(); ++j) {
                const Aabb a = boxes[i].volumes().aabb;
                const Aabb b = boxes[j].volumes().aabb;
                if (!a.overlaps(b)) continue;
                for (int k = 0; k < 3; ++k) {
                    exact_touches += a.max[k] == b.min[k] || b.max[k] == a.min[k];
                }
            }
        }
    }
    EXPECT_GT(exact_touches, 50);
}

// Regression: `sphere` pruned its x sweep with cx +- r, which rounds differently from the
// sphere test |c_a - c_b|^2 <= (r_a + r_b)^2; about 2% of sphere pairs touching along x were
// reported by sphere-brute and not by sphere. Set-up, per pair, at every magnitude:
//
//      (  A  )(   B   )      centres on one x line, c_b.x = c_a.x + r_a + r_b (rounded)
//
TEST(BroadPhaseDifferential, SpheresTouchingAlongXEqualTheirReference) {
    const BroadPhaseEntry* entry = findBroadPhase("sphere");
    ASSERT_NE(entry, nullptr);
    const BroadPhaseEntry* ref_entry = findBroadPhase(entry->reference);
    ASSERT_NE(ref_entry, nullptr);
    Rng rng(7);
    int overlapping = 0;
    int apart = 0;
    for (const Real offset : {Real(0), Real(1e3), Real(1e6)}) {
        for (const Real scale : {Real(1e-4), Real(1), Real(1e4)}) {
            std::unique_ptr<BroadPhase> fast = entry->create();
            std::unique_ptr<BroadPhase> ref = ref_entry->create();
            for (int k = 0; k < 100; ++k) {
                const Real ra = scale * rng.uniform(0.05, 1.0);
                const Real rb = scale * rng.uniform(0.05, 1.0);
                const Vec3 ca(offset + scale * rng.uniform(-1, 1), 10 * scale * k, 0);
                const Vec3 cb(ca.x() + (ra + rb), ca.y(), ca.z());
                const BoundingSphere sa{ca, ra};
                const BoundingSphere sb{cb, rb};
                (sa.overlaps(sb) ? overlapping : apart) += 1;
                for (const auto& [id, s] : {std::pair{2 * k, sa}, std::pair{2 * k + 1, sb}}) {
                    const Vec3 e = Vec3::Constant(s.radius);
                    const ProxyVolumes v{Aabb{s.center - e, s.center + e}, s,
                                         Obb{s.center, Mat3::Identity(), e}};
                    fast->insert(static_cast<ProxyId>(id), v);
                    ref->insert(static_cast<ProxyId>(id), v);
                }
            }
            std::vector<ProxyPair> fast_pairs;
            std::vector<ProxyPair> ref_pairs;
            BroadPhaseCounters fc;
            BroadPhaseCounters rc;
            fast->findPairs(fast_pairs, fc);
            ref->findPairs(ref_pairs, rc);
            EXPECT_EQ(fast_pairs, ref_pairs) << "offset " << offset << " scale " << scale;
        }
    }
    // Rounding must put pairs on both sides of the touching test, or nothing was probed.
    EXPECT_GT(overlapping, 300);
    EXPECT_GT(apart, 0);
}

// Extreme extents. Regression: `grid` never returned when a box's extent was infinite (its
// cell-size doubling loop could not fit the grid), and `hash` multiplied cell counts in int64
// with a half-extent-1e4 box beside radius-1e-4 spheres (UBSan: signed overflow). Volumes are
// finite by contract (World::step stops on a non-finite state before any volume reaches a broad
// phase), and every broad phase must equal its reference with finite but huge (1e300) and tiny
// boxes side by side:
//
//         [-1e300 ................. 1e300]       box 0
//      [-1e4 ... 1e4]                            box 1
//        .  .  .  .                              boxes 2.. (1e-4), a row along x
//
// The cell-based broad phases must also return, with every pair, when a box is infinite in x.
std::vector<ProxyVolumes> extremeBoxes(bool with_infinite) {
    auto box = [](const Vec3& lo, const Vec3& hi) {
        const Vec3 c = (lo + hi) / 2;
        const Vec3 h = (hi - lo) / 2;
        return ProxyVolumes{Aabb{lo, hi}, BoundingSphere{c, h.norm()},
                            Obb{c, Mat3::Identity(), h}};
    };
    std::vector<ProxyVolumes> volumes{
        box(Vec3::Constant(Real(-1e300)), Vec3::Constant(Real(1e300))),
        box(Vec3::Constant(Real(-1e4)), Vec3::Constant(Real(1e4))),
    };
    for (int i = 0; i < 40; ++i) {
        const Vec3 c(Real(i) * Real(1.5e-4), 0, 0);
        volumes.push_back(box(c - Vec3::Constant(Real(1e-4)), c + Vec3::Constant(Real(1e-4))));
    }
    if (with_infinite) {
        const Real inf = std::numeric_limits<Real>::infinity();
        // Its centre is 0 (the midpoint formula would give inf - inf = NaN).
        volumes.push_back(ProxyVolumes{Aabb{Vec3(-inf, -1, -1), Vec3(inf, 1, 1)},
                                       BoundingSphere{Vec3::Zero(), inf},
                                       Obb{Vec3::Zero(), Mat3::Identity(), Vec3(inf, 1, 1)}});
    }
    return volumes;
}

std::vector<ProxyPair> pairsOf(const BroadPhaseEntry& entry,
                               const std::vector<ProxyVolumes>& volumes) {
    std::unique_ptr<BroadPhase> bp = entry.create();
    for (std::size_t i = 0; i < volumes.size(); ++i) bp->insert(static_cast<ProxyId>(i), volumes[i]);
    std::vector<ProxyPair> pairs;
    BroadPhaseCounters counters;
    bp->findPairs(pairs, counters);
    return pairs;
}

TEST(BroadPhaseDifferential, HugeAndTinyExtentsEqualTheReference) {
    const std::vector<ProxyVolumes> volumes = extremeBoxes(false);
    for (const BroadPhaseEntry& entry : testedBroadPhases()) {
        SCOPED_TRACE(std::string(entry.name));
        const std::vector<ProxyPair> ref = pairsOf(*findBroadPhase(entry.reference), volumes);
        EXPECT_EQ(pairsOf(entry, volumes), ref);
        // The two big boxes overlap every box, and neighbours in the row (1.5e-4 apart) overlap:
        // at least 41 + 40 + 39 pairs (bounding spheres, 1.7e-4 in radius, add second
        // neighbours).
        EXPECT_GE(ref.size(), 41u + 40 + 39) << "the reference itself";
    }
}

TEST(BroadPhaseDifferential, CellBroadPhasesReturnOnInfiniteExtents) {
    const std::vector<ProxyVolumes> volumes = extremeBoxes(true);
    const std::vector<ProxyPair> ref = pairsOf(*findBroadPhase("brute"), volumes);
    EXPECT_EQ(ref.size(), 41u + 40 + 39 + 42);
    for (const char* name : {"grid", "hash", "hgrid", "hgrid2", "sap", "sap1", "sap-packed"}) {
        SCOPED_TRACE(name);
        EXPECT_EQ(pairsOf(*findBroadPhase(name), volumes), ref);
    }
}

// Float-rounding edges: sap-packed sweeps bounds rounded outward to float and confirms on the
// doubles. Along each axis a row of boxes at coordinates float cannot hold (multiples of 0.1),
// each starting exactly where the previous one ends (touching: a pair) or one double ulp after
// it (apart: no pair, though both bounds round to the same float):
//
//      [0.1 ...... 0.2][0.2 ...... 0.3] [0.3+ulp ... 0.4][0.4 ...
//             touching              apart by one ulp
//
// then, near (1e7, 1e7, 1e7) where a float step is 1, boxes of half size 1e-6 every 1.5e-6
// along x: neighbours overlap, second neighbours do not, and every float box is the same.
std::vector<ProxyVolumes> floatEdgeBoxes() {
    auto box = [](const Vec3& lo, const Vec3& hi) {
        const Vec3 c = (lo + hi) / 2;
        const Vec3 h = (hi - lo) / 2;
        return ProxyVolumes{Aabb{lo, hi}, BoundingSphere{c, h.norm()},
                            Obb{c, Mat3::Identity(), h}};
    };
    std::vector<ProxyVolumes> volumes;
    for (int axis = 0; axis < 3; ++axis) {
        Vec3 offset = Vec3::Constant(Real(100 * (axis + 1)));
        Real lo = Real(0.1);
        for (int i = 0; i < 12; ++i) {
            const Real hi = lo + Real(0.1);
            Vec3 a = offset;
            Vec3 b = offset + Vec3::Constant(Real(0.1));
            a[axis] = lo;
            b[axis] = hi;
            volumes.push_back(box(a, b));
            lo = i % 2 == 0 ? hi : std::nextafter(hi, Real(1e9));
        }
    }
    for (int i = 0; i < 20; ++i) {
        const Vec3 c = Vec3::Constant(Real(1e7)) + Vec3(Real(i) * Real(1.5e-6), 0, 0);
        volumes.push_back(box(c - Vec3::Constant(Real(1e-6)), c + Vec3::Constant(Real(1e-6))));
    }
    return volumes;
}

TEST(BroadPhaseDifferential, FloatRoundingEdgesEqualTheReference) {
    const std::vector<ProxyVolumes> volumes = floatEdgeBoxes();
    // The premise: an apart pair's bounds round to the same float, so only the double test
    // can separate them.
    const Real touch = volumes[0].aabb.max.x();
    const Real apart = volumes[2].aabb.min.x();
    ASSERT_LT(volumes[1].aabb.max.x(), apart);
    ASSERT_EQ(static_cast<float>(volumes[1].aabb.max.x()), static_cast<float>(apart));
    ASSERT_EQ(touch, volumes[1].aabb.min.x());
    const std::vector<ProxyPair> ref = pairsOf(*findBroadPhase("brute"), volumes);
    // Per axis 6 touching neighbours and 5 apart ones; 19 overlapping neighbours near 1e7.
    ASSERT_EQ(ref.size(), 3u * 6 + 19);
    for (const BroadPhaseEntry& entry : testedBroadPhases()) {
        if (entry.volume != collision::VolumeKind::Aabb) continue;
        SCOPED_TRACE(std::string(entry.name));
        EXPECT_EQ(pairsOf(entry, volumes), ref);
    }
}

TEST(BroadPhaseRegistry, NamesAreUniqueAndReferencesExist) {
    std::set<std::string_view> names;
    for (const BroadPhaseEntry& e : broadPhaseRegistry()) {
        EXPECT_TRUE(names.insert(e.name).second) << e.name;
        EXPECT_NE(findBroadPhase(e.reference), nullptr) << e.name;
    }
    for (const BroadPhaseEntry& e : testedBroadPhases()) EXPECT_EQ(e.create()->name(), e.name);
    EXPECT_EQ(findBroadPhase("no-such"), nullptr);
    EXPECT_NE(broadPhaseNames().find("sap"), std::string::npos);
}

// Without a rendering context (this binary links no renderer) `cullide` is not made: the error
// says what it needs, so a scene asking for it fails with that message.
TEST(BroadPhaseRegistry, CullideWithoutARenderingContextSaysWhatItNeeds) {
    if (hasVisibilityOracleFactory()) GTEST_SKIP() << "an oracle is installed here";
    const BroadPhaseEntry* entry = findBroadPhase("cullide");
    ASSERT_NE(entry, nullptr);
    EXPECT_TRUE(entry->needs_render_context);
    try {
        entry->create();
        ADD_FAILURE() << "created without an oracle";
    } catch (const BroadPhaseUnavailable& e) {
        EXPECT_NE(std::string(e.what()).find("needs the render module's OSMesa context"),
                  std::string::npos)
            << e.what();
    }
}

// PairOrder::Found skips the sort: the same pairs as brute force, each (a, b) with a < b, no
// duplicates, in the sweep's order (not sorted on some frame: else the choice would be moot),
// and the same list from two grids given the same calls.
TEST(HierarchicalGrid, PairsInFoundOrderAreTheSortedSetUnsorted) {
    using Order = HierarchicalGrid::PairOrder;
    HierarchicalGrid found(false, Order::Found), again(false, Order::Found);
    std::unique_ptr<BroadPhase> ref = findBroadPhase("brute")->create();
    Rng rng(13);
    std::vector<MovingBox> boxes = makeScene(Layout::MixedSizes, 600, rng);
    for (int i = 0; i < 600; ++i) {
        found.insert(i, boxes[i].volumes());
        again.insert(i, boxes[i].volumes());
        ref->insert(i, boxes[i].volumes());
    }
    int unsorted_frames = 0;
    for (int frame = 0; frame < 8; ++frame) {
        if (frame > 0) advance(boxes, Layout::MixedSizes);
        for (int i = 0; i < 600; ++i) {
            found.move(i, boxes[i].volumes());
            again.move(i, boxes[i].volumes());
            ref->move(i, boxes[i].volumes());
        }
        std::vector<ProxyPair> pairs, pairs_again, ref_pairs;
        BroadPhaseCounters c;
        found.findPairs(pairs, c);
        again.findPairs(pairs_again, c);
        ref->findPairs(ref_pairs, c);
        EXPECT_EQ(pairs, pairs_again) << "frame " << frame;
        for (const ProxyPair& p : pairs) ASSERT_LT(p.a, p.b);
        unsorted_frames += !std::is_sorted(pairs.begin(), pairs.end());
        std::sort(pairs.begin(), pairs.end());
        ASSERT_EQ(pairs, ref_pairs) << "frame " << frame;  // also: no duplicates
        ASSERT_GT(ref_pairs.size(), 100u);
    }
    EXPECT_GT(unsorted_frames, 0);
}
TEST(SweepAndPrune, CoherentMotionCostsFewSwaps) {
    // Behaviour, not speed: after the first frame, tiny motions reorder few endpoints, so the
    // insertion sort does far fewer swaps than a full re-sort would compare.
    std::unique_ptr<BroadPhase> sap = findBroadPhase("sap")->create();
    Rng rng(9);
    std::vector<MovingBox> boxes = makeScene(Layout::Uniform, 500, rng);
    for (int i = 0; i < 500; ++i) sap->insert(i, boxes[i].volumes());
    std::vector<ProxyPair> pairs;
    BroadPhaseCounters first;
    sap->findPairs(pairs, first);
    for (MovingBox& b : boxes) {
        b.velocity *= 0.01;
        b.spin = Quat::Identity();
    }
    advance(boxes, Layout::Uniform);
    for (int i = 0; i < 500; ++i) sap->move(i, boxes[i].volumes());
    BroadPhaseCounters second;
    sap->findPairs(pairs, second);
    EXPECT_LT(second.swaps, 500);
    EXPECT_EQ(second.volumes_updated, 500);
}

}  // namespace
}  // namespace collision
