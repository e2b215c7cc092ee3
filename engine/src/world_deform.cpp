// engine/src/world_deform.cpp -- the World's deforming mesh bodies (vertices moved, hierarchy
// refitted or rebuilt every step) and self-collision of mesh bodies (their own intersecting
// triangle pairs).
#include <memory>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "collision/assert.h"
#include "collision/bvh/bvh.h"
#include "collision/geometry/convex_hull.h"
#include "engine/world.h"
#include "stage_clock.h"
#include "world_records.h"

namespace engine {

namespace {

using Clock = StageClock;

// Sum of every node's volume over the root's volume, for the tree's volume type (0 for an empty
// tree or a root of zero volume). >= 1 for nested volumes; grows as a refit loosens the tree;
// a uniform scaling of the mesh leaves it unchanged.
template <class BV>
Real volumeRatioOf(const collision::MeshBvh& tree, Real& out) {
    const collision::Bvh<BV>* typed = nullptr;
    if constexpr (std::is_same_v<BV, collision::Obb>) {
        typed = collision::obbTreeOf(tree);  // obb, or the binary tree inside obb4
    } else {
        typed = collision::treeOf<BV>(tree);
    }
    if (typed != nullptr) {
        const auto& nodes = typed->nodes();
        Real sum = 0;
        for (const auto& n : nodes) sum += n.cost;
        out = !nodes.empty() && nodes.front().cost > 0 ? sum / nodes.front().cost : Real(0);
    }
    return out;
}

Real volumeRatio(const collision::MeshBvh& tree) {
    Real out = 0;
    std::apply([&](auto... bv) { (volumeRatioOf<decltype(bv)>(tree, out), ...); },
               collision::BvhVolumeTypes{});
    return out;
}

}  // namespace

// A deforming mesh body gets its own mesh and hierarchy (shapes from one file share theirs),
// placed at its deformation at the present time.
void World::addDeforming(BodyId id) {
    const Body& added = bodies_[static_cast<std::size_t>(id)];
    if (added.shape.type != collision::ShapeType::Mesh || !added.shape.mesh || !added.shape.bvh) {
        return;
    }
    DeformingMesh d;
    d.body = id;
    d.mesh = std::make_shared<collision::TriangleMesh>(*added.shape.mesh);
    d.rest = d.mesh->vertices;
    d.bvh = collision::buildMeshBvh(added.shape.bvh->volumeName(), *d.mesh);
    d.built_ratio = volumeRatio(*d.bvh);
    d.speed_bound = deformSpeedBound(*added.deform, d.rest);
    deforming_.push_back(std::move(d));
    deformBody(deforming_.back());
}

// Refit or rebuild (the rule after Lauterbach, Yoon, Tuft, Manocha, "RT-DEFORM: interactive
// ray tracing of dynamic scenes using BVHs", 2006: a refitted tree is kept while its quality is
// within a factor of its quality when built; here quality is the sum of node volumes over the
// root volume, which a uniform growth of the body leaves unchanged).
void World::deformBody(DeformingMesh& d) {
    Body& body = bodies_[static_cast<std::size_t>(d.body)];
    const Clock::time_point t = Clock::now();
    for (std::size_t k = 0; k < d.rest.size(); ++k) {
        d.mesh->vertices[k] = deformPoint(*body.deform, d.rest[k], time_);
    }
    stats_.refit_nodes += d.bvh->refit(*d.mesh);
    if (volumeRatio(*d.bvh) > settings_.rebuild_ratio * d.built_ratio) {
        d.bvh = collision::buildMeshBvh(d.bvh->volumeName(), *d.mesh);
        d.built_ratio = volumeRatio(*d.bvh);
        ++stats_.rebuilds;
    }
    stats_.refit_s += secondsSince(t);
    // The hull (support function, bounding volumes) and local bounds follow the new vertices.
    collision::ConvexHullOutput hull = collision::computeConvexHull(d.mesh->vertices);
    if (!hull.ok) {
        throw SimulationError("body '" + body.name + "': the deformed mesh has no convex hull at " +
                              "step " + std::to_string(step_count_) + " (" + hull.error + ")");
    }
    body.shape = collision::Shape::triangleMesh(
        d.mesh, std::make_shared<const collision::ConvexPolytope>(std::move(hull.hull)), d.bvh);
    body.local_bounds = collision::fitLocalBounds(body.shape);
}

void World::findSelfPairs() {
    stats_.self_pairs = 0;
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
        const Body& body = bodies_[i];
        if (!body.self_collision || body.shape.type != collision::ShapeType::Mesh ||
            !body.shape.bvh) {
            continue;
        }
        // The mesh's own hierarchy against itself, in the body frame (a rigid motion changes
        // nothing): the pairs are a property of the shape's current vertices.
        collision::BvhQueryStats counts;
        self_pairs_[i] = body.shape.bvh->intersectSelf(&counts);
        stats_.self_pairs += static_cast<std::int64_t>(self_pairs_[i].size());
        stats_.bv_tests += counts.bv_tests;
        stats_.triangle_tests += counts.triangle_tests;
    }
}

std::span<const collision::TrianglePair> World::selfPairs(BodyId id) const {
    CDLAB_ASSERT(id >= 0 && static_cast<std::size_t>(id) < self_pairs_.size(), "body id");
    return self_pairs_[static_cast<std::size_t>(id)];
}

}  // namespace engine
