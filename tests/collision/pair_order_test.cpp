// PairOrder through the registry: every broad phase asked for its own order (PairOrder::Found)
// reports exactly the pairs it reports sorted, each (a, b) with a < b, once, and the same list
// for the same calls; only the rows marked found_order write anything but the sorted list.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "collision/visibility_oracle.h"
#include "test_random.h"

namespace collision {
namespace {

using cdlab_test::Rng;

// Boxes wandering in a cube whose volume grows with their number, one in eight four times
// larger (so hgrid plans more than one level), about six pairs per box; proxy 17 leaves at
// frame 3 and comes back at frame 5.
struct Wanderers {
    Real reach;  // the cube is [-reach, reach]^3
    std::vector<Vec3> centre, velocity, half;

    Wanderers(int n, Rng& rng) : reach(10 * std::cbrt(Real(n) / 800)) {
        for (int i = 0; i < n; ++i) {
            centre.push_back(rng.vec(-reach, reach));
            velocity.push_back(rng.vec(-0.3, 0.3));
            half.push_back(rng.vec(0.5, 1.0) * (i % 8 == 0 ? 4 : 1));
        }
    }
    ProxyVolumes volumes(int i) const {
        const Vec3 c = centre[std::size_t(i)], h = half[std::size_t(i)];
        return ProxyVolumes{Aabb{c - h, c + h}, BoundingSphere{c, h.norm()},
                            Obb{c, Mat3::Identity(), h}};
    }
    void step() {
        for (std::size_t i = 0; i < centre.size(); ++i) {
            centre[i] += velocity[i];
            for (int k = 0; k < 3; ++k) {
                if (std::abs(centre[i][k]) > reach) velocity[i][k] = -velocity[i][k];
            }
        }
    }
};

// Runs `entry` sorted and twice in its own order through the same frames; checks each frame and
// returns on how many frames the found list was not sorted.
int framesOutOfOrder(const BroadPhaseEntry& entry, int n) {
    std::unique_ptr<BroadPhase> sorted = entry.create();
    std::unique_ptr<BroadPhase> found = entry.create();
    std::unique_ptr<BroadPhase> again = entry.create();
    found->setPairOrder(PairOrder::Found);
    again->setPairOrder(PairOrder::Found);
    Rng rng(29);
    Wanderers w(n, rng);
    for (int i = 0; i < n; ++i) {
        for (BroadPhase* bp : {sorted.get(), found.get(), again.get()}) {
            bp->insert(i, w.volumes(i));
        }
    }
    int unsorted = 0;
    for (int frame = 0; frame < 8; ++frame) {
        if (frame > 0) w.step();
        for (BroadPhase* bp : {sorted.get(), found.get(), again.get()}) {
            if (frame == 3) bp->remove(17);
            if (frame == 5) bp->insert(17, w.volumes(17));
            for (int i = 0; i < n; ++i) {
                if (i != 17 || frame < 3 || frame >= 5) bp->move(i, w.volumes(i));
            }
        }
        std::vector<ProxyPair> s, f, g;
        BroadPhaseCounters c;
        sorted->findPairs(s, c);
        found->findPairs(f, c);
        again->findPairs(g, c);
        EXPECT_TRUE(std::is_sorted(s.begin(), s.end())) << entry.name << " frame " << frame;
        EXPECT_EQ(f, g) << entry.name << " frame " << frame << ": not deterministic";
        for (const ProxyPair& p : f) EXPECT_LT(p.a, p.b) << entry.name;
        unsorted += !std::is_sorted(f.begin(), f.end());
        std::sort(f.begin(), f.end());
        EXPECT_EQ(f, s) << entry.name << " frame " << frame;  // same pairs, none twice
        EXPECT_GT(s.size(), std::size_t(n)) << entry.name;    // a scene with pairs to order
    }
    return unsorted;
}

TEST(PairOrder, FoundOrderHoldsTheSortedPairsForEveryBroadPhase) {
    for (const BroadPhaseEntry& e : broadPhaseRegistry()) {
        if (e.needs_render_context && !hasVisibilityOracleFactory()) continue;
        const int unsorted = framesOutOfOrder(e, 800);
        if (e.found_order) {
            // Else the row's promise of an order of its own is moot.
            EXPECT_GT(unsorted, 0) << e.name << " wrote its found pairs sorted on every frame";
        } else {
            EXPECT_EQ(unsorted, 0) << e.name << " has no order of its own: found is sorted";
        }
    }
}

// hgrid2 on two threads (from kTwoLaneMinimum proxies) sorts in either order: which lane sweeps
// which columns varies from run to run. The same pairs, sorted, on every frame.
TEST(PairOrder, TwoLaneHgridWritesFoundPairsSorted) {
    const BroadPhaseEntry* e = findBroadPhase("hgrid2");
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(framesOutOfOrder(*e, 6000), 0);
}

TEST(PairOrder, NamesRoundTripAndUnknownNamesAreRefused) {
    for (const PairOrder order : {PairOrder::Sorted, PairOrder::Found}) {
        EXPECT_EQ(findPairOrder(pairOrderName(order)), order);
    }
    EXPECT_EQ(pairOrderName(PairOrder::Sorted), "sorted");
    EXPECT_EQ(pairOrderName(PairOrder::Found), "found");
    EXPECT_FALSE(findPairOrder("Found"));
    EXPECT_FALSE(findPairOrder(""));
    EXPECT_FALSE(findPairOrder("unsorted"));
    EXPECT_EQ(pairOrderNames(), "sorted, found");
}

}  // namespace
}  // namespace collision
