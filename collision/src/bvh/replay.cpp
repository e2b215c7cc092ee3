// collision/src/bvh/replay.cpp -- recording the node and triangle tests one all-pairs query makes
// and replaying them alone, for timing the cost model's unit costs Cv and Cp (bvh_replay.h).
#include "collision/bvh/bvh_replay.h"

#include <array>
#include <cstdint>

#include "bvh/traversal.h"
#include "bvh/typed.h"
#include "volumes/bvh_volumes.h"

namespace collision {

namespace {

// The volume tests of `sample` as traverse() does them: B's node volume moved into A's frame
// once per run of pairs with the same B node (movable types), then the overlap test. Returns how
// many overlap, `repeats` times over.
template <class BV>
std::int64_t replayVolumeTestsOf(const Bvh<BV>& a, const Bvh<BV>& b, const BvhTransform& x,
                                 const BvhTestSample& sample, int repeats) {
    const auto& na = a.nodes();
    const auto& nb = b.nodes();
    std::int64_t overlapping = 0;
    for (int r = 0; r < repeats; ++r) {
        [[maybe_unused]] BV moved_b{};
        [[maybe_unused]] std::int32_t moved_id = -1;
        for (const auto& [ia, ib] : sample.node_pairs) {
            const auto& node_a = na[static_cast<std::size_t>(ia)];
            const auto& node_b = nb[static_cast<std::size_t>(ib)];
            if constexpr (MovableVolume<BV>) {
                if (ib != moved_id) {
                    moved_b = BvTraits<BV>::move(node_b.volume, x);
                    moved_id = ib;
                }
                overlapping += BvTraits<BV>::overlapsMoved(node_a.volume, moved_b, x) ? 1 : 0;
            } else {
                overlapping += BvTraits<BV>::overlaps(node_a.volume, node_b.volume, x) ? 1 : 0;
            }
        }
    }
    return overlapping;
}

// The triangle tests of `sample` as traverse() does them at a leaf pair of one triangle each:
// B's triangle moved into A's frame, then the exact test. Returns how many intersect.
template <class BV>
std::int64_t replayTriangleTestsOf(const Bvh<BV>& a, const Bvh<BV>& b, const BvhTransform& x,
                                   const BvhTestSample& sample, int repeats) {
    std::int64_t intersecting = 0;
    for (int r = 0; r < repeats; ++r) {
        for (const auto& [i, j] : sample.triangle_pairs) {
            const auto& tb = b.leafTriangle(j);
            const std::array<Vec3, 3> moved{x.apply(tb[0]), x.apply(tb[1]), x.apply(tb[2])};
            const auto& ta = a.leafTriangle(i);
            intersecting +=
                testTriangleTriangle(ta[0], ta[1], ta[2], moved[0], moved[1], moved[2]) ? 1 : 0;
        }
    }
    return intersecting;
}

// Every index of `sample` names a node or leaf triangle of `a` and of `b`.
template <class BV>
bool sampleFits(const BvhTestSample& sample, const Bvh<BV>& a, const Bvh<BV>& b) {
    const auto nodes_a = static_cast<std::int32_t>(a.nodes().size());
    const auto nodes_b = static_cast<std::int32_t>(b.nodes().size());
    for (const auto& [ia, ib] : sample.node_pairs) {
        if (ia < 0 || ia >= nodes_a || ib < 0 || ib >= nodes_b) return false;
    }
    for (const auto& [i, j] : sample.triangle_pairs) {
        if (i < 0 || i >= a.triangleCount() || j < 0 || j >= b.triangleCount()) return false;
    }
    return true;
}

}  // namespace

BvhTestSample recordTests(const MeshBvh& a, const MeshBvh& b, const Pose& b_in_a) {
    // The wide tree tests up to four boxes per node in lanes; the binary traversal's tests are
    // not the ones its queries make.
    if (a.volumeName() == kWideObbName || b.volumeName() == kWideObbName) return {};
    return withTreePair(a, b, BvhTestSample{}, [&](const auto& ta, const auto& tb) {
        BvhTestSample sample;
        const BvhTransform x = makeBvhTransform(b_in_a, ta.scale(), tb.scale());
        traverse(
            ta, tb, x, nullptr,
            [](std::int32_t, std::int32_t, const std::array<Vec3, 3>&, const std::array<Vec3, 3>&) {
                return false;
            },
            SampleTestRecord{&sample});
        return sample;
    });
}

std::int64_t replayVolumeTests(const MeshBvh& a, const MeshBvh& b, const Pose& b_in_a,
                               const BvhTestSample& sample, int repeats) {
    return withTreePair(a, b, std::int64_t(0), [&](const auto& ta, const auto& tb) {
        if (!sampleFits(sample, ta, tb)) return std::int64_t(-1);
        const BvhTransform x = makeBvhTransform(b_in_a, ta.scale(), tb.scale());
        return replayVolumeTestsOf(ta, tb, x, sample, repeats);
    });
}

std::int64_t replayTriangleTests(const MeshBvh& a, const MeshBvh& b, const Pose& b_in_a,
                                 const BvhTestSample& sample, int repeats) {
    return withTreePair(a, b, std::int64_t(0), [&](const auto& ta, const auto& tb) {
        if (!sampleFits(sample, ta, tb)) return std::int64_t(-1);
        const BvhTransform x = makeBvhTransform(b_in_a, ta.scale(), tb.scale());
        return replayTriangleTestsOf(ta, tb, x, sample, repeats);
    });
}

}  // namespace collision
