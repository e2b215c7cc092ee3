// collision/src/broad_phase.cpp -- the broad-phase registry: one row per broad phase.
// The scene loader, the CLI and the differential tests all read this table.
#include "collision/broad_phase.h"

#include "broad_phase_brute.h"
#include "broad_phase_sap.h"
#include "broad_phase_sphere.h"

namespace collision {

namespace {

using Brute = BruteForceBroadPhase;

const BroadPhaseEntry kRegistry[] = {
    {"brute", "all pairs of AABBs (reference)", "aabb", "brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<Brute>(Brute::Volume::Aabb); }},
    {"sphere", "bounding spheres, pruned by a sort along x", "sphere", "sphere-brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<SphereBroadPhase>(); }},
    {"sphere-brute", "all pairs of bounding spheres (reference)", "sphere", "sphere-brute",
     []() -> std::unique_ptr<BroadPhase> {
         return std::make_unique<Brute>(Brute::Volume::Sphere);
     }},
    {"sap", "sweep-and-prune on AABBs, insertion-sort coherence (I-COLLIDE)", "aabb", "brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<SweepAndPrune>(); }},
    {"obb-brute", "all pairs of OBBs, separating-axis test (reference)", "obb", "obb-brute",
     []() -> std::unique_ptr<BroadPhase> { return std::make_unique<Brute>(Brute::Volume::Obb); }},
};

}  // namespace

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
