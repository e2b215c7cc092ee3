// app/lab/broadphase_check.cpp -- per-step verification of a broad phase against its reference.
#include "broadphase_check.h"

#include <algorithm>
#include <iterator>
#include <sstream>

namespace app {

std::string describePairMismatch(std::string_view name, std::string_view reference_name,
                                 std::span<const collision::ProxyPair> got,
                                 std::span<const collision::ProxyPair> expected,
                                 std::span<const engine::Body> bodies) {
    if (std::equal(got.begin(), got.end(), expected.begin(), expected.end())) return {};
    // `got` may come in the broad phase's own order (PairOrder::Found): compared as sets, on a
    // sorted copy (the reference's pairs are sorted).
    std::vector<collision::ProxyPair> sorted(got.begin(), got.end());
    std::sort(sorted.begin(), sorted.end());
    if (std::equal(sorted.begin(), sorted.end(), expected.begin(), expected.end())) return {};
    std::vector<collision::ProxyPair> missing;
    std::vector<collision::ProxyPair> extra;
    std::set_difference(expected.begin(), expected.end(), sorted.begin(), sorted.end(),
                        std::back_inserter(missing));
    std::set_difference(sorted.begin(), sorted.end(), expected.begin(), expected.end(),
                        std::back_inserter(extra));
    std::ostringstream out;
    auto label = [&](collision::ProxyId id) {
        std::string s = std::to_string(id);
        if (id >= 0 && static_cast<std::size_t>(id) < bodies.size()) s += " " + bodies[id].name;
        return s;
    };
    auto describe = [&](const char* what, const std::vector<collision::ProxyPair>& list) {
        out << "  " << what << " (" << list.size() << "):";
        for (std::size_t k = 0; k < list.size() && k < 20; ++k) {
            out << " (" << label(list[k].a) << ", " << label(list[k].b) << ")";
        }
        out << (list.size() > 20 ? " ..." : "") << "\n";
    };
    out << "broad phase '" << name << "' reports " << got.size() << " pairs, reference '"
        << reference_name << "' reports " << expected.size() << "\n";
    describe("missed", missing);
    describe("extra", extra);
    return out.str();
}

BroadPhaseChecker::BroadPhaseChecker(const std::string& name) {
    const collision::BroadPhaseEntry* entry = collision::findBroadPhase(name);
    reference_name_ = std::string(entry->reference);
    reference_ = collision::findBroadPhase(entry->reference)->create();
}

std::string BroadPhaseChecker::check(const engine::World& world) {
    const auto volumes = world.volumes();
    for (std::size_t i = 0; i < volumes.size(); ++i) {
        const auto id = static_cast<collision::ProxyId>(i);
        if (i < inserted_) {
            reference_->move(id, volumes[i]);
        } else {
            reference_->insert(id, volumes[i]);
        }
    }
    inserted_ = volumes.size();
    collision::BroadPhaseCounters ignored;
    reference_->findPairs(expected_, ignored);
    return describePairMismatch(world.broadPhase().name(), reference_name_, world.flaggedPairs(),
                                expected_, world.bodies());
}

}  // namespace app
