// engine/src/world_contacts.cpp -- the detail of the World's confirmed contacts (triangles,
// witnesses, depth), derived once per state on request, and drawing it: mesh hierarchy levels
// coloured by state and contact witnesses (as Box2D's b2World_Draw, the world decides what its
// debug drawing shows; a renderer only draws lines).
#include <algorithm>
#include <numeric>
#include <span>
#include <vector>

#include "engine/world.h"
#include "world_records.h"

namespace engine {

namespace {

bool finitePose(const Body& body) {
    return body.position.allFinite() && body.orientation.coeffs().allFinite();
}

// The body's hierarchy when it is a mesh that has one (the scene loader always builds one).
const collision::MeshBvh* meshTree(const Body& body) {
    const collision::Shape& s = body.shape;
    return s.type == collision::ShapeType::Mesh && s.mesh && s.bvh && finitePose(body) ? s.bvh.get()
                                                                                       : nullptr;
}

// Both bodies of the pair exist and have finite poses.
bool drawable(std::span<const Body> bodies, const collision::ProxyPair& p) {
    const auto ia = static_cast<std::size_t>(p.a);
    const auto ib = static_cast<std::size_t>(p.b);
    return ia < bodies.size() && ib < bodies.size() && finitePose(bodies[ia]) &&
           finitePose(bodies[ib]);
}

collision::Color nodeColor(collision::BvhNodeState state, const ContactDrawStyle& style) {
    switch (state) {
        case collision::BvhNodeState::Apart:
            return style.node_apart;
        case collision::BvhNodeState::Overlapping:
            return style.node_overlapping;
        case collision::BvhNodeState::Confirmed:
            return style.node_confirmed;
    }
    return style.contact;
}

}  // namespace

void World::computeDetails(bool convex_pairs, bool mesh_pairs) const {
    const bool do_convex = convex_pairs && !convex_details_;
    const bool do_mesh = mesh_pairs && !mesh_details_;
    if (!do_convex && !do_mesh) return;
    details_.resize(colliding_.size());
    for (std::size_t k = 0; k < colliding_.size(); ++k) {
        const Body& a = bodies_[static_cast<std::size_t>(colliding_[k].a)];
        const Body& b = bodies_[static_cast<std::size_t>(colliding_[k].b)];
        if (!finitePose(a) || !finitePose(b)) continue;
        const bool convex = a.shape.isConvex() && b.shape.isConvex();
        if (convex ? do_convex : do_mesh) {
            details_[k] = collision::pairContacts(a.shape, a.pose(), b.shape, b.pose());
        }
    }
    convex_details_ = convex_details_ || do_convex;
    mesh_details_ = mesh_details_ || do_mesh;
}

std::span<const collision::PairContacts> World::contactDetails() const {
    computeDetails(true, true);
    return details_;
}

Real World::deepestPenetration() const {
    computeDetails(true, false);
    Real deepest = 0;
    for (const collision::PairContacts& d : details_) deepest = std::max(deepest, d.penetration);
    return deepest;
}

void World::drawHierarchyLevels(collision::DebugDraw& draw, int depth,
                                const ContactDrawStyle& style) const {
    std::vector<collision::BvhLevel> levels(bodies_.size());
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
        if (const collision::MeshBvh* tree = meshTree(bodies_[i])) {
            levels[i] = collision::makeBvhLevel(*tree, depth);
        }
    }
    // colliding_ by (a, b), for the look-up of each flagged pair: the identity in sorted pair
    // order; in the broad phase's own order (settings().pair_order) sorted here, O(c log c) in
    // the confirmed pairs, for drawing only.
    std::vector<std::size_t> by_pair(colliding_.size());
    std::iota(by_pair.begin(), by_pair.end(), std::size_t(0));
    const auto pair_less = [this](std::size_t x, std::size_t y) {
        return colliding_[x] < colliding_[y];
    };
    if (!std::is_sorted(colliding_.begin(), colliding_.end())) {
        std::sort(by_pair.begin(), by_pair.end(), pair_less);
    }
    for (const collision::ProxyPair& p : flagged_) {
        if (!drawable(bodies_, p)) continue;
        const auto ia = static_cast<std::size_t>(p.a);
        const auto ib = static_cast<std::size_t>(p.b);
        const Body& a = bodies_[ia];
        const Body& b = bodies_[ib];
        const collision::MeshBvh* tree_a = meshTree(a);
        const collision::MeshBvh* tree_b = meshTree(b);
        if (!tree_a && !tree_b) continue;
        const auto it = std::lower_bound(
            by_pair.begin(), by_pair.end(), p,
            [this](std::size_t k, const collision::ProxyPair& key) { return colliding_[k] < key; });
        const collision::PairContacts* confirmed = nullptr;
        if (it != by_pair.end() && colliding_[*it] == p) {
            computeDetails(false, true);  // the mesh pairs' triangles; no convex contact() here
            confirmed = &details_[*it];
        }
        if (tree_a && tree_b) {
            if (!tree_a->sameVolumeType(*tree_b)) continue;
            collision::markBvhLevels(
                levels[ia], *tree_a, a.pose(), levels[ib], *tree_b, b.pose(),
                confirmed ? std::span<const collision::TrianglePair>(confirmed->triangle_pairs)
                          : std::span<const collision::TrianglePair>{});
        } else if (tree_a && b.shape.isConvex()) {
            collision::markBvhLevel(levels[ia], *tree_a, a.pose(), b.shape, b.pose(),
                                    confirmed ? std::span<const std::int32_t>(confirmed->triangles)
                                              : std::span<const std::int32_t>{});
        } else if (tree_b && a.shape.isConvex()) {
            collision::markBvhLevel(levels[ib], *tree_b, b.pose(), a.shape, a.pose(),
                                    confirmed ? std::span<const std::int32_t>(confirmed->triangles)
                                              : std::span<const std::int32_t>{});
        }
    }
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
        const Pose pose = bodies_[i].pose();
        for (std::size_t k = 0; k < levels[i].nodes.size(); ++k) {
            collision::drawBvhLevelNode(draw, levels[i].nodes[k], pose,
                                        nodeColor(levels[i].states[k], style));
        }
    }
}

void World::drawContacts(collision::DebugDraw& draw, const ContactDrawStyle& style) const {
    const std::span<const collision::PairContacts> details = contactDetails();
    for (std::size_t k = 0; k < colliding_.size(); ++k) {
        const collision::ProxyPair& p = colliding_[k];
        if (!drawable(bodies_, p)) continue;
        const Body& a = bodies_[static_cast<std::size_t>(p.a)];
        const Body& b = bodies_[static_cast<std::size_t>(p.b)];
        const Real size = std::min(a.local_bounds.sphere.radius, b.local_bounds.sphere.radius);
        const Real cross = style.cross_fraction * size;
        for (const collision::ContactWitness& w : details[k].witnesses) {
            for (const Vec3& point : {w.point_a, w.point_b}) {
                if (!point.allFinite()) continue;
                for (int axis = 0; axis < 3; ++axis) {
                    const Vec3 d = Vec3::Unit(axis) * cross;
                    draw.drawLine(point - d, point + d, style.contact);
                }
            }
            if (w.point_a.allFinite() && w.normal.allFinite()) {
                draw.drawLine(w.point_a, w.point_a + w.normal * (style.normal_fraction * size),
                              style.contact);
            }
        }
    }
}

}  // namespace engine
