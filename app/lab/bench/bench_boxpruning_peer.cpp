// app/lab/bench/bench_boxpruning_peer.cpp -- Terdiman's BoxPruning17 (github.com/Pierre-Terdiman/
// BoxPruning, "Box pruning revisited", 2017) as the bench row `terdiman-v17`, when configured with
// CDLAB_BOXPRUNING_DIR. His code has no coherence: every findPairs() is a one-shot query on the
// boxes as floats (his AABB type). The BoxPruning scene's boxes are integers, so the floats are
// exact there; on other workloads rounding to float can change the pair set, which the bench
// then reports as a peer mismatch.
#include "bench_method.h"

#ifdef CDLAB_HAVE_BOXPRUNING_V17
#include <algorithm>
#include <vector>

#include "boxpruning_v17.h"
#endif

namespace app {

#ifdef CDLAB_HAVE_BOXPRUNING_V17
namespace {

class BoxPruningV17Method : public BenchMethod {
public:
    void insertAll(const MovingBoxes& boxes,
                   std::span<const collision::ProxyVolumes> volumes) override {
        moveAll(boxes, volumes);
    }
    void moveAll(const MovingBoxes& boxes,
                 std::span<const collision::ProxyVolumes> /*volumes*/) override {
        const int n = boxes.size();
        floats_.resize(6 * static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) {
            const collision::Aabb b = boxes.aabb(i);
            for (int k = 0; k < 3; ++k) {
                floats_[6 * i + k] = static_cast<float>(b.min[k]);
                floats_[6 * i + 3 + k] = static_cast<float>(b.max[k]);
            }
        }
    }
    void findPairs() override {
        pairs_ = boxPruningV17(floats_.data(), static_cast<std::uint32_t>(floats_.size() / 6));
    }
    PairSummary summary(const MovingBoxes& /*boxes*/) override {
        // Every pair as he reports it, unfiltered: a false or duplicated pair shows as a mismatch.
        PairSummary out;
        for (std::size_t i = 0; i + 1 < pairs_.size(); i += 2) {
            const auto a = static_cast<collision::ProxyId>(std::min(pairs_[i], pairs_[i + 1]));
            const auto b = static_cast<collision::ProxyId>(std::max(pairs_[i], pairs_[i + 1]));
            ++out.pairs;
            out.hash += pairHash(a, b);
        }
        return out;
    }

private:
    std::vector<float> floats_;
    std::span<const std::uint32_t> pairs_;
};

}  // namespace
#endif

void appendBoxPruningPeer([[maybe_unused]] std::vector<BenchMethodEntry>& methods) {
#ifdef CDLAB_HAVE_BOXPRUNING_V17
    BenchMethodEntry m;
    m.name = "terdiman-v17";
    m.description =
        "Terdiman's BoxPruning17 CompleteBoxPruning (radix sort, 5 YZ buckets, SSE), "
        "one-shot every frame, boxes as floats";
    m.peer = true;
    // Named only: on workloads whose bounds are not floats, rounding can change the pair set.
    m.default_set = false;
    m.create = []() -> std::unique_ptr<BenchMethod> {
        return std::make_unique<BoxPruningV17Method>();
    };
    methods.push_back(std::move(m));
#endif
}

}  // namespace app
