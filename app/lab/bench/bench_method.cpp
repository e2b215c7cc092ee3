// app/lab/bench/bench_method.cpp -- cdlab's AABB broad phases behind the benchmark interface, and the
// list of every benchmark method by name.
#include "bench_method.h"

#include <utility>

#include "collision/broadphase/loose_broad_phase.h"
#include "collision/visibility_oracle.h"

namespace app {

namespace {

/// A cdlab registry broad phase (one that decides on AABBs) reading the workload's array of
/// boxes, as the peers read it box by box: insertBoxes() and moveBoxes() take it at once;
/// findPairs() writes into a reused vector.
class CdlabMethod : public BenchMethod {
public:
    CdlabMethod(const collision::BroadPhaseEntry& entry, collision::PairOrder order)
        : broad_phase_(entry.create()) {
        broad_phase_->setPairOrder(order);
    }
    explicit CdlabMethod(std::unique_ptr<collision::BroadPhase> broad_phase)
        : broad_phase_(std::move(broad_phase)) {}

    void insertAll(const MovingBoxes& boxes,
                   std::span<const collision::ProxyVolumes> /*volumes*/) override {
        broad_phase_->insertBoxes(0, boxes.aabbs());
    }
    void moveAll(const MovingBoxes& boxes,
                 std::span<const collision::ProxyVolumes> /*volumes*/) override {
        broad_phase_->moveBoxes(0, boxes.aabbs());
    }
    void findPairs() override { broad_phase_->findPairs(pairs_, counters_); }
    PairSummary summary(const MovingBoxes& /*boxes*/) override { return summarizePairs(pairs_); }
    std::int64_t potentiallyColliding() const override {
        return broad_phase_->potentiallyCollidingSize();
    }

protected:
    std::unique_ptr<collision::BroadPhase> broad_phase_;
    std::vector<collision::ProxyPair> pairs_;
    collision::BroadPhaseCounters counters_;
};

/// A cdlab broad phase with a loose output (collision/broadphase/loose_broad_phase.h), driven like
/// the registry's but read as a Bullet pair cache is: findPairs() brings the held list up to date
/// (updatePairs) and the list is read in place (heldPairs), no copy. It is a superset of the
/// exact pairs and is treated as the peers' caches: rawPairs() is its size, deliverExact() keeps
/// the pairs whose exact boxes overlap (timed under the exact-pairs rule), summary() filters it
/// again, untimed.
class LooseCdlabMethod : public CdlabMethod {
public:
    explicit LooseCdlabMethod(std::unique_ptr<collision::LooseBroadPhase> broad_phase)
        : CdlabMethod(nullptr), loose_(broad_phase.get()) {
        broad_phase_ = std::move(broad_phase);
    }

    void findPairs() override {
        loose_->updatePairs(counters_);
        delivered_ = false;
    }
    void deliverExact(const MovingBoxes& boxes) override {
        // What its caller does before a narrow phase: keep the pairs whose exact boxes (the
        // workload's, as the Bullet rows with float proxies test them) overlap. Stays sorted.
        exact_.clear();
        for (const collision::ProxyPair& p : loose_->heldPairs()) {
            if (boxes.aabb(p.a).overlaps(boxes.aabb(p.b))) exact_.push_back(p);
        }
        delivered_ = true;
    }
    PairSummary summary(const MovingBoxes& boxes) override {
        PairSummary out;
        for (const collision::ProxyPair& p : loose_->heldPairs()) {
            if (!boxes.aabb(p.a).overlaps(boxes.aabb(p.b))) continue;
            ++out.pairs;
            out.hash += pairHash(p.a, p.b);
        }
        // deliverExact()'s list, when it ran for this frame, must be the same set: a differing
        // one is reported as a mismatch (the count made impossible).
        if (delivered_ && !(summarizePairs(exact_) == out)) out.pairs = -1;
        return out;
    }
    std::int64_t rawPairs() const override {
        return static_cast<std::int64_t>(loose_->heldPairs().size());
    }

private:
    collision::LooseBroadPhase* loose_;  ///< broad_phase_, as its loose interface
    std::vector<collision::ProxyPair> exact_;
    bool delivered_ = false;
};

std::vector<BenchMethodEntry> makeMethods() {
    std::vector<BenchMethodEntry> methods;
    for (const collision::BroadPhaseEntry& entry : collision::broadPhaseRegistry()) {
        if (entry.volume != collision::VolumeKind::Aabb) continue;
        // cullide only where a rendering context was installed (cdlab, not the bare bench).
        if (entry.needs_render_context && !collision::hasVisibilityOracleFactory()) continue;
        BenchMethodEntry m;
        m.name = std::string(entry.name);
        m.description = std::string(entry.description);
        m.default_set = !entry.needs_render_context;
        m.threads = entry.threads;
        m.foreign_threads = entry.needs_render_context;
        const collision::BroadPhaseEntry* e = &entry;
        m.create = [e]() -> std::unique_ptr<BenchMethod> {
            return std::make_unique<CdlabMethod>(*e, collision::PairOrder::Sorted);
        };
        methods.push_back(m);
        // Its pairs in its own order (no final sort), run only when named: `hgrid:found`.
        if (entry.found_order) {
            m.name += ":found";
            m.description += "; pairs in the order found, not sorted";
            m.default_set = false;
            m.create = [e]() -> std::unique_ptr<BenchMethod> {
                return std::make_unique<CdlabMethod>(*e, collision::PairOrder::Found);
            };
            methods.push_back(std::move(m));
        }
    }
    // A cdlab method with a loose output, outside the registry (whose entries equal brute
    // force): its median_ms compares like for like with the peers' pair caches, its exact_ms
    // (the filter timed) with their exact_ms.
    BenchMethodEntry loose;
    loose.name = "sap-packed-loose";
    loose.description =
        "sap-packed writing its candidates (fat boxes overlap), a superset of the exact pairs, "
        "as Bullet's pair cache; filtered in exact_ms";
    loose.default_set = true;
    loose.create = []() -> std::unique_ptr<BenchMethod> {
        return std::make_unique<LooseCdlabMethod>(collision::createLoosePackedSweepAndPrune());
    };
    methods.push_back(std::move(loose));
    appendPeerMethods(methods);
    appendBoxPruningPeer(methods);
    return methods;
}

}  // namespace

const std::vector<BenchMethodEntry>& benchMethods() {
    static const std::vector<BenchMethodEntry> methods = makeMethods();
    return methods;
}

const BenchMethodEntry* findBenchMethod(std::string_view name) {
    for (const BenchMethodEntry& m : benchMethods()) {
        if (m.name == name) return &m;
    }
    return nullptr;
}

}  // namespace app
