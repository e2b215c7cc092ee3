// sap-packed's coherent path beside brute force: the pairs of overlapping fat boxes kept between
// frames, fat boxes led by the motion, and the look-ups of the boxes that left theirs, on
// jittering, steadily moving and mixed-size scenes; and its loose output (the candidates
// themselves) beside the exact one. (The registry's differential tests in
// broad_phase_test.cpp run it on random and adversarial scenes like every other broad phase.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "broadphase/float_bounds.h"
#include "broadphase/sap_packed.h"
#include "collision/broadphase/broad_phase.h"
#include "collision/broadphase/loose_broad_phase.h"
#include "test_random.h"

namespace collision {
namespace {

using cdlab_test::Rng;


// sap-packed beside brute force on boxes given by their centres and half extents (read at each
// call, so a test moves a box by changing its centre): every findPairs of the two must agree,
// and sap-packed's invariants must hold.
class PackedBesideBrute {
public:
    PackedBesideBrute(const std::vector<Vec3>& centre, const std::vector<Vec3>& half)
        : centre_(centre),
          half_(half),
          fast_(findBroadPhase("sap-packed")->create()),
          ref_(findBroadPhase("brute")->create()) {
        for (int i = 0; i < count(); ++i) {
            fast_->insert(i, volumes(i));
            ref_->insert(i, volumes(i));
        }
    }
    /// Moves every box to its present centre (unless `move` is false: the first frame), finds
    /// the pairs of both and returns sap-packed's counters; mismatch() says what disagreed.
    BroadPhaseCounters findPairs(bool move = true) {
        if (move) {
            for (int i = 0; i < count(); ++i) {
                fast_->move(i, volumes(i));
                ref_->move(i, volumes(i));
            }
        }
        BroadPhaseCounters fc, rc;
        fast_->findPairs(fast_pairs_, fc);
        ref_->findPairs(ref_pairs_, rc);
        mismatch_.clear();
        if (fast_pairs_ != ref_pairs_) {
            mismatch_ = "sap-packed found " + std::to_string(fast_pairs_.size()) +
                        " pairs, brute force " + std::to_string(ref_pairs_.size());
        } else {
            mismatch_ = fast_->validate();
        }
        return fc;
    }
    /// Empty when the last findPairs agreed with brute force and sap-packed was valid.
    const std::string& mismatch() const { return mismatch_; }
    /// Brute force's pairs at the last findPairs.
    const std::vector<ProxyPair>& pairs() const { return ref_pairs_; }

private:
    int count() const { return static_cast<int>(centre_.size()); }
    ProxyVolumes volumes(int i) const {
        const Vec3& c = centre_[static_cast<std::size_t>(i)];
        const Vec3& h = half_[static_cast<std::size_t>(i)];
        return ProxyVolumes{Aabb{c - h, c + h}, BoundingSphere{c, h.norm()},
                            Obb{c, Mat3::Identity(), h}};
    }

    const std::vector<Vec3>& centre_;
    const std::vector<Vec3>& half_;
    std::unique_ptr<BroadPhase> fast_;
    std::unique_ptr<BroadPhase> ref_;
    std::vector<ProxyPair> fast_pairs_, ref_pairs_;
    std::string mismatch_;
};

// sap-packed keeps the pairs of overlapping fat boxes between frames and re-queries only the
// boxes that left theirs. A jittering scene (Terdiman's BoxPruning, scaled down: integer centres
// moving by -1, 0 or +1 per axis per frame, integer half sizes, so boxes touch exactly and
// often) takes that path on most frames; every frame must still equal brute force, and the
// coherent frames must test far fewer volumes than the full sweep of the first frame.
TEST(PackedSweepAndPrune, JitteringBoxesEqualBruteForceWhileFatBoxesAreReused) {
    constexpr int kBoxes = 1500;
    Rng rng(17);
    std::vector<Vec3> centre(kBoxes);
    std::vector<Vec3> half(kBoxes);
    for (int i = 0; i < kBoxes; ++i) {
        centre[i] = Vec3(rng.integer(-300, 300), rng.integer(-300, 300), rng.integer(-300, 300));
        half[i] = Vec3(rng.integer(0, 20), rng.integer(0, 20), rng.integer(0, 20));
    }
    PackedBesideBrute check(centre, half);
    const BroadPhaseCounters first = check.findPairs(false);
    ASSERT_EQ(check.mismatch(), "");
    ASSERT_GT(check.pairs().size(), 300u);
    int cheap_frames = 0;
    for (int frame = 1; frame <= 200; ++frame) {
        for (int i = 0; i < kBoxes; ++i) {
            for (int k = 0; k < 3; ++k) centre[i][k] += rng.integer(-1, 1);
        }
        const BroadPhaseCounters fc = check.findPairs();
        ASSERT_EQ(check.mismatch(), "") << "frame " << frame;
        cheap_frames += fc.volume_tests < first.volume_tests / 4;
    }
    EXPECT_GT(cheap_frames, 150);
}

// sap-packed's steady state under steady motion: boxes of sizes 1:100 (log-uniform) and a few
// huge ones (spanning many y bands, swept apart as "big") drift 1-2 % of their size per frame,
// so every frame some boxes leave their fat box. Those are looked up in the sorted
// bands, and boxes re-fattened since (stale) in a list of their own, sorted on min x:
//
//      bands (as last dealt)                 stale (current fat boxes)
//      y3 |  [==]   [=]     [====]           [=]  [==]       [=]
//      y2 |    [=]    [==] [=]                  ^ escaped this frame: looked up in both
//      y1 | [====]  [=]  [=]
//
// Every frame must equal brute force.
TEST(PackedSweepAndPrune, SteadilyMovingMixedSizesEqualBruteForceOnTheIncrementalPath) {
    constexpr int kBoxes = 2000;
    constexpr int kHuge = 6;
    constexpr Real kSide = 60;
    Rng rng(23);
    std::vector<Vec3> centre(kBoxes), half(kBoxes), velocity(kBoxes);
    for (int i = 0; i < kBoxes; ++i) {
        const Real scale =
            i < kHuge ? Real(15) : Real(0.05) * std::pow(Real(100), rng.uniform(0, 1));
        half[i] = scale * rng.vec(Real(0.8), Real(1.2));
        centre[i] = rng.vec(0, kSide);
        velocity[i] = rng.vec(-1, 1).normalized() * (2 * scale * rng.uniform(0.01, 0.02));
    }
    PackedBesideBrute check(centre, half);
    check.findPairs(false);
    ASSERT_EQ(check.mismatch(), "");
    ASSERT_GT(check.pairs().size(), std::size_t(kBoxes));
    constexpr int kFrames = 160;
    std::int64_t changed = 0;
    for (int frame = 1; frame <= kFrames; ++frame) {
        for (int i = 0; i < kBoxes; ++i) {
            centre[i] += velocity[i];
            for (int k = 0; k < 3; ++k) {
                if (centre[i][k] < 0 || centre[i][k] > kSide) velocity[i][k] = -velocity[i][k];
            }
        }
        const std::vector<ProxyPair> before = check.pairs();
        check.findPairs();
        ASSERT_EQ(check.mismatch(), "") << "frame " << frame;
        changed += check.pairs() != before;
    }
    EXPECT_GT(changed, kFrames / 2);  // the pair set really moves
}

// sap-packed looks an escaped box up in each band it meets from the first box whose running
// maximum of max x reaches its min x (binary search). A few boxes much wider in x than the rest
// (rods) set that maximum: an escaped small box must still find a rod whose min x lies far
// behind its own, and a rod that escaped every box along its length:
//
//      band |  [=============== rod ===============]       [========= rod =========]
//           |    [.] [.]  [.]        [.]  [.]  [.]-->  [.]   [.]    [.]   [.]
//                                              ^ escaped: its min x is far past the rod's
//
// Every frame must equal brute force.
TEST(PackedSweepAndPrune, EscapedBoxesFindRodsFarBehindInX) {
    constexpr int kBoxes = 1500;
    constexpr int kRods = 40;
    constexpr Real kSide = 50;
    Rng rng(41);
    std::vector<Vec3> centre(kBoxes), half(kBoxes), velocity(kBoxes);
    for (int i = 0; i < kBoxes; ++i) {
        const bool rod = i < kRods;
        half[i] =
            rod ? Vec3(rng.uniform(8, 20), Real(0.4), Real(0.4)) : rng.vec(Real(0.3), Real(0.6));
        centre[i] = rng.vec(0, kSide);
        velocity[i] = rng.vec(-1, 1).normalized() * Real(rod ? 0.01 : 0.03);
    }
    PackedBesideBrute check(centre, half);
    const BroadPhaseCounters first = check.findPairs(false);
    ASSERT_EQ(check.mismatch(), "");
    constexpr int kFrames = 200;
    int cheap_frames = 0;
    std::int64_t rod_pairs = 0;
    for (int frame = 1; frame <= kFrames; ++frame) {
        for (int i = 0; i < kBoxes; ++i) {
            centre[i] += velocity[i];
            for (int k = 0; k < 3; ++k) {
                if (centre[i][k] < 0 || centre[i][k] > kSide) velocity[i][k] = -velocity[i][k];
            }
        }
        const BroadPhaseCounters fc = check.findPairs();
        ASSERT_EQ(check.mismatch(), "") << "frame " << frame;
        cheap_frames += fc.volume_tests < first.volume_tests / 4;
        for (const ProxyPair& p : check.pairs()) rod_pairs += p.a < kRods && p.b >= kRods;
    }
    EXPECT_GT(cheap_frames, kFrames / 4);  // the escape look-ups, not full sweeps
    EXPECT_GT(rod_pairs, kFrames * 10);    // the rods really touch the small boxes
}

// sap-packed leads a moving box's fat box in the direction it moves (Box2D's predicted
// displacement), so a box moving steadily leaves its fat box only once in many frames:
//
//      +-------------------------+  fat box: a thin margin behind, a long lead ahead
//      | [box] --> v             |
//      +-------------------------+
//
// One box crosses a field of still ones with a velocity of mixed signs; a frame where no box
// left its fat box makes no volume test. Every frame must still equal brute force.
TEST(PackedSweepAndPrune, SteadilyMovingBoxLeavesItsLeadingFatBoxRarely) {
    constexpr int kStill = 400;
    constexpr Real kSide = 40;
    Rng rng(31);
    std::vector<Vec3> centre(kStill + 1), half(kStill + 1);
    for (int i = 0; i < kStill; ++i) {
        centre[i] = rng.vec(0, kSide);
        half[i] = rng.vec(Real(0.5), Real(1.5));
    }
    centre[kStill] = Vec3(kSide - 2, 2, kSide - 2);
    half[kStill] = Vec3(1, 1, 1);
    const Vec3 velocity(-0.12, 0.1, -0.08);
    PackedBesideBrute check(centre, half);
    int querying_frames = 0;
    constexpr int kFrames = 300;
    for (int frame = 0; frame <= kFrames; ++frame) {
        if (frame > 0) centre[kStill] += velocity;
        const BroadPhaseCounters fc = check.findPairs(frame > 0);
        ASSERT_EQ(check.mismatch(), "") << "frame " << frame;
        if (frame > 10) querying_frames += fc.volume_tests > 0;
    }
    // About one frame in kLead (32) re-queries; with symmetric margins of 16 steps it would be
    // one in 16, with the lead on the wrong side nearly every frame.
    EXPECT_LE(querying_frames, (kFrames - 10) / 24);
    EXPECT_GT(querying_frames, 0);
}

// A moving scene for the loose output: boxes by centre and half extents, and how a frame moves
// them (steady velocities reflected at the walls of [lo, hi]^3, or an integer jitter).
struct MovingScene {
    std::vector<Vec3> centre, half, velocity;
    Real lo = 0, hi = 1;
    bool jitter = false;
    Real jitter_step = 1;  ///< a jittering box moves by -1, 0 or +1 of these per axis

    int size() const { return static_cast<int>(centre.size()); }
    ProxyVolumes volumes(int i) const {
        const Vec3& c = centre[static_cast<std::size_t>(i)];
        const Vec3& h = half[static_cast<std::size_t>(i)];
        return ProxyVolumes{Aabb{c - h, c + h}, BoundingSphere{c, h.norm()},
                            Obb{c, Mat3::Identity(), h}};
    }
    void step(Rng& rng) {
        for (std::size_t i = 0; i < centre.size(); ++i) {
            for (int k = 0; k < 3; ++k) {
                if (jitter) {
                    centre[i][k] += jitter_step * rng.integer(-1, 1);
                    continue;
                }
                centre[i][k] += velocity[i][k];
                if (centre[i][k] < lo || centre[i][k] > hi) velocity[i][k] = -velocity[i][k];
            }
        }
    }
    /// Every coordinate and motion scaled by `s` and then moved by `shift` on every axis.
    MovingScene transformed(Real s, Real shift) const {
        MovingScene out = *this;
        for (std::size_t i = 0; i < centre.size(); ++i) {
            out.centre[i] = centre[i] * s + Vec3::Constant(shift);
            out.half[i] = half[i] * s;
            out.velocity[i] = velocity[i] * s;
        }
        out.jitter_step = jitter_step * s;
        out.lo = lo * s + shift;
        out.hi = hi * s + shift;
        return out;
    }
};

// Boxes of one size class (mixed: sizes 1:100, log-uniform, and a few huge ones spanning many
// bands) moving 1-2 % of their size per frame, about 3 overlaps per box.
MovingScene steadyScene(int n, bool mixed, std::uint64_t seed) {
    Rng rng(seed);
    MovingScene scene;
    const Real side = mixed ? 45 : 14;
    scene.hi = side;
    for (int i = 0; i < n; ++i) {
        const Real scale = !mixed ? Real(0.5)
                           : i < 4 ? Real(12)
                                   : Real(0.05) * std::pow(Real(100), rng.uniform(0, 1));
        scene.half.push_back(scale * rng.vec(Real(0.8), Real(1.2)));
        scene.centre.push_back(rng.vec(0, side));
        scene.velocity.push_back(rng.vec(-1, 1).normalized() *
                                 (2 * scale * rng.uniform(0.01, 0.02)));
    }
    return scene;
}

// Terdiman's BoxPruning motion, scaled down: integer centres and half sizes moving by -1, 0 or
// +1 per axis per frame, so many boxes touch exactly (closed test: they overlap).
MovingScene touchingScene(int n, std::uint64_t seed) {
    Rng rng(seed);
    MovingScene scene;
    scene.jitter = true;
    for (int i = 0; i < n; ++i) {
        scene.centre.push_back(
            Vec3(rng.integer(-170, 170), rng.integer(-170, 170), rng.integer(-170, 170)));
        scene.half.push_back(Vec3(rng.integer(0, 20), rng.integer(0, 20), rng.integer(0, 20)));
        scene.velocity.push_back(Vec3::Zero());
    }
    return scene;
}

// One scene through sap-packed twice, exact and loose output, and brute force; every frame:
// (a) the loose pairs contain every exact pair (brute force), (b) each loose pair's fat boxes
// overlap, (c) the loose pairs filtered by the exact test are the exact output, (d) the loose
// pairs are sorted and unique. Returns what went wrong first (empty: nothing) and counts the
// frames and the loose pairs beyond the exact ones.
struct LooseRun {
    std::string failure;
    std::int64_t extra = 0;    ///< loose pairs whose AABBs do not overlap, over all frames
    std::int64_t exact = 0;    ///< exact pairs over all frames
    int coherent_frames = 0;   ///< frames with fewer volume tests than a quarter of the first's
};

LooseRun runLooseBesideExact(MovingScene scene, int frames, std::uint64_t seed) {
    Rng rng(seed);
    PackedSweepAndPrune exact;
    PackedSweepAndPrune loose(PackedSweepAndPrune::Output::Loose);
    std::unique_ptr<BroadPhase> brute = findBroadPhase("brute")->create();
    const int n = scene.size();
    for (int i = 0; i < n; ++i) {
        exact.insert(i, scene.volumes(i));
        loose.insert(i, scene.volumes(i));
        brute->insert(i, scene.volumes(i));
    }
    LooseRun run;
    std::vector<ProxyPair> exact_pairs, loose_pairs, brute_pairs, sorted, filtered;
    std::int64_t first_tests = 0;
    for (int frame = 0; frame <= frames && run.failure.empty(); ++frame) {
        if (frame > 0) {
            scene.step(rng);
            for (int i = 0; i < n; ++i) {
                exact.move(i, scene.volumes(i));
                loose.move(i, scene.volumes(i));
                brute->move(i, scene.volumes(i));
            }
        }
        BroadPhaseCounters ec, lc, bc;
        exact.findPairs(exact_pairs, ec);
        loose.findPairs(loose_pairs, lc);
        brute->findPairs(brute_pairs, bc);
        if (frame == 0) first_tests = lc.volume_tests;
        run.coherent_frames += frame > 0 && lc.volume_tests < first_tests / 4;
        // Every check runs on a failing frame, so a failure names each that failed.
        const auto fail = [&](const std::string& what) {
            run.failure += (run.failure.empty() ? "frame " + std::to_string(frame) + ": " : "; ") +
                           what;
        };
        if (exact_pairs != brute_pairs) fail("the exact output differs from brute force");
        if (const std::string v = loose.validate(); !v.empty()) fail("loose: " + v);
        // (a), on a sorted copy so that it does not lean on (d).
        sorted = loose_pairs;
        std::sort(sorted.begin(), sorted.end());
        if (!std::includes(sorted.begin(), sorted.end(), brute_pairs.begin(), brute_pairs.end())) {
            fail("(a) the loose pairs miss an exact pair");
        }
        // (b) and (c).
        filtered.clear();
        std::string not_fat;
        for (const ProxyPair& p : loose_pairs) {
            if (scene.volumes(p.a).aabb.overlaps(scene.volumes(p.b).aabb)) {
                filtered.push_back(p);
            } else {
                ++run.extra;
            }
            if (not_fat.empty() && !loose.fatBoxesOverlap(p.a, p.b)) {
                not_fat = "(b) a loose pair (" + std::to_string(p.a) + ", " +
                          std::to_string(p.b) + ") whose fat boxes do not overlap";
            }
        }
        if (!not_fat.empty()) fail(not_fat);
        if (filtered != exact_pairs) {
            fail("(c) the loose pairs filtered (" + std::to_string(filtered.size()) +
                 ") are not the exact output (" + std::to_string(exact_pairs.size()) + ")");
        }
        // (d)
        for (std::size_t k = 0; k < loose_pairs.size(); ++k) {
            const ProxyPair& p = loose_pairs[k];
            if (!(p.a < p.b) || (k > 0 && !(loose_pairs[k - 1] < p))) {
                fail("(d) the loose pairs are not sorted and unique at " + std::to_string(k));
                break;
            }
        }
        if (!run.failure.empty()) break;
        run.exact += static_cast<std::int64_t>(exact_pairs.size());
    }
    return run;
}

// The loose output on random and adversarial moving scenes. Each must exercise both outcomes
// of the exact test (pairs that overlap and loose pairs that do not) and the coherent path.
TEST(PackedSweepAndPrune, LooseOutputHoldsEveryExactPairAndOnlyFatOverlaps) {
    constexpr int kFrames = 120;
    const MovingScene uniform = steadyScene(900, false, 51);
    const MovingScene mixed = steadyScene(900, true, 52);
    struct Case {
        const char* name;
        MovingScene scene;
    };
    const Case cases[] = {
        {"uniform", uniform},
        {"mixed 1:100", mixed},
        {"touching (integer jitter)", touchingScene(900, 53)},
        // At 1e6 a float step is 1/16: the float bounds round far outward of these unit boxes.
        {"uniform far from origin", uniform.transformed(1, 1e6)},
        {"mixed far from origin", mixed.transformed(1, -3e6)},
        {"mixed huge (x 1e4)", mixed.transformed(1e4, 0)},
        {"mixed tiny (x 1e-4)", mixed.transformed(1e-4, 0)},
        {"touching tiny and far (x 1e-3, + 50)", touchingScene(900, 54).transformed(1e-3, 50)},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const LooseRun run = runLooseBesideExact(c.scene, kFrames, 61);
        ASSERT_EQ(run.failure, "");
        EXPECT_GT(run.exact, kFrames * 300);  // both outcomes of the exact test...
        EXPECT_GT(run.extra, 0);              // ...among the loose pairs
        EXPECT_GT(run.coherent_frames, kFrames / 4);
    }
}

// Inserting and removing proxies between frames rebuilds the candidates from exact boxes (no
// margins): the loose output must stay a sorted superset and filter to the exact output.
TEST(PackedSweepAndPrune, LooseOutputFollowsInsertsAndRemoves) {
    MovingScene scene = steadyScene(600, true, 71);
    Rng rng(72);
    PackedSweepAndPrune exact;
    PackedSweepAndPrune loose(PackedSweepAndPrune::Output::Loose);
    std::vector<char> present(scene.centre.size(), 0);
    std::vector<ProxyPair> exact_pairs, loose_pairs, filtered;
    BroadPhaseCounters counters;
    for (int frame = 0; frame < 60; ++frame) {
        scene.step(rng);
        for (int i = 0; i < scene.size(); ++i) {
            const bool want = (i + frame / 10) % 3 != 0;
            if (want && !present[i]) {
                exact.insert(i, scene.volumes(i));
                loose.insert(i, scene.volumes(i));
            } else if (!want && present[i]) {
                exact.remove(i);
                loose.remove(i);
            } else if (want) {
                exact.move(i, scene.volumes(i));
                loose.move(i, scene.volumes(i));
            }
            present[i] = want;
        }
        exact.findPairs(exact_pairs, counters);
        loose.findPairs(loose_pairs, counters);
        ASSERT_EQ(loose.validate(), "") << "frame " << frame;
        ASSERT_TRUE(std::is_sorted(loose_pairs.begin(), loose_pairs.end()));
        ASSERT_EQ(std::adjacent_find(loose_pairs.begin(), loose_pairs.end()), loose_pairs.end());
        filtered.clear();
        for (const ProxyPair& p : loose_pairs) {
            ASSERT_TRUE(present[p.a] && present[p.b]) << "frame " << frame;
            if (scene.volumes(p.a).aabb.overlaps(scene.volumes(p.b).aabb)) filtered.push_back(p);
        }
        ASSERT_EQ(filtered, exact_pairs) << "frame " << frame;
        ASSERT_GT(exact_pairs.size(), 100u);
    }
}

// The held list read in place (updatePairs, heldPairs: no copy, as a Bullet pair cache is read)
// is the list findPairs writes, frame after frame, through the coherent path and the full
// sweeps; and the exact mode holds the same candidates (the output mode changes only what is
// written).
TEST(PackedSweepAndPrune, LooseHeldPairsAreTheLooseOutput) {
    for (MovingScene scene : {steadyScene(700, true, 81), touchingScene(700, 82)}) {
        Rng rng(83);
        PackedSweepAndPrune written(PackedSweepAndPrune::Output::Loose);
        PackedSweepAndPrune held(PackedSweepAndPrune::Output::Loose);
        PackedSweepAndPrune exact;
        for (int i = 0; i < scene.size(); ++i) {
            written.insert(i, scene.volumes(i));
            held.insert(i, scene.volumes(i));
            exact.insert(i, scene.volumes(i));
        }
        std::vector<ProxyPair> loose_pairs, exact_pairs;
        int coherent_frames = 0;
        int looser_frames = 0;  // frames whose loose list holds more than the exact pairs
        std::int64_t first_tests = 0;
        for (int frame = 0; frame <= 80; ++frame) {
            if (frame > 0) {
                scene.step(rng);
                for (int i = 0; i < scene.size(); ++i) {
                    written.move(i, scene.volumes(i));
                    held.move(i, scene.volumes(i));
                    exact.move(i, scene.volumes(i));
                }
            }
            BroadPhaseCounters wc, hc, ec;
            written.findPairs(loose_pairs, wc);
            held.updatePairs(hc);
            exact.findPairs(exact_pairs, ec);
            const std::span<const ProxyPair> in_place = held.heldPairs();
            ASSERT_TRUE(std::equal(in_place.begin(), in_place.end(), loose_pairs.begin(),
                                   loose_pairs.end()))
                << "frame " << frame << ": held " << in_place.size() << ", written "
                << loose_pairs.size();
            const std::span<const ProxyPair> written_held = written.heldPairs();
            ASSERT_TRUE(std::equal(written_held.begin(), written_held.end(), loose_pairs.begin(),
                                   loose_pairs.end()));
            const std::span<const ProxyPair> exact_held = exact.heldPairs();
            ASSERT_TRUE(std::equal(exact_held.begin(), exact_held.end(), loose_pairs.begin(),
                                   loose_pairs.end()));
            ASSERT_EQ(hc.pairs_flagged, static_cast<std::int64_t>(loose_pairs.size()));
            looser_frames += loose_pairs.size() > exact_pairs.size();
            if (frame == 0) first_tests = hc.volume_tests;
            coherent_frames += frame > 0 && hc.volume_tests < first_tests / 4;
        }
        EXPECT_GT(coherent_frames, 20);
        EXPECT_GT(looser_frames, 40);
    }
}

// The bench's and a user's way in: the factory gives the loose mode, under its own name.
TEST(PackedSweepAndPrune, LooseFactoryNamesItsOutput) {
    const std::unique_ptr<BroadPhase> loose = createLoosePackedSweepAndPrune();
    EXPECT_EQ(loose->name(), "sap-packed-loose");
    EXPECT_EQ(findBroadPhase("sap-packed-loose"), nullptr);  // never in the registry
}

// The packed boxes' conservativeness rests on these two: roundDown(x) is the largest float <= x
// and roundUp(x) the smallest float >= x, for every finite double, including those between two
// floats, on a tie, below the smallest denormal, and beyond the float range (where the answer is
// +-FLT_MAX or +-infinity). Checked by definition: r <= x < the next float above r.
TEST(FloatBounds, RoundDownIsTheLargestFloatBelowAndRoundUpTheSmallestAbove) {
    using float_bounds::roundDown;
    using float_bounds::roundUp;
    constexpr float kInf = std::numeric_limits<float>::infinity();
    constexpr float kMax = std::numeric_limits<float>::max();
    constexpr double kDoubleMax = std::numeric_limits<double>::max();
    std::vector<double> xs = {0.0, -0.0, 1e-50, -1e-50, 1e-300, -1e-300, 1e39, -1e39, kDoubleMax,
                              -kDoubleMax};
    const float floats[] = {0.0f, 1.0f, -1.0f, kMax, -kMax, std::numeric_limits<float>::min(),
                            std::numeric_limits<float>::denorm_min(), 2048.0f, 1e7f, 0.1f};
    for (const float f : floats) {
        for (const float g : {f, -f}) {
            const double d = g;
            const double up = std::nextafter(g, kInf);
            xs.insert(xs.end(), {d, std::nextafter(d, 1e300), std::nextafter(d, -1e300),
                                 (d + up) / 2});  // the tie between g and the next float
        }
    }
    Rng rng(41);
    for (int i = 0; i < 20000; ++i) {
        const double x = std::ldexp(rng.uniform(-1, 1), rng.integer(-160, 135));
        xs.push_back(x);
    }
    for (const double x : xs) {
        if (!std::isfinite(x)) continue;
        SCOPED_TRACE(x);
        const float lo = roundDown(x);
        ASSERT_LE(double(lo), x);
        ASSERT_GT(double(std::nextafter(lo, kInf)), x);
        const float hi = roundUp(x);
        ASSERT_GE(double(hi), x);
        ASSERT_LT(double(std::nextafter(hi, -kInf)), x);
    }
    EXPECT_TRUE(std::isnan(roundDown(std::numeric_limits<double>::quiet_NaN())));
}

// firstReaching is std::lower_bound: on non-decreasing arrays of every length to 40 with many
// ties, from every start, for values below, between, equal to and above the entries.
TEST(PackedSweepAndPrune, FirstReachingIsLowerBound) {
    Rng rng(5);
    for (int n = 0; n <= 40; ++n) {
        for (int trial = 0; trial < 20; ++trial) {
            std::vector<float> reach(static_cast<std::size_t>(n));
            float v = -3;
            for (float& r : reach) r = v += float(rng.integer(0, 2));  // steps of 0, 1 or 2
            for (std::size_t begin = 0; begin <= reach.size(); ++begin) {
                for (float x = -5; x <= v + 2; x += 0.5f) {
                    const auto want = static_cast<std::size_t>(
                        std::lower_bound(reach.begin() + std::ptrdiff_t(begin), reach.end(), x) -
                        reach.begin());
                    ASSERT_EQ(PackedSweepAndPrune::firstReaching(reach, begin, reach.size(), x),
                              want)
                        << "n " << n << " begin " << begin << " x " << x;
                }
            }
        }
    }
}

}  // namespace
}  // namespace collision
