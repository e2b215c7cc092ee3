// collision/volumes/volume_kind.h -- the bounding volumes every body has (ProxyVolumes), by
// name: the one vocabulary of the broad-phase registry's volume column, the brute-force
// references, the engine's per-volume overlap states, the scene's `draw.volumes` and a picture's
// legend.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace collision {

enum class VolumeKind : std::uint8_t { Sphere, Aabb, Obb };
inline constexpr VolumeKind kVolumeKinds[] = {VolumeKind::Sphere, VolumeKind::Aabb,
                                              VolumeKind::Obb};

/// "sphere", "aabb", "obb": as scene files and the registry's table write them.
constexpr std::string_view volumeKindName(VolumeKind kind) {
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

/// The kind of that name (volumeKindName), nullopt for any other.
constexpr std::optional<VolumeKind> volumeKindNamed(std::string_view name) {
    for (const VolumeKind kind : kVolumeKinds) {
        if (volumeKindName(kind) == name) return kind;
    }
    return std::nullopt;
}

}  // namespace collision
