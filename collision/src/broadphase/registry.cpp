// collision/src/broadphase/registry.cpp -- the broad-phase registry: one row per broad phase.
// The scene loader, the CLI and the differential tests all read this table.
#include "collision/broadphase/broad_phase.h"

#include <string>

#include "collision/debug_draw.h"

#include "broadphase/brute.h"
#include "broadphase/cullide.h"
#include "broadphase/grid.h"
#include "broadphase/hgrid.h"
#include "broadphase/obb.h"
#include "broadphase/octree.h"
#include "broadphase/sap.h"
#include "broadphase/sap1.h"
#include "broadphase/sap_packed.h"
#include "broadphase/sphere.h"
#include "broadphase/tree.h"

namespace collision {

ProxyVolumes volumesOfBox(const Aabb& box) {
    ProxyVolumes v;
    v.aabb = box;
    v.sphere.center = v.obb.center = box.center();
    v.obb.half_extents = box.extents() / 2;
    v.obb.axes = Mat3::Identity();
    v.sphere.radius = v.obb.half_extents.norm();
    return v;
}

void BroadPhase::insertBoxes(ProxyId first, std::span<const Aabb> boxes) {
    for (std::size_t i = 0; i < boxes.size(); ++i) {
        insert(first + static_cast<ProxyId>(i), volumesOfBox(boxes[i]));
    }
}

void BroadPhase::moveBoxes(ProxyId first, std::span<const Aabb> boxes) {
    for (std::size_t i = 0; i < boxes.size(); ++i) {
        move(first + static_cast<ProxyId>(i), volumesOfBox(boxes[i]));
    }
}

void BroadPhase::draw(DebugDraw& draw, const Aabb& /*bounds*/) const {
    draw.legend(std::string(name()) + ": no structure of its own to draw", kStructurePalette[0]);
}

namespace {

using Brute = BruteForceBroadPhase;

const BroadPhaseEntry kRegistry[] = {
    {"brute", "all pairs of AABBs (reference)", VolumeKind::Aabb, "brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<Brute>(VolumeKind::Aabb); }},
    {"sphere", "bounding spheres, pruned by a sort along x", VolumeKind::Sphere, "sphere-brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<SphereBroadPhase>(); }},
    {"sphere-brute", "all pairs of bounding spheres (reference)", VolumeKind::Sphere,
     "sphere-brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<Brute>(VolumeKind::Sphere); }},
    {"sap", "sweep-and-prune on AABBs, insertion-sort coherence (I-COLLIDE)", VolumeKind::Aabb,
     "brute", []() -> std::unique_ptr<BroadPhase> { return std::make_unique<SweepAndPrune>(); }},
    {"sap1", "single-axis sort and sweep, axis of greatest spread, insertion-sort coherence",
     VolumeKind::Aabb, "brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<SortAndSweep1>(); }},
    {"sap-packed",
     "box pruning: one sort on min x, float bounds rounded outward, SSE2 y/z test, exact confirm",
     VolumeKind::Aabb, "brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<PackedSweepAndPrune>(); }},
    {"grid", "uniform grid over the bodies, cell size from the median body size", VolumeKind::Aabb,
     "brute",
     []() -> std::unique_ptr<BroadPhase> {
         return std::make_unique<GridBroadPhase>(GridBroadPhase::Mode::Dense);
     }},
    {"hash", "spatial hash: unbounded uniform grid of hashed cells", VolumeKind::Aabb, "brute",
     []() -> std::unique_ptr<BroadPhase> {
         return std::make_unique<GridBroadPhase>(GridBroadPhase::Mode::Hashed);
     }},
    {"hgrid", "hierarchical hash grid (Mirtich TR-97-23 §2.2)", VolumeKind::Aabb, "brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<HierarchicalGrid>(); }, 1, false,
     /*found_order=*/true},
    {"hgrid2", "hgrid on two threads (a helper thread from 4096 proxies; same pairs)",
     VolumeKind::Aabb, "brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<HierarchicalGrid>(true); }, 2,
     false, /*found_order=*/true},
    {"hgrid-levels",
     "hgrid always on its level hierarchy, a level per size class (never planned down to one)",
     VolumeKind::Aabb, "brute",
     []() -> std::unique_ptr<BroadPhase> {
         return std::make_unique<HierarchicalGrid>(false, PairOrder::Sorted,
                                                   HierarchicalGrid::LevelPlan::Hierarchy);
     },
     1, false, /*found_order=*/true},
    {"tree", "dynamic AABB tree: fat leaves, SAH insertion, rotations", VolumeKind::Aabb, "brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<DynamicAabbTree>(); }},
    {"octree", "loose octree (k = 2)", VolumeKind::Aabb, "brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<LooseOctree>(); }},
    {"cullide",
     "CULLIDE: AABBs fully visible in an occlusion-query pass are pruned, exact AABB pairs among "
     "the rest (needs render's OSMesa context)",
     VolumeKind::Aabb, "brute", createCullide, 1, true},
    {"obb", "OBB separating-axis test after a sweep over the OBBs' AABBs", VolumeKind::Obb,
     "obb-brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<ObbBroadPhase>(); }},
    {"obb-brute", "all pairs of OBBs, separating-axis test (reference)", VolumeKind::Obb,
     "obb-brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<Brute>(VolumeKind::Obb); }},
};

}  // namespace

std::string_view pairOrderName(PairOrder order) {
    return order == PairOrder::Found ? "found" : "sorted";
}

std::optional<PairOrder> findPairOrder(std::string_view name) {
    if (name == "sorted") return PairOrder::Sorted;
    if (name == "found") return PairOrder::Found;
    return std::nullopt;
}

std::string pairOrderNames() { return "sorted, found"; }

std::span<const BroadPhaseEntry> broadPhaseRegistry() { return kRegistry; }

const BroadPhaseEntry* findBroadPhase(std::string_view name) {
    for (const BroadPhaseEntry& e : kRegistry) {
        if (e.name == name) return &e;
    }
    return nullptr;
}

std::string broadPhaseNames() {
    std::string out;
    for (const BroadPhaseEntry& e : kRegistry) {
        if (!out.empty()) out += ", ";
        out += e.name;
    }
    return out;
}

}  // namespace collision
