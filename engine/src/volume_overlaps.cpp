// engine/src/volume_overlaps.cpp -- see volume_overlaps.h.
// A picture never colours a volume by another volume's test: a sphere is yellow only when it
// overlaps another body's sphere, whatever the broad phase flagged.
#include "engine/volume_overlaps.h"

#include <algorithm>
#include <memory>
#include <string>

namespace engine {

namespace {

/// The registry's broad phase that finds the pairs of each kind (indexed by VolumeKind): each
/// sorts along an axis, so a fresh one costs O(n log n + pairs), not the O(n^2) of the brute
/// reference it is tested against.
constexpr std::string_view kFinder[] = {"sphere", "sap", "obb"};

}  // namespace

std::optional<VolumeKind> broadPhaseVolume(const World& world) {
    const collision::BroadPhaseEntry* entry = collision::findBroadPhase(world.broadPhase().name());
    if (entry == nullptr) return std::nullopt;
    return entry->volume;
}

DrawSettings drawSettingsFor(const DrawSettings& draw, const World& world) {
    DrawSettings out = draw;
    if (draw.volumes_given) return out;
    for (const VolumeKind kind : kVolumeKinds) out.shows(kind) = false;
    out.shows(broadPhaseVolume(world).value_or(VolumeKind::Aabb)) = true;
    out.kdop = {};
    return out;
}

std::vector<std::string> drawnVolumeNames(const DrawSettings& draw) {
    std::vector<std::string> out;
    if (draw.sphere) out.emplace_back("sphere");
    if (draw.aabb) out.emplace_back("AABB");
    if (draw.obb) out.emplace_back("OBB");
    for (std::size_t i = 0; i < kDrawnKdops.size(); ++i) {
        if (draw.kdop[i]) out.push_back(std::to_string(kDrawnKdops[i]) + "-DOP");
    }
    return out;
}

namespace {

/// Flagged for every body in a pair, then Colliding for those in a confirmed pair among them.
std::vector<BodyState> statesOf(const World& world, std::size_t n,
                                        const std::vector<collision::ProxyPair>& pairs) {
    std::vector<BodyState> states(n, BodyState::Apart);
    for (const collision::ProxyPair& p : pairs) {
        states[std::size_t(p.a)] = BodyState::Flagged;
        states[std::size_t(p.b)] = BodyState::Flagged;
    }
    for (const collision::ProxyPair& p : world.collidingPairs()) {
        if (!std::binary_search(pairs.begin(), pairs.end(), p)) continue;
        states[std::size_t(p.a)] = BodyState::Colliding;
        states[std::size_t(p.b)] = BodyState::Colliding;
    }
    return states;
}

}  // namespace

std::vector<collision::WorldKdop> worldKdops(const World& world, int k) {
    std::vector<collision::WorldKdop> out;
    out.reserve(world.bodies().size());
    for (const Body& b : world.bodies()) {
        out.push_back(collision::computeWorldKdop(b.shape, b.pose(), k));
    }
    return out;
}

VolumeOverlaps kdopOverlaps(const World& world,
                            const std::vector<collision::WorldKdop>& kdops) {
    VolumeOverlaps out;
    std::vector<std::size_t> order(kdops.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return kdops[a].min[0] < kdops[b].min[0] || (kdops[a].min[0] == kdops[b].min[0] && a < b);
    });
    for (std::size_t i = 0; i < order.size(); ++i) {
        const collision::WorldKdop& a = kdops[order[i]];
        for (std::size_t j = i + 1; j < order.size() && kdops[order[j]].min[0] <= a.max[0]; ++j) {
            if (!a.overlaps(kdops[order[j]])) continue;
            const auto lo = collision::ProxyId(std::min(order[i], order[j]));
            const auto hi = collision::ProxyId(std::max(order[i], order[j]));
            out.pairs.push_back({lo, hi});
        }
    }
    std::sort(out.pairs.begin(), out.pairs.end());
    out.states = statesOf(world, kdops.size(), out.pairs);
    return out;
}

VolumeOverlaps volumeOverlaps(const World& world, VolumeKind kind) {
    VolumeOverlaps out;
    const auto volumes = world.volumes();
    if (broadPhaseVolume(world) == kind && world.states().size() == volumes.size()) {
        out.pairs.assign(world.flaggedPairs().begin(), world.flaggedPairs().end());
        // In the broad phase's own order when the world asks for it (WorldSettings::pair_order);
        // most rows write sorted pairs whatever the setting, and those need no sort.
        if (!std::is_sorted(out.pairs.begin(), out.pairs.end())) {
            std::sort(out.pairs.begin(), out.pairs.end());
        }
        out.states.assign(world.states().begin(), world.states().end());
        return out;
    }
    const collision::BroadPhaseEntry* entry =
        collision::findBroadPhase(kFinder[static_cast<int>(kind)]);
    std::unique_ptr<collision::BroadPhase> finder = entry->create();
    for (std::size_t i = 0; i < volumes.size(); ++i) {
        finder->insert(static_cast<collision::ProxyId>(i), volumes[i]);
    }
    collision::BroadPhaseCounters counters;
    finder->findPairs(out.pairs, counters);

    out.states = statesOf(world, volumes.size(), out.pairs);
    return out;
}

}  // namespace engine
