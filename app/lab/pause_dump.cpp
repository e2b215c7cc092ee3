// app/lab/pause_dump.cpp -- pause dumps as JSON (nlohmann::ordered_json, numbers round-trip exactly).
#include "pause_dump.h"

#include <algorithm>
#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "collision/bvh/bvh.h"
#include "engine/volume_overlaps.h"

namespace app {

namespace {

nlohmann::ordered_json vec(const collision::Vec3& v) { return {v.x(), v.y(), v.z()}; }

// Sorted by (a, b): the world's pairs come in its pair order (world.pair_order), the dump's do not.
nlohmann::ordered_json pairs(std::span<const collision::ProxyPair> list) {
    std::vector<collision::ProxyPair> sorted(list.begin(), list.end());
    std::sort(sorted.begin(), sorted.end());
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const collision::ProxyPair& p : sorted) out.push_back({p.a, p.b});
    return out;
}

/// A volume's state in the dump: "apart", "overlapping" (its volume overlaps another body's
/// volume of the same kind) or "colliding" (a pair the narrow phase confirmed).
std::string_view volumeStateName(engine::BodyState state) {
    switch (state) {
        case engine::BodyState::Apart: return "apart";
        case engine::BodyState::Flagged: return "overlapping";
        case engine::BodyState::Colliding: return "colliding";
    }
    return "apart";
}

}  // namespace

std::string pauseDumpJson(const engine::World& world, int frame, const engine::DrawSettings& draw,
                          bool compact) {
    nlohmann::ordered_json doc;
    doc["frame"] = frame;
    doc["time"] = world.time();
    doc["broadphase"] = std::string(world.broadPhase().name());
    doc["broadphase_volume"] = std::string(
        engine::volumeKindName(engine::broadPhaseVolume(world).value_or(engine::VolumeKind::Aabb)));
    // Each kind of volume by its own overlap test, as the pause picture colours them.
    std::array<engine::VolumeOverlaps, 3> overlaps;
    for (const engine::VolumeKind kind : engine::kVolumeKinds) {
        overlaps[int(kind)] = engine::volumeOverlaps(world, kind);
    }
    // Each k-DOP drawn, by the slab test that colours it.
    struct KdopKind {
        int k = 6;
        std::string name;
        std::vector<collision::WorldKdop> kdops;
        engine::VolumeOverlaps overlaps;
    };
    std::vector<KdopKind> kdop_kinds;
    for (std::size_t i = 0; i < engine::kDrawnKdops.size(); ++i) {
        if (!draw.kdop[i]) continue;
        const int k = engine::kDrawnKdops[i];
        KdopKind kind{k, "kdop" + std::to_string(k), engine::worldKdops(world, k), {}};
        kind.overlaps = engine::kdopOverlaps(world, kind.kdops);
        kdop_kinds.push_back(std::move(kind));
    }
    nlohmann::ordered_json bodies = nlohmann::ordered_json::array();
    const auto all = world.bodies();
    for (std::size_t i = 0; i < all.size(); ++i) {
        const engine::Body& b = all[i];
        const collision::ProxyVolumes& v = world.volumes()[i];
        const collision::Quat& q = b.orientation;
        nlohmann::ordered_json axes = nlohmann::ordered_json::array();
        for (int k = 0; k < 3; ++k) axes.push_back(vec(v.obb.axes.col(k)));
        bodies.push_back({
            {"id", i},
            {"name", b.name},
            {"shape", std::string(collision::shapeTypeName(b.shape.type))},
            {"position", vec(b.position)},
            {"orientation_wxyz", {q.w(), q.x(), q.y(), q.z()}},
            {"velocity", vec(b.velocity())},
            {"angular_velocity", vec(b.angularVelocity())},
            {"sphere", {{"center", vec(v.sphere.center)}, {"radius", v.sphere.radius}}},
            {"aabb", {{"min", vec(v.aabb.min)}, {"max", vec(v.aabb.max)}}},
            {"obb",
             {{"center", vec(v.obb.center)},
              {"axes", axes},
              {"half_extents", vec(v.obb.half_extents)}}},
            {"state", std::string(engine::bodyStateName(world.states()[i]))},
        });
        nlohmann::ordered_json volume_states;
        for (const engine::VolumeKind kind : engine::kVolumeKinds) {
            const auto& states = overlaps[int(kind)].states;
            volume_states[std::string(engine::volumeKindName(kind))] = std::string(
                volumeStateName(i < states.size() ? states[i] : engine::BodyState::Apart));
        }
        for (const KdopKind& kind : kdop_kinds) {
            const collision::WorldKdop& kdop = kind.kdops[i];
            const auto slabs = static_cast<std::ptrdiff_t>(kdop.k / 2);
            bodies.back()[kind.name] = {
                {"k", kdop.k},
                {"min", std::vector<collision::Real>(kdop.min.begin(), kdop.min.begin() + slabs)},
                {"max", std::vector<collision::Real>(kdop.max.begin(), kdop.max.begin() + slabs)},
            };
            volume_states[kind.name] = std::string(volumeStateName(kind.overlaps.states[i]));
        }
        bodies.back()["volume_states"] = std::move(volume_states);
        // A mesh body's hierarchy: the volume it was built with (world.mesh_bvh).
        if (b.shape.bvh != nullptr) {
            bodies.back()["mesh_bvh"] = std::string(b.shape.bvh->volumeName());
        }
    }
    if (!kdop_kinds.empty()) {
        nlohmann::ordered_json directions = nlohmann::ordered_json::object();
        for (const KdopKind& kind : kdop_kinds) {
            nlohmann::ordered_json list = nlohmann::ordered_json::array();
            for (int s = 0; s < kind.k / 2; ++s) {
                list.push_back(vec(collision::kdopSlabDirection(kind.k, s)));
            }
            directions[kind.name] = std::move(list);
        }
        doc["kdop_slab_directions"] = std::move(directions);
    }
    doc["bodies"] = std::move(bodies);
    doc["flagged_pairs"] = pairs(world.flaggedPairs());
    doc["colliding_pairs"] = pairs(world.collidingPairs());
    nlohmann::ordered_json overlapping = nlohmann::ordered_json::object();
    for (const engine::VolumeKind kind : engine::kVolumeKinds) {
        overlapping[std::string(engine::volumeKindName(kind))] = pairs(overlaps[int(kind)].pairs);
    }
    for (const KdopKind& kind : kdop_kinds) overlapping[kind.name] = pairs(kind.overlaps.pairs);
    doc["overlapping_pairs"] = std::move(overlapping);
    return compact ? doc.dump() : doc.dump(1) + "\n";
}

engine::DrawSettings pauseDrawSettings(engine::DrawSettings frame_draw, bool volumes_chosen) {
    if (!volumes_chosen) frame_draw.sphere = frame_draw.aabb = frame_draw.obb = true;
    return frame_draw;
}

std::vector<std::optional<render::ScreenRect>> bodyRects(const engine::World& world,
                                                         const engine::CameraSettings& camera,
                                                         int width, int height) {
    std::vector<std::optional<render::ScreenRect>> rects;
    rects.reserve(world.volumes().size());
    for (const collision::ProxyVolumes& v : world.volumes()) {
        rects.push_back(render::screenRect(camera, width, height, v.aabb.min, v.aabb.max));
    }
    return rects;
}

}  // namespace app
