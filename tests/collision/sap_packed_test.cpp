// sap-packed's coherent path beside brute force: the pairs of overlapping fat boxes kept between
// frames, fat boxes led by the motion, and the look-ups of the boxes that left theirs, on
// jittering, steadily moving and mixed-size scenes. (The registry's differential tests in
// broad_phase_test.cpp run it on random and adversarial scenes like every other broad phase.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "collision/broadphase/broad_phase.h"
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
}  // namespace
}  // namespace collision
