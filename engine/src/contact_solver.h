// engine/src/contact_solver.h -- impulse-based contact response (private to the engine): a
// sequential-impulse solver over the manifolds of collision::contact() for the colliding pairs.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "collision/narrowphase/contact.h"
#include "collision/narrowphase/half_space.h"
#include "engine/body.h"

namespace engine {

/// A static wall (a face of the world's bounds): a half-space with a material of its own.
struct Wall {
    collision::HalfSpace plane;  ///< the solid side is dot(normal, x) <= offset
    Real restitution = 0;
    Real friction = 0;
};

/// A body that may touch a wall this step (its grown AABB reaches the wall's plane).
struct WallCandidate {
    std::uint32_t wall = 0;  ///< index into the walls
    BodyId body = 0;
};

/// The bodies as the solver indexes them: the world's bodies 0..n-1, then one static stand-in
/// per wall (n + w), so that every constraint is a pair of indices.
struct SolverBodies {
    std::span<const Body> bodies;
    const Body* wall = nullptr;  ///< a static body at the origin: infinite mass, no velocity
    std::size_t walls = 0;
    std::size_t size() const { return bodies.size() + walls; }
    const Body& operator[](std::size_t id) const { return id < bodies.size() ? bodies[id] : *wall; }
};

/// Solver parameters (the world's settings pass them through).
struct ContactSolverSettings {
    int velocity_iterations = 30;
    int position_iterations = 5;
    Real baumgarte = Real(0.2);  ///< fraction of the penetration removed per step (split impulse)
    /// Penetration left alone, relative to the smaller bounding radius of the pair.
    Real slop_fraction = Real(0.005);
    /// Pairs closer than this (relative to the smaller bounding radius) but not touching get
    /// speculative contacts, so resting bodies keep their contacts from step to step.
    Real margin_fraction = Real(0.02);
    /// Restitution applies only when the pair approaches faster than this (m/s); slower
    /// contacts come to rest instead of bouncing forever in tiny hops.
    Real restitution_threshold = Real(0.5);
    /// After the iterations, extra velocity and position passes (kShockPasses) in which the
    /// lower body of each contact (fewer contacts away from a static body) is held fixed
    /// (Guendelman, Bridson, Fedkiw 2003 §5, shock propagation), so a heavy body on a light one
    /// cannot squeeze it out of the stack: sequential impulses alone need thousands of
    /// iterations at a 1000:1 mass ratio.
    bool shock_propagation = true;
};

/// One frame's worth of contact constraints with warm starting across frames.
class ContactSolver {
public:
    /// A copy with the same warm starts and scratch (World::snapshot).
    std::unique_ptr<ContactSolver> clone() const { return std::make_unique<ContactSolver>(*this); }
    /// Builds the constraints of the candidate `pairs` (sorted; touching, penetrating, or closer
    /// than the margin: speculative) and of the bodies near `walls` (`wall_candidates` sorted
    /// by wall, then body; each wall a static body of restitution and friction of its own) at
    /// the bodies' present poses,
    /// warm-starts them from the previous call's accumulated impulses (same body pair, same
    /// witness features, nearest point within 10 % of the smaller body's radius), runs the
    /// velocity iterations (changing the momenta), then the split-impulse position iterations,
    /// whose pseudo velocities go to `pseudo_linear` / `pseudo_angular` (m/s, rad/s, world): the
    /// caller moves the bodies by them for one step only, so position correction adds no energy.
    /// `pseudo_linear` and `pseudo_angular` get one entry per body and wall (those of the walls
    /// stay zero).
    void solve(std::span<Body> bodies, std::span<const collision::ProxyPair> pairs,
               std::span<const Wall> walls, std::span<const WallCandidate> wall_candidates,
               Real dt, const ContactSolverSettings& settings, std::vector<Vec3>& pseudo_linear,
               std::vector<Vec3>& pseudo_angular);

    /// Contact points solved in the last call.
    int pointCount() const { return static_cast<int>(points_.size()); }
    /// The body pairs of the last solve with a positive normal impulse at some point (pushed
    /// apart, including speculative contacts not yet touching), sorted, each once; walls are
    /// not bodies and are left out.
    void pushedPairs(std::vector<collision::ProxyPair>& out) const;

private:
    struct Point {
        BodyId a = 0;
        BodyId b = 0;
        Vec3 ra = Vec3::Zero();  ///< contact point - centre of mass of a, world
        Vec3 rb = Vec3::Zero();
        Vec3 normal = Vec3::Zero();  ///< a towards b
        Vec3 t1 = Vec3::Zero();
        Vec3 t2 = Vec3::Zero();
        Real mass_n = 0;  ///< 1 / effective mass along the normal
        Real mass_t1 = 0;
        Real mass_t2 = 0;
        Real friction = 0;
        Real velocity_bias = 0;  ///< restitution target for the normal velocity
        Real depth = 0;
        Real slop = 0;
        Real impulse_n = 0;  ///< accumulated, >= 0
        Real impulse_t1 = 0;
        Real impulse_t2 = 0;
        Real pseudo_n = 0;            ///< accumulated split impulse, >= 0
        Vec3 local_a = Vec3::Zero();  ///< contact point in a's body frame (warm-start matching)
        collision::Feature feature_a;
        collision::Feature feature_b;
    };
    struct Velocities {
        Vec3 v = Vec3::Zero();
        Vec3 w = Vec3::Zero();
    };

    /// Appends the constraint points of one candidate pair (none when it is farther apart than
    /// the margin), warm-started from previous_.
    void addPairPoints(const SolverBodies& bodies, const collision::ProxyPair& pair,
                       const std::vector<Mat3>& inv_inertia, const std::vector<Velocities>& vel,
                       Real dt, const ContactSolverSettings& settings);
    /// The same for a body and a wall (the wall is a, index n + wall).
    void addWallPoints(const SolverBodies& bodies, const Wall& wall, BodyId wall_id, BodyId body,
                       const std::vector<Mat3>& inv_inertia, const std::vector<Velocities>& vel,
                       Real dt, const ContactSolverSettings& settings);
    /// The points of manifold `c` of a and b, found with b moved `shift` along the normal
    /// (speculative contacts: the shift is taken back here), with the pair's material.
    void addManifoldPoints(const SolverBodies& bodies, BodyId a_id, BodyId b_id,
                           collision::ContactOutput& c, Real shift, Real size, Real restitution,
                           Real friction, const std::vector<Mat3>& inv_inertia,
                           const std::vector<Velocities>& vel, Real dt,
                           const ContactSolverSettings& settings);
    /// The accumulated impulses of the nearest previous point of the same pair and features,
    /// within kMatchFraction * size; `range` the pair's previous points.
    static void warmStart(Point& p, Real size, std::span<const Point> range);

    /// The split-impulse position iterations, then their shock passes: pseudo velocities that
    /// remove baumgarte * (depth - slop) / dt of each penetration.
    void solvePositions(const SolverBodies& bodies, const std::vector<Mat3>& inv_inertia,
                        const std::vector<int>& level, const std::vector<std::size_t>& shock_order,
                        Real dt, const ContactSolverSettings& settings,
                        std::vector<Vec3>& pseudo_linear, std::vector<Vec3>& pseudo_angular);

    std::vector<Point> points_;
    std::vector<Point> previous_;  ///< last call's points, sorted by (a, b)
    std::size_t body_count_ = 0;   ///< bodies of the last call (walls come after them)
    Body wall_body_ = makeWallBody();
    static Body makeWallBody();
};

}  // namespace engine
