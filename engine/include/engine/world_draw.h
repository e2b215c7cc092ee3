// engine/world_draw.h -- what a picture of a world shows, decided here and drawn through any
// DebugDraw: the bounds and floor grid, the broad phase's own structure, every bounding volume in
// the colours of its own overlap test, the continuous stage's poses at impact, chain skeletons,
// mesh hierarchy levels and contacts. A renderer only rasterises the lines it is given (as
// Box2D's b2World_Draw and Jolt's PhysicsSystem::DrawBodies leave the pixels to their caller).
#pragma once

#include <optional>

#include "collision/bvh/bvh_level.h"
#include "collision/debug_draw.h"
#include "engine/scene.h"
#include "engine/volume_overlaps.h"
#include "engine/world.h"

namespace engine {

/// Colours of the overlap states: green apart, yellow flagged, red colliding.
collision::Color stateColor(BodyState state);
/// Colour of a hierarchy node drawn with draw.bvh_depth: the state colours, Overlapping as
/// flagged (yellow) and Confirmed as colliding (red).
collision::Color nodeColor(collision::BvhNodeState state);

/// Wireframes of the bodies at the times of impact the CCD stage acted on in the last step
/// (World::toiEvents), and the contact normal there: blue.
inline constexpr collision::Color kToiColor{0.25f, 0.5f, 1.0f, 1.0f};
/// Chains' skeletons: joint origins joined by lines (with the bodies).
inline constexpr collision::Color kSkeletonColor{0.92f, 0.92f, 0.85f, 1.0f};
/// Witness points (small crosses) and normals (short segments from A's witness) of the confirmed
/// contacts, with draw.contacts: magenta, a colour no state uses.
inline constexpr collision::Color kContactColor{1.0f, 0.0f, 1.0f, 1.0f};
/// The world bounds' box and the floor grid on its bottom face.
inline constexpr collision::Color kBoundsColor{0.74f, 0.76f, 0.82f, 1.0f};
inline constexpr collision::Color kGridColor{0.22f, 0.24f, 0.29f, 1.0f};
/// The selected body's volumes (DrawOptions::selected): white, a colour no state uses.
inline constexpr collision::Color kSelectColor{1.0f, 1.0f, 1.0f, 1.0f};

/// What a picture of a world shows. Plain data: it may change from one frame to the next.
struct DrawOptions {
    DrawSettings draw;       ///< layers and volumes (the scene's `draw:`)
    bool structure = false;  ///< the broad phase's own structure (BroadPhase::draw)
    /// One body highlighted: its AABB and every volume shown of it drawn again in kSelectColor.
    std::optional<BodyId> selected;
};

/// The groups of lines drawWorld draws, in this order; a renderer may give each its own buffer
/// and line width.
enum class DrawLayer {
    Frame,      ///< the world bounds and floor grid
    Structure,  ///< the broad phase's cells, intervals, nodes (with legend entries)
    Volumes,    ///< bounding volumes, poses at impact, chain skeletons
    Hierarchy,  ///< mesh hierarchy levels
    Contacts,   ///< contact witnesses and normals
    Selection,  ///< the selected body's volumes, over everything else
};

/// The DebugDraw that drawWorld draws through: told which layer the lines that follow belong to,
/// and asked whether a volume of that centre and radius may show at all (a view's culling; a
/// volume it refuses is not drawn). Legend entries come from the Structure layer only.
class WorldDraw : public collision::DebugDraw {
public:
    virtual void setLayer(DrawLayer /*layer*/) {}
    virtual bool mayShow(const Vec3& /*center*/, Real /*radius*/) { return true; }
};

/// What drawWorld drew that a legend must explain.
struct WorldDrawn {
    std::optional<VolumeKind> tested_volume;  ///< the kind the broad phase tests
    /// Some volume drawn is not the kind the broad phase tests: each volume is coloured by its
    /// own overlap test (volume_overlaps.h), not by the broad phase's flags.
    bool own_tests = false;
};

/// Draws every overlay of `world` that `options` asks for, layer by layer, in a fixed order, so
/// the same state and options give the same lines. Read-only on the world (it derives contact
/// details on first use, as World::contactDetails does). `world` must have run detect() or
/// step(): volumes it lacks are not drawn.
WorldDrawn drawWorld(const World& world, WorldDraw& draw, const DrawOptions& options);

}  // namespace engine
