// render/src/volume_states.cpp -- see volume_states.h.
// A picture never colours a volume by another volume's test: a sphere is yellow only when it
// overlaps another body's sphere, whatever the broad phase flagged.
#include "render/volume_states.h"

#include <algorithm>
#include <memory>
#include <string>

namespace render {

namespace {

/// The registry's broad phase that finds the pairs of each kind (indexed by VolumeKind): each
/// sorts along an axis, so a fresh one costs O(n log n + pairs), not the O(n^2) of the brute
/// reference it is tested against.
constexpr std::string_view kFinder[] = {"sphere", "sap", "obb"};

}  // namespace

std::string_view volumeKindName(VolumeKind kind) {
    switch (kind) {
        case VolumeKind::Sphere:
            return "sphere";
        case VolumeKind::Aabb:
            return "aabb";
        case VolumeKind::Obb:
            return "obb";
    }
    return "aabb";
}

std::optional<VolumeKind> broadPhaseVolume(const engine::World& world) {
    const collision::BroadPhaseEntry* entry = collision::findBroadPhase(world.broadPhase().name());
    if (entry == nullptr) return std::nullopt;
    for (const VolumeKind kind : kVolumeKinds) {
        if (entry->volume == volumeKindName(kind)) return kind;
    }
    return std::nullopt;
}

engine::DrawSettings drawSettingsFor(const engine::DrawSettings& draw, const engine::World& world) {
    engine::DrawSettings out = draw;
    if (draw.volumes_given) return out;
    const VolumeKind kind = broadPhaseVolume(world).value_or(VolumeKind::Aabb);
    out.sphere = kind == VolumeKind::Sphere;
    out.aabb = kind == VolumeKind::Aabb;
    out.obb = kind == VolumeKind::Obb;
    return out;
}

VolumeOverlaps volumeOverlaps(const engine::World& world, VolumeKind kind) {
    VolumeOverlaps out;
    const auto volumes = world.volumes();
    if (broadPhaseVolume(world) == kind && world.states().size() == volumes.size()) {
        out.pairs.assign(world.flaggedPairs().begin(), world.flaggedPairs().end());
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

    out.states.assign(volumes.size(), engine::BodyState::Apart);
    for (const collision::ProxyPair& p : out.pairs) {
        out.states[std::size_t(p.a)] = engine::BodyState::Flagged;
        out.states[std::size_t(p.b)] = engine::BodyState::Flagged;
    }
    for (const collision::ProxyPair& p : world.collidingPairs()) {
        if (!std::binary_search(out.pairs.begin(), out.pairs.end(), p)) continue;
        out.states[std::size_t(p.a)] = engine::BodyState::Colliding;
        out.states[std::size_t(p.b)] = engine::BodyState::Colliding;
    }
    return out;
}

}  // namespace render
