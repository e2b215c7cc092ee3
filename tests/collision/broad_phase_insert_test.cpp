// Bulk updates equal single ones: for every broad phase in the registry, insertMany(),
// insertBoxes() and moveBoxes() leave the same pairs, counters and internal state as the same
// proxies inserted and moved one at a time, and the pairs equal the brute-force reference's.
// collision_tests runs them on every broad phase that needs no rendering context; cullide_tests
// compiles this same file and runs them on those that do.
#include "collision/broadphase/broad_phase.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <span>
#include <string>
#include <tuple>

#include "broad_phase_scenes.h"

namespace collision {
namespace {

using namespace cdlab_test;

// insertMany is insert() called for each id in turn. One copy of each broad phase takes its
// boxes one by one, the other in spans: the first half at once into an empty broad phase, a
// proxy alone, then, after a findPairs (state kept between calls must notice the new set),
// the rest at once, some of it into ids freed by removals. Both then move the same way; the
// pairs and the broad phase's own checks must agree on every frame, and equal the reference.
TEST(BroadPhaseDifferential, InsertManyEqualsInsertingOneByOne) {
    constexpr int kBoxes = 400;
    for (const BroadPhaseEntry& entry : testedBroadPhases()) {
        SCOPED_TRACE(std::string(entry.name));
        std::unique_ptr<BroadPhase> single, many, ref;
        std::tie(single, many, ref) = twoCopiesAndReference(entry);
        ASSERT_NE(ref, nullptr);
        Rng rng(7);
        std::vector<MovingBox> boxes = makeScene(Layout::Uniform, kBoxes, rng);
        std::vector<ProxyVolumes> volumes;
        for (const MovingBox& b : boxes) volumes.push_back(b.volumes());
        const std::span<const ProxyVolumes> all(volumes);
        std::vector<ProxyPair> single_pairs, many_pairs, ref_pairs;
        BroadPhaseCounters counters;
        auto expectSame = [&](const char* when) {
            single->findPairs(single_pairs, counters);
            many->findPairs(many_pairs, counters);
            ref->findPairs(ref_pairs, counters);
            ASSERT_EQ(many_pairs, single_pairs) << when;
            ASSERT_EQ(many_pairs, ref_pairs) << when;
            ASSERT_EQ(many->validate(), "") << when;
        };
        // Ids [0, 200) at once, 200 alone; [201, 400) at once after a findPairs.
        for (int i = 0; i <= kBoxes / 2; ++i) {
            single->insert(i, volumes[std::size_t(i)]);
            ref->insert(i, volumes[std::size_t(i)]);
        }
        many->insertMany(0, all.first(kBoxes / 2));
        many->insert(kBoxes / 2, volumes[kBoxes / 2]);
        expectSame("after the first half");
        for (int i = kBoxes / 2 + 1; i < kBoxes; ++i) {
            single->insert(i, volumes[std::size_t(i)]);
            ref->insert(i, volumes[std::size_t(i)]);
        }
        many->insertMany(kBoxes / 2 + 1, all.subspan(kBoxes / 2 + 1));
        expectSame("after the second half");
        // Ids [100, 150) removed and given back at once.
        for (int i = 100; i < 150; ++i) {
            single->remove(i);
            many->remove(i);
            ref->remove(i);
        }
        expectSame("after the removals");
        for (int i = 100; i < 150; ++i) {
            single->insert(i, volumes[std::size_t(i)]);
            ref->insert(i, volumes[std::size_t(i)]);
        }
        many->insertMany(100, all.subspan(100, 50));
        expectSame("after the ids were given back");
        for (int frame = 0; frame < 20; ++frame) {
            advance(boxes, Layout::Uniform);
            for (int i = 0; i < kBoxes; ++i) {
                const ProxyVolumes v = boxes[std::size_t(i)].volumes();
                single->move(i, v);
                many->move(i, v);
                ref->move(i, v);
            }
            expectSame("while moving");
        }
        EXPECT_FALSE(many_pairs.empty());
    }
}

TEST(BroadPhaseVolumes, OfABoxAreTheBoxItsCircumsphereAndTheBoxAsAnAxisAlignedObb) {
    const ProxyVolumes v = volumesOfBox(Aabb{Vec3(1, 2, 3), Vec3(3, 6, 9)});
    EXPECT_EQ(v.aabb.min, Vec3(1, 2, 3));
    EXPECT_EQ(v.aabb.max, Vec3(3, 6, 9));
    EXPECT_EQ(v.sphere.center, Vec3(2, 4, 6));
    EXPECT_EQ(v.sphere.radius, std::sqrt(Real(14)));
    EXPECT_EQ(v.obb.center, Vec3(2, 4, 6));
    EXPECT_EQ(v.obb.half_extents, Vec3(1, 2, 3));
    EXPECT_EQ(v.obb.axes, Mat3::Identity());
}

// insertBoxes and moveBoxes are insert() and move() of volumesOfBox for each id in turn. One
// copy of each broad phase is given its boxes one by one, the other in spans: half at once into
// an empty broad phase, one alone, the rest at once after a findPairs, ids freed by removals
// given back at once; then frames of coherent motion, of jumps (most boxes leave any margin a
// broad phase keeps) and of no motion, moved in spans of several lengths with single moves
// between them. Pairs, counters and the broad phase's own checks must agree on every frame, and
// the pairs equal the reference's.
TEST(BroadPhaseDifferential, InsertBoxesAndMoveBoxesEqualOneByOne) {
    constexpr int kBoxes = 400;
    for (const BroadPhaseEntry& entry : testedBroadPhases()) {
        SCOPED_TRACE(std::string(entry.name));
        std::unique_ptr<BroadPhase> single, spans, ref;
        std::tie(single, spans, ref) = twoCopiesAndReference(entry);
        ASSERT_NE(ref, nullptr);
        Rng rng(11);
        std::vector<MovingBox> scene = makeScene(Layout::Uniform, kBoxes + 10, rng);
        std::vector<Aabb> boxes;
        for (const MovingBox& b : scene) boxes.push_back(b.volumes().aabb);
        const auto one = [&](int i) { return volumesOfBox(boxes[std::size_t(i)]); };
        std::vector<ProxyPair> single_pairs, span_pairs, ref_pairs;
        std::int64_t total_pairs = 0;
        auto expectSame = [&](const std::string& when) {
            BroadPhaseCounters single_counters, span_counters, ref_counters;
            single->findPairs(single_pairs, single_counters);
            spans->findPairs(span_pairs, span_counters);
            ref->findPairs(ref_pairs, ref_counters);
            ASSERT_EQ(span_pairs, single_pairs) << when;
            ASSERT_EQ(span_pairs, ref_pairs) << when;
            ASSERT_EQ(span_counters.volumes_updated, single_counters.volumes_updated) << when;
            ASSERT_EQ(span_counters.pairs_flagged, single_counters.pairs_flagged) << when;
            ASSERT_EQ(spans->validate(), "") << when;
            total_pairs += static_cast<std::int64_t>(ref_pairs.size());
        };
        const auto insertOneByOne = [&](int begin, int end) {
            for (int i = begin; i < end; ++i) {
                single->insert(i, one(i));
                ref->insert(i, one(i));
            }
        };
        const std::span<const Aabb> all(boxes);
        insertOneByOne(0, kBoxes / 2 + 1);
        spans->insertBoxes(0, all.first(kBoxes / 2));
        spans->insert(kBoxes / 2, one(kBoxes / 2));
        expectSame("after the first half");
        insertOneByOne(kBoxes / 2 + 1, kBoxes);
        spans->insertBoxes(kBoxes / 2 + 1, all.subspan(kBoxes / 2 + 1, kBoxes / 2 - 1));
        expectSame("after the second half");
        for (int i = 100; i < 150; ++i) {
            single->remove(i);
            spans->remove(i);
            ref->remove(i);
        }
        expectSame("after the removals");
        insertOneByOne(100, 150);
        spans->insertBoxes(100, all.subspan(100, 50));
        expectSame("after the ids were given back");
        // As many proxies out as in between two findPairs: ids [0, 10) swapped for [400, 410),
        // then back.
        for (const auto& [out, in] : {std::pair{0, kBoxes}, std::pair{kBoxes, 0}}) {
            for (int i = out; i < out + 10; ++i) {
                single->remove(i);
                spans->remove(i);
                ref->remove(i);
            }
            insertOneByOne(in, in + 10);
            spans->insertBoxes(in, all.subspan(std::size_t(in), 10));
            expectSame("after swapping ids " + std::to_string(out) + "+ for " + std::to_string(in) + "+");
        }
        for (int frame = 0; frame < 30; ++frame) {
            const int kind = frame % 10;  // 0-6 coherent, 7 jumps, 8 no motion, 9 coherent
            if (kind == 7) {
                for (MovingBox& b : scene) b.center = rng.vec(-10, 10);
            } else if (kind != 8) {
                advance(scene, Layout::Uniform);
            }
            for (int i = 0; i < kBoxes; ++i) {
                boxes[std::size_t(i)] = scene[std::size_t(i)].volumes().aabb;
            }
            for (int i = 0; i < kBoxes; ++i) {
                single->move(i, one(i));
                ref->move(i, one(i));
            }
            // Spans of 0, 1, 37 and the rest, with single moves of the same boxes between.
            const int cut = 1 + frame * 7 % 300;
            spans->moveBoxes(0, all.first(cut));
            spans->moveBoxes(cut, all.subspan(std::size_t(cut), 0));
            spans->move(cut, one(cut));
            spans->moveBoxes(cut + 1, all.subspan(std::size_t(cut) + 1, 1));
            spans->moveBoxes(cut + 2, all.subspan(std::size_t(cut) + 2, 37));
            spans->moveBoxes(cut + 39, all.subspan(std::size_t(cut) + 39, kBoxes - cut - 39));
            expectSame("frame " + std::to_string(frame));
        }
        EXPECT_GT(total_pairs, 0);
    }
}

}  // namespace
}  // namespace collision
