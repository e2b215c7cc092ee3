// render/src/frame_lines.cpp -- what a frame draws as lines: the world bounds and floor grid,
// the broad phase's own structure, every bounding volume in the colours of its own overlap test,
// the continuous stage's poses at impact, chain skeletons, hierarchy levels and contacts.
// Read-only on the World; the lines are built in a fixed order, so frames stay bit-identical.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "collision/geometry/shape.h"
#include "collision/volumes/bounding_volumes.h"
#include "renderer_impl.h"

namespace render {
namespace {

using collision::Color;
using collision::Real;
using collision::Vec3;

constexpr Color kBoundsColor{0.74f, 0.76f, 0.82f, 1.0f};
constexpr Color kGridColor{0.22f, 0.24f, 0.29f, 1.0f};
/// Contact marks, as fractions of the smaller bounding radius of the pair: the half size of a
/// witness cross and the length of the normal segment.
constexpr Real kContactCrossFraction = Real(0.06);
constexpr Real kContactNormalFraction = Real(0.5);

/// "Nice" grid spacing (1, 2 or 5 times a power of ten) giving about `target` cells over `extent`.
Real gridStep(Real extent, Real target) {
    const Real raw = extent / target;
    const Real p = std::pow(Real(10), std::floor(std::log10(raw)));
    for (const Real m : {Real(1), Real(2), Real(5)}) {
        if (m * p >= raw) return m * p;
    }
    return 10 * p;
}
}  // namespace

void Renderer::Impl::buildLines(const engine::World& world, const CameraFrame& cam,
                                const FrameOptions& options) {
    frame_lines.clear();
    structure_lines.clear();
    volume_lines.clear();
    outline_lines.clear();
    bvh_lines.clear();
    contact_lines.clear();
    GlDebugDraw debug(cam, frame_lines);

    if (options.draw.bounds) {
        const collision::Aabb& b = world.settings().bounds;
        // A faint floor grid on the bottom face (y is up in scenes), then the box itself.
        const Real ext = std::max(b.extents().x(), b.extents().z());
        if (ext > 0 && std::isfinite(ext)) {
            const Real step = gridStep(ext, 10);
            const Real y = b.min.y();
            for (Real x = std::ceil(b.min.x() / step) * step; x < b.max.x(); x += step) {
                if (x > b.min.x()) debug.drawLine({x, y, b.min.z()}, {x, y, b.max.z()}, kGridColor);
            }
            for (Real z = std::ceil(b.min.z() / step) * step; z < b.max.z(); z += step) {
                if (z > b.min.z()) debug.drawLine({b.min.x(), y, z}, {b.max.x(), y, z}, kGridColor);
            }
        }
        debug.drawAabb(b, kBoundsColor);
    }

    structure_legend.clear();
    if (options.draw_structure) {
        debug.setTarget(structure_lines);
        debug.setLegend(&structure_legend);
        world.broadPhase().draw(debug, world.settings().bounds);
        debug.setLegend(nullptr);
    }

    drawVolumes(world, cam, options, debug);

    // CCD: each moving body of a time-of-impact event at its pose there (spheres as spheres,
    // other shapes as their OBB), and the contact normal, in blue. Read-only use of the events.
    const auto bodies = world.bodies();
    for (const engine::ToiEvent& e : world.toiEvents()) {
        for (const auto& [id, pose] : {std::pair{e.a, e.pose_a}, std::pair{e.b, e.pose_b}}) {
            if (id < 0 || static_cast<std::size_t>(id) >= bodies.size()) continue;
            const engine::Body& b = bodies[static_cast<std::size_t>(id)];
            if (b.is_static && !b.kinematic) continue;  // links move with their chain
            if (b.shape.type == collision::ShapeType::Sphere) {
                debug.drawSphere(collision::transformSphere(b.local_bounds.sphere, pose),
                                 kToiColor);
            } else {
                debug.drawObb(collision::transformObb(b.local_bounds.obb, pose), kToiColor);
            }
        }
        Real size = 0;
        for (const engine::BodyId id : {e.a, e.b}) {
            if (id >= 0 && static_cast<std::size_t>(id) < bodies.size()) {
                size =
                    std::max(size, bodies[static_cast<std::size_t>(id)].local_bounds.sphere.radius);
            }
        }
        debug.drawLine(e.point, e.point + e.normal * size, kToiColor);
    }
    if (options.draw.bodies) world.drawChainSkeletons(debug, kSkeletonColor);

    // What the narrow phase confirmed: the World derives it and decides what to draw.
    engine::ContactDrawStyle style;
    style.node_apart = nodeColor(collision::BvhNodeState::Apart);
    style.node_overlapping = nodeColor(collision::BvhNodeState::Overlapping);
    style.node_confirmed = nodeColor(collision::BvhNodeState::Confirmed);
    style.contact = kContactColor;
    style.cross_fraction = kContactCrossFraction;
    style.normal_fraction = kContactNormalFraction;
    if (options.draw.bvh_depth >= 0) {
        debug.setTarget(bvh_lines);
        world.drawHierarchyLevels(debug, options.draw.bvh_depth, style);
    }
    if (options.draw.contacts) {
        debug.setTarget(contact_lines);
        world.drawContacts(debug, style);
    }
}

void Renderer::Impl::drawVolumes(const engine::World& world, const CameraFrame& cam,
                                 const FrameOptions& options, GlDebugDraw& debug) {
    // Each kind of volume in the colours of its own overlap test: the broad phase's flags for
    // the kind it tests, that kind's own pairs for the others (volume_states.h).
    tested_volume = broadPhaseVolume(world);
    own_tests = false;
    const bool drawn[3] = {options.draw.sphere, options.draw.aabb, options.draw.obb};
    std::vector<engine::BodyState> kind_states[3];
    for (const VolumeKind kind : kVolumeKinds) {
        if (!drawn[int(kind)]) continue;
        kind_states[int(kind)] = volumeOverlaps(world, kind).states;
        own_tests = own_tests || tested_volume != kind;
    }
    const auto volumes = world.volumes();
    debug.setTarget(volume_lines, &outline_lines);
    for (std::size_t i = 0; i < volumes.size() && i < world.bodies().size(); ++i) {
        auto colorOf = [&](VolumeKind kind) {
            const std::vector<engine::BodyState>& states = kind_states[int(kind)];
            return stateColor(i < states.size() ? states[i] : engine::BodyState::Apart);
        };
        const collision::ProxyVolumes& v = volumes[i];
        auto shows = [&](const Vec3& center, Real radius) {
            if (!options.cull || cam.mayShow(center, radius)) return true;
            ++stats.volumes_culled;
            return false;
        };
        if (options.draw.sphere && shows(v.sphere.center, v.sphere.radius)) {
            debug.drawSphere(v.sphere, colorOf(VolumeKind::Sphere));
        }
        if (options.draw.aabb && shows(v.aabb.center(), Real(0.5) * v.aabb.extents().norm())) {
            debug.drawAabb(v.aabb, colorOf(VolumeKind::Aabb));
        }
        if (options.draw.obb && shows(v.obb.center, v.obb.half_extents.norm())) {
            debug.drawObb(v.obb, colorOf(VolumeKind::Obb));
        }
    }
    drawKdops(world, options, debug);
}

void Renderer::Impl::drawKdops(const engine::World& world, const FrameOptions& options,
                               GlDebugDraw& debug) {
    // Each k-DOP in the colours of its own slab test against the other bodies' k-DOPs of the
    // same k; drawn as the polytope its slabs bound (Klosowski et al. 1998).
    for (std::size_t i = 0; i < engine::kDrawnKdops.size(); ++i) {
        if (!options.draw.kdop[i]) continue;
        own_tests = true;
        const std::vector<collision::WorldKdop> kdops = worldKdops(world, engine::kDrawnKdops[i]);
        const std::vector<engine::BodyState> states = kdopOverlaps(world, kdops).states;
        for (std::size_t b = 0; b < kdops.size(); ++b) {
            debug.drawKdop(kdops[b], stateColor(states[b]));
        }
    }
}

}  // namespace render
