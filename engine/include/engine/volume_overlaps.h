// engine/volume_overlaps.h -- each kind of bounding volume judged by its own overlap test: which
// volumes a picture draws by default, and the overlap state of every body's volume of each kind.
// Computed here, by the registry's broad phases, so that a picture and a data file only read it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "collision/volumes/kdop_volume.h"
#include "collision/volumes/volume_kind.h"
#include "engine/scene.h"
#include "engine/world.h"

namespace engine {

using collision::kVolumeKinds;
using collision::VolumeKind;
using collision::volumeKindName;

/// The volume the world's broad phase decides on (BroadPhaseEntry::volume); nullopt for a
/// broad phase that is not in the registry.
std::optional<VolumeKind> broadPhaseVolume(const World& world);

/// The scene's draw settings with, unless the scene chose its volumes (`draw.volumes` given),
/// exactly the volume the world's broad phase tests drawn: bounding spheres for `sphere`, OBBs
/// for `obb`, AABBs for every AABB-based broad phase.
DrawSettings drawSettingsFor(const DrawSettings& draw, const World& world);

/// The volumes `draw` draws, as a legend names them: "sphere", "AABB", "OBB", then "6-DOP",
/// "14-DOP", "18-DOP", "26-DOP" for each k-DOP drawn, in that order.
std::vector<std::string> drawnVolumeNames(const DrawSettings& draw);

/// One kind of volume over all bodies, each judged by that kind's own overlap test.
struct VolumeOverlaps {
    /// Pairs whose volumes of this kind overlap (touching counts): sorted, a < b, unique.
    std::vector<collision::ProxyPair> pairs;
    /// Per body: Colliding when in a pair the narrow phase confirmed (World::collidingPairs) and
    /// whose volumes of this kind overlap; else Flagged when its volume overlaps another body's
    /// volume of this kind; else Apart.
    std::vector<BodyState> states;
};

/// The overlaps of the world's volumes of `kind` at its last detect() or step(). For the kind
/// the broad phase tests these are the world's own flagged pairs and states (the broad phases
/// report exactly their volume's overlaps; sorted here when the world keeps them in the broad
/// phase's own order, WorldSettings::pair_order); any other kind is found afresh by the registry's
/// sorting broad phase for that volume (sap, sphere, obb: exact tests, each checked against its
/// brute-force reference), O(n log n + pairs).
VolumeOverlaps volumeOverlaps(const World& world, VolumeKind kind);

/// Per body, its world k-DOP of `k` (6, 14, 18, 26) at its current pose (exact support of
/// its shape along every slab direction, collision::computeWorldKdop).
std::vector<collision::WorldKdop> worldKdops(const World& world, int k);

/// The overlaps of the bodies' k-DOPs (collision::WorldKdop::overlaps; touching counts), states
/// as for volumeOverlaps: sorted on the first slab and swept, O(n log n + pairs on that axis).
VolumeOverlaps kdopOverlaps(const World& world,
                            const std::vector<collision::WorldKdop>& kdops);

}  // namespace engine
