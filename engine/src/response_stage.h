// engine/src/response_stage.h -- contact response (response: impulse), one stage of the step
// with its own state: the walls (the faces of the bounds), the pairs whose AABBs grown by the
// speculative margin overlap (from an instance of the scene's broad phase), the bodies near a
// wall, the sequential-impulse solver with its warm starts, and the split-impulse pseudo
// velocities it leaves for the position correction after the continuous stage.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "box_pair_finder.h"
#include "collision/broadphase/broad_phase.h"
#include "contact_solver.h"
#include "engine/body.h"
#include "engine/world.h"

namespace engine {

class ResponseStage {
public:
    /// Walls from `settings.bounds` with its restitution and friction; pairs from registry broad
    /// phase `settings.broad_phase`.
    explicit ResponseStage(const WorldSettings& settings);
    std::unique_ptr<ResponseStage> clone() const { return std::make_unique<ResponseStage>(*this); }

    /// Pairs from registry broad phase `name` from the next step on (BoxPairFinder::reset).
    void reset(const std::string& name) { finder_.reset(name); }

    /// Before integration: gravity as a velocity kick, then the solver on the grown pairs and
    /// the wall candidates of the bodies at their poses (`volumes` their exact volumes, as the
    /// last detection left them); the velocities it leaves are the ones the integrator uses.
    void solve(std::span<Body> bodies, std::span<const collision::ProxyVolumes> volumes,
               const WorldSettings& settings, Real dt);
    /// After the continuous stage: this step's pseudo velocities move the bodies; the momenta
    /// are not changed by them (L only turns with the body).
    void correctPositions(std::span<Body> bodies, Real dt) const;

    /// Contact points solved in the last step.
    int pointCount() const { return solver_.pointCount(); }
    /// The pair finder's counters and the candidate pairs of the last step.
    const collision::BroadPhaseCounters& pairCounters() const { return finder_.counters(); }
    std::int64_t pairCount() const { return std::int64_t(pairs_.size()); }
    /// Pairs the solver pushed apart in the last step (World::pushedPairs).
    std::span<const collision::ProxyPair> pushedPairs() const { return pushed_; }

private:
    /// The grown AABBs, their pairs (not both static; sorted) and the wall candidates.
    void findPairs(std::span<const Body> bodies, std::span<const collision::ProxyVolumes> volumes,
                   const collision::Aabb& bounds, Real margin_fraction);

    std::vector<Wall> walls_;
    BoxPairFinder finder_;
    ContactSolver solver_;
    std::vector<collision::Aabb> grown_;
    std::vector<collision::ProxyPair> pairs_;
    std::vector<WallCandidate> wall_candidates_;
    std::vector<collision::ProxyPair> pushed_;
    std::vector<Vec3> pseudo_linear_;
    std::vector<Vec3> pseudo_angular_;
};

}  // namespace engine
