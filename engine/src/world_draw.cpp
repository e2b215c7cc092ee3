// engine/src/world_draw.cpp -- see world_draw.h. The lines are drawn in a fixed order (bounds,
// structure, volumes body by body, k-DOPs, poses at impact, skeletons, hierarchy levels,
// contacts), so frames stay bit-identical.
#include "engine/world_draw.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "collision/geometry/shape.h"
#include "collision/volumes/bounding_volumes.h"

namespace engine {

collision::Color stateColor(BodyState state) {
    switch (state) {
        case BodyState::Apart:
            return {0.1f, 0.85f, 0.2f, 1.0f};
        case BodyState::Flagged:
            return {1.0f, 0.85f, 0.0f, 1.0f};
        case BodyState::Colliding:
            return {1.0f, 0.1f, 0.1f, 1.0f};
    }
    return {1.0f, 0.0f, 1.0f, 1.0f};
}

collision::Color nodeColor(collision::BvhNodeState state) {
    switch (state) {
        case collision::BvhNodeState::Apart:
            return stateColor(BodyState::Apart);
        case collision::BvhNodeState::Overlapping:
            return stateColor(BodyState::Flagged);
        case collision::BvhNodeState::Confirmed:
            return stateColor(BodyState::Colliding);
    }
    return kContactColor;
}

namespace {

/// "Nice" grid spacing (1, 2 or 5 times a power of ten) giving about `target` cells over `extent`.
Real gridStep(Real extent, Real target) {
    const Real raw = extent / target;
    const Real p = std::pow(Real(10), std::floor(std::log10(raw)));
    for (const Real m : {Real(1), Real(2), Real(5)}) {
        if (m * p >= raw) return m * p;
    }
    return 10 * p;
}

/// A faint floor grid on the bottom face of the bounds (y is up in scenes), then the box itself.
void drawBounds(const collision::Aabb& b, WorldDraw& draw) {
    const Real ext = std::max(b.extents().x(), b.extents().z());
    if (ext > 0 && std::isfinite(ext)) {
        const Real step = gridStep(ext, 10);
        const Real y = b.min.y();
        for (Real x = std::ceil(b.min.x() / step) * step; x < b.max.x(); x += step) {
            if (x > b.min.x()) draw.drawLine({x, y, b.min.z()}, {x, y, b.max.z()}, kGridColor);
        }
        for (Real z = std::ceil(b.min.z() / step) * step; z < b.max.z(); z += step) {
            if (z > b.min.z()) draw.drawLine({b.min.x(), y, z}, {b.max.x(), y, z}, kGridColor);
        }
    }
    draw.drawAabb(b, kBoundsColor);
}

/// Each kind of volume drawn in the colours of its own overlap test: the broad phase's flags for
/// the kind it tests, that kind's own pairs for the others (volume_overlaps.h); each k-DOP in the
/// colours of its own slab test against the other bodies' k-DOPs of the same k, drawn as the
/// polytope its slabs bound (Klosowski et al. 1998).
void drawVolumes(const World& world, const DrawSettings& show, WorldDraw& draw,
                 WorldDrawn& drawn) {
    std::vector<BodyState> kind_states[std::size(kVolumeKinds)];
    for (const VolumeKind kind : kVolumeKinds) {
        if (!show.shows(kind)) continue;
        kind_states[int(kind)] = volumeOverlaps(world, kind).states;
        drawn.own_tests = drawn.own_tests || drawn.tested_volume != kind;
    }
    const auto volumes = world.volumes();
    for (std::size_t i = 0; i < volumes.size() && i < world.bodies().size(); ++i) {
        auto colorOf = [&](VolumeKind kind) {
            const std::vector<BodyState>& states = kind_states[int(kind)];
            return stateColor(i < states.size() ? states[i] : BodyState::Apart);
        };
        const collision::ProxyVolumes& v = volumes[i];
        if (show.sphere && draw.mayShow(v.sphere.center, v.sphere.radius)) {
            draw.drawSphere(v.sphere, colorOf(VolumeKind::Sphere));
        }
        if (show.aabb && draw.mayShow(v.aabb.center(), Real(0.5) * v.aabb.extents().norm())) {
            draw.drawAabb(v.aabb, colorOf(VolumeKind::Aabb));
        }
        if (show.obb && draw.mayShow(v.obb.center, v.obb.half_extents.norm())) {
            draw.drawObb(v.obb, colorOf(VolumeKind::Obb));
        }
    }
    for (std::size_t i = 0; i < kDrawnKdops.size(); ++i) {
        if (!show.kdop[i]) continue;
        drawn.own_tests = true;
        const std::vector<collision::WorldKdop> kdops = worldKdops(world, kDrawnKdops[i]);
        const std::vector<BodyState> states = kdopOverlaps(world, kdops).states;
        for (std::size_t b = 0; b < kdops.size(); ++b) {
            draw.drawKdop(kdops[b], stateColor(states[b]));
        }
    }
}

/// Each moving body of a time-of-impact event at its pose there (spheres as spheres, other
/// shapes as their OBB), and the contact normal, in blue.
void drawImpacts(const World& world, WorldDraw& draw) {
    const auto bodies = world.bodies();
    for (const ToiEvent& e : world.toiEvents()) {
        for (const auto& [id, pose] : {std::pair{e.a, e.pose_a}, std::pair{e.b, e.pose_b}}) {
            if (id < 0 || static_cast<std::size_t>(id) >= bodies.size()) continue;
            const Body& b = bodies[static_cast<std::size_t>(id)];
            if (b.is_static && !b.kinematic) continue;  // links move with their chain
            if (b.shape.type == collision::ShapeType::Sphere) {
                draw.drawSphere(collision::transformSphere(b.local_bounds.sphere, pose), kToiColor);
            } else {
                draw.drawObb(collision::transformObb(b.local_bounds.obb, pose), kToiColor);
            }
        }
        Real size = 0;
        for (const BodyId id : {e.a, e.b}) {
            if (id >= 0 && static_cast<std::size_t>(id) < bodies.size()) {
                size = std::max(size, bodies[static_cast<std::size_t>(id)].local_bounds.sphere.radius);
            }
        }
        draw.drawLine(e.point, e.point + e.normal * size, kToiColor);
    }
}

/// The selected body's AABB, and each other proxy volume shown of it, in kSelectColor.
void drawSelection(const World& world, BodyId id, const DrawSettings& show, WorldDraw& draw) {
    const collision::ProxyVolumes& v = world.volumes()[static_cast<std::size_t>(id)];
    draw.drawAabb(v.aabb, kSelectColor);
    if (show.sphere) draw.drawSphere(v.sphere, kSelectColor);
    if (show.obb) draw.drawObb(v.obb, kSelectColor);
}

}  // namespace

WorldDrawn drawWorld(const World& world, WorldDraw& draw, const DrawOptions& options) {
    WorldDrawn drawn;
    drawn.tested_volume = broadPhaseVolume(world);
    draw.setLayer(DrawLayer::Frame);
    if (options.draw.bounds) drawBounds(world.settings().bounds, draw);

    if (options.structure) {
        draw.setLayer(DrawLayer::Structure);
        world.broadPhase().draw(draw, world.settings().bounds);
    }

    draw.setLayer(DrawLayer::Volumes);
    drawVolumes(world, options.draw, draw, drawn);
    drawImpacts(world, draw);
    if (options.draw.bodies) world.drawChainSkeletons(draw, kSkeletonColor);

    // What the narrow phase confirmed: the World derives it.
    ContactDrawStyle style;
    style.node_apart = nodeColor(collision::BvhNodeState::Apart);
    style.node_overlapping = nodeColor(collision::BvhNodeState::Overlapping);
    style.node_confirmed = nodeColor(collision::BvhNodeState::Confirmed);
    style.contact = kContactColor;
    if (options.draw.bvh_depth >= 0) {
        draw.setLayer(DrawLayer::Hierarchy);
        world.drawHierarchyLevels(draw, options.draw.bvh_depth, style);
    }
    if (options.draw.contacts) {
        draw.setLayer(DrawLayer::Contacts);
        world.drawContacts(draw, style);
    }
    if (options.selected && *options.selected >= 0 &&
        static_cast<std::size_t>(*options.selected) < world.volumes().size()) {
        draw.setLayer(DrawLayer::Selection);
        drawSelection(world, *options.selected, options.draw, draw);
    }
    return drawn;
}

}  // namespace engine
