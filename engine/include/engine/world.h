// engine/world.h -- bodies and time: the fixed step, bounds reflection, and the collision pipeline
// (bounding volumes -> broad phase -> narrow phase) whose results the renderer and dumps read.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "collision/bounding_volumes.h"
#include "collision/broad_phase.h"
#include "collision/bvh.h"
#include "engine/body.h"

namespace engine {

/// Overlap state of a body, the worst over its pairs.
enum class BodyState : std::uint8_t { Apart, Flagged, Colliding };
std::string_view bodyStateName(BodyState state);  ///< "apart", "flagged", "colliding"

struct WorldSettings {
    collision::Aabb bounds{Vec3::Constant(-10), Vec3::Constant(10)};  ///< m; bodies reflect off it
    Vec3 gravity = Vec3::Zero();   ///< m/s^2
    Real time_step = Real(1) / 60; ///< s, > 0
    std::string broad_phase = "sap";  ///< registry name
    /// Node volume of mesh bodies' hierarchies (collision::bvhVolumeNames()); scene key
    /// `world.mesh_bvh`. Read when mesh bodies are built (scene loading), not by the World.
    std::string mesh_bvh{collision::kDefaultMeshBvh};
};

/// Wall-clock time per stage of the last step, in seconds, and the broad phase's counters.
struct StepStats {
    double integrate_s = 0;
    double volumes_s = 0;
    double broad_phase_s = 0;
    double narrow_phase_s = 0;
    double total_s = 0;
    collision::BroadPhaseCounters broad;
    std::int64_t narrow_tests = 0;
    std::int64_t triangle_tests = 0;  ///< triangle-level tests of the narrow phase (meshes)
    std::int64_t bv_tests = 0;        ///< mesh-hierarchy node tests of the narrow phase
};

class World {
public:
    /// Throws std::invalid_argument when the broad phase name is unknown.
    explicit World(WorldSettings settings);
    ~World();
    World(World&&) noexcept;
    World& operator=(World&&) noexcept;

    BodyId addBody(Body body);

    /// One time step: integrate (semi-implicit Euler), reflect off the bounds, then detect.
    void step();
    /// Recomputes volumes, pairs and states at the current state, without moving anything.
    void detect();
    /// Replaces the broad phase (state kept); throws std::invalid_argument on an unknown name.
    void setBroadPhase(const std::string& name);

    const WorldSettings& settings() const { return settings_; }
    std::span<const Body> bodies() const { return bodies_; }
    std::span<const collision::ProxyVolumes> volumes() const { return volumes_; }
    std::span<const BodyState> states() const { return states_; }
    /// Pairs whose volumes overlap according to the broad phase (sorted, a < b).
    std::span<const collision::ProxyPair> flaggedPairs() const { return flagged_; }
    /// Flagged pairs the narrow phase confirmed (touching or penetrating), sorted.
    std::span<const collision::ProxyPair> collidingPairs() const { return colliding_; }
    const collision::BroadPhase& broadPhase() const { return *broad_phase_; }
    const StepStats& lastStats() const { return stats_; }
    Real time() const { return time_; }
    std::int64_t stepCount() const { return step_count_; }

    /// FNV-1a over the bit patterns of every body's state: equal hashes = bit-identical states.
    std::uint64_t stateHash() const;

private:
    void integrate(Real dt);
    void reflectOffBounds();
    void updateVolumes();
    void runCollisionPipeline();

    WorldSettings settings_;
    std::vector<Body> bodies_;
    std::vector<collision::ProxyVolumes> volumes_;
    std::vector<BodyState> states_;
    std::vector<collision::ProxyPair> flagged_;
    std::vector<collision::ProxyPair> colliding_;
    std::unique_ptr<collision::BroadPhase> broad_phase_;
    StepStats stats_;
    Real time_ = 0;
    std::int64_t step_count_ = 0;
    bool proxies_inserted_ = false;
};

}  // namespace engine
