// The optional bench peer `terdiman-v17` (Terdiman's BoxPruning17, built only when configured
// with CDLAB_BOXPRUNING_DIR): its pair set on his BoxPruning scene equals a brute-force test of
// every pair of boxes, one-shot and after the boxes moved. Skipped when the peer is not built.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "bench_method.h"
#include "bench_workload.h"

namespace {

// Every pair of boxes tested with the closed interval test on each axis (touching counts).
app::PairSummary bruteForce(const app::MovingBoxes& boxes) {
    app::PairSummary out;
    for (int a = 0; a < boxes.size(); ++a) {
        for (int b = a + 1; b < boxes.size(); ++b) {
            if (boxes.aabb(a).overlaps(boxes.aabb(b))) {
                ++out.pairs;
                out.hash += app::pairHash(a, b);
            }
        }
    }
    return out;
}

TEST(BoxPruningPeer, PairsEqualBruteForceOnTheBoxPruningScene) {
    const app::BenchMethodEntry* entry = app::findBenchMethod("terdiman-v17");
    if (entry == nullptr) GTEST_SKIP() << "built without CDLAB_BOXPRUNING_DIR";
    EXPECT_TRUE(entry->peer);
    app::MovingBoxes boxes(app::WorkloadKind::BoxPruning, 10000, 1);  // --seed 1: his seed 42
    std::vector<collision::ProxyVolumes> volumes;
    boxes.volumes(volumes);
    std::unique_ptr<app::BenchMethod> method = entry->create();
    method->insertAll(boxes, volumes);
    method->findPairs();
    const app::PairSummary first = bruteForce(boxes);
    EXPECT_EQ(first.pairs, 11811);  // the count his study reports for this scene
    EXPECT_EQ(method->summary(boxes), first);
    for (int frame = 1; frame <= 3; ++frame) {
        boxes.step();
        boxes.volumes(volumes);
        method->moveAll(boxes, volumes);
        method->findPairs();
        EXPECT_EQ(method->summary(boxes), bruteForce(boxes)) << "frame " << frame;
    }
}

}  // namespace
