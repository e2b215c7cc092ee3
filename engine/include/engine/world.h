// engine/world.h -- bodies and time: the fixed step, bounds reflection, and the collision pipeline
// (bounding volumes -> broad phase -> narrow phase) whose results the renderer and dumps read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "collision/broadphase/broad_phase.h"
#include "collision/bvh/bvh.h"
#include "collision/bvh/bvh_level.h"
#include "collision/ccd/ccd.h"
#include "collision/debug_draw.h"
#include "collision/volumes/bounding_volumes.h"
#include "engine/body.h"
#include "engine/chain.h"
#include "engine/clone_ptr.h"
#include "engine/world_state.h"

namespace engine {

/// Time integrator of the step. State is (x, q, P, L); the only force is gravity and no torque
/// acts, so L (world frame) is constant and the gyroscopic term of Euler's equations is carried
/// by w = R I^-1 R^T L: |L| is conserved exactly by every integrator, they differ in x and q.
enum class Integrator : std::uint8_t {
    ExplicitEuler,      ///< x += v(t) dt, P += F dt, q += 1/2 w q dt then normalised (first order)
    SemiImplicitEuler,  ///< P first, x with the new v; q by the exact-rotation splitting (2nd
                        ///< order)
    Rk4,                ///< Runge-Kutta 4 on (x, P, q, L); unstable for thin fast-spinning bodies
};
std::string_view integratorName(Integrator integrator);  ///< scene name, e.g. "rk4"
/// Integrator by scene name; false when the name is unknown.
bool findIntegrator(std::string_view name, Integrator& out);
/// "explicit_euler, semi_implicit_euler, rk4", for error messages.
std::string integratorNames();

/// Continuous collision detection policy of the step (world.ccd in scene files).
enum class CcdMethod : std::uint8_t {
    Off,                      ///< discrete only: fast or thin bodies may tunnel; costs nothing
    ConservativeAdvancement,  ///< collision::timeOfImpact on every pair whose swept bounds meet
};
std::string_view ccdMethodName(CcdMethod method);  ///< "off", "conservative_advancement"
/// CCD method by scene name; false when the name is unknown.
bool findCcdMethod(std::string_view name, CcdMethod& out);
/// "off, conservative_advancement", for error messages.
std::string ccdMethodNames();

/// Time of impact of a sphere-sphere pair in the continuous stage (world.ccd_spheres).
enum class CcdSpheres : std::uint8_t {
    Advancement,  ///< collision::timeOfImpact like every other pair (iterative, tolerance)
    Exact,        ///< collision::timeOfImpactSphereSweeps: the closed-form root, one iteration
};
std::string_view ccdSpheresName(CcdSpheres method);  ///< "advancement", "exact"
/// By scene name; false when the name is unknown.
bool findCcdSpheres(std::string_view name, CcdSpheres& out);

/// Contact response of the step (world.response in scene files).
enum class Response : std::uint8_t {
    /// No contact solver: discrete contacts are detected only, so overlapping bodies pass
    /// through each other (the bounds still reflect). With ccd on, a pair the CCD stage stops
    /// at its time of impact while approaching still gets one elastic, frictionless impulse
    /// (restitution 1, the pair's own restitution ignored), so it bounces back instead of
    /// passing.
    None,
    /// Sequential impulses at contact() manifolds: restitution, friction, resting; the CCD
    /// stage's impulse uses the pair's restitution (the larger of the two), frictionless.
    Impulse,
};
std::string_view responseName(Response response);  ///< "none", "impulse"
bool findResponse(std::string_view name, Response& out);

/// A time of impact the CCD stage acted on in the last step: the pair was stopped at `t` (a
/// fraction of the step), `pose_a`/`pose_b` are the bodies' poses there, world frame.
struct ToiEvent {
    BodyId a = 0;
    BodyId b = 0;
    Real t = 0;
    Pose pose_a;
    Pose pose_b;
    Vec3 point = Vec3::Zero();   ///< m, world: midpoint of the witness points
    Vec3 normal = Vec3::Zero();  ///< unit, world, from a towards b
    bool failed = false;         ///< the query hit its iteration cap (t is then a safe time)
};

/// Overlap state of a body, the worst over its pairs.
enum class BodyState : std::uint8_t { Apart, Flagged, Colliding };
std::string_view bodyStateName(BodyState state);  ///< "apart", "flagged", "colliding"

/// The most candidate pairs one step may flag. Past it the step costs seconds and gigabytes
/// (20,000 coincident spheres flag 2e8 pairs: 130 s and 11 GB for frame 0), so the run stops
/// with a SimulationError; the scene loader refuses scenes whose bodies already overlap in more
/// pairs than this at the start (estimated from a sample, see scene.cpp).
inline constexpr std::size_t kMaxCandidatePairs = 10'000'000;

struct WorldSettings {
    /// m. With response: none bodies reflect off it (velocity flipped, elastic); with response:
    /// impulse its faces are static walls for the contact solver (restitution, friction).
    collision::Aabb bounds{Vec3::Constant(-10), Vec3::Constant(10)};
    Vec3 gravity = Vec3::Zero();      ///< m/s^2
    Real time_step = Real(1) / 60;    ///< s, > 0
    std::string broad_phase = "sap";  ///< registry name
    /// The order flaggedPairs() and collidingPairs() come in (scene key `pair_order`): sorted by
    /// (a, b) (default), or the broad phase's own order (collision::PairOrder::Found), which
    /// saves hgrid its final sort. Either way the same pairs, and the same list for the same run.
    /// The motion does not depend on it: the contact solver and the CCD stage get their pairs
    /// from instances of the same broad phase over boxes of their own, sorted.
    collision::PairOrder pair_order = collision::PairOrder::Sorted;
    /// Node volume of mesh bodies' hierarchies (collision::bvhVolumeNames()); scene key
    /// `world.mesh_bvh`. Read when mesh bodies are built (scene loading), not by the World.
    std::string mesh_bvh{collision::kDefaultMeshBvh};
    Integrator integrator = Integrator::SemiImplicitEuler;
    CcdMethod ccd = CcdMethod::Off;
    /// Acceptance tolerance of the continuous stage's time-of-impact queries, dimensionless: a
    /// fraction of the smaller bounding radius (about the local origin) of the pair's shapes.
    /// A pair is stopped once its gap is within target gap + this; looser stops earlier (never
    /// after first contact) with fewer iterations. Scene key `world.ccd_tolerance`, in (0, 1].
    Real ccd_tolerance = collision::kToiRelativeTolerance;
    /// Gap the continuous stage leaves between a pair stopped at its time of impact,
    /// dimensionless: a fraction of the smaller bounding radius of the two bodies, so the next
    /// step starts separated. Scene key `world.ccd_target_gap`, in [0, 1].
    Real ccd_target_gap = Real(1e-3);
    /// Sphere-sphere pairs of the continuous stage: advancement (default, as every pair) or
    /// the exact quadratic root. Scene key `world.ccd_spheres`.
    CcdSpheres ccd_spheres = CcdSpheres::Advancement;
    Response response = Response::None;
    /// Default of bodies that do not set theirs (scene files), and with response: impulse the
    /// material of the bounds' faces, which then act as static walls.
    Real restitution = Real(0.5);
    Real friction = Real(0.5);  ///< as restitution

    /// A step that flags more candidate pairs stops the run (SimulationError). Not a scene key:
    /// scenes get kMaxCandidatePairs; tests lower it.
    std::size_t max_candidate_pairs = kMaxCandidatePairs;
    /// A deforming mesh body's hierarchy is rebuilt instead of refitted when its quality ratio
    /// (sum of node volumes / root volume, MeshBvh::volumeRatio) exceeds this multiple of the
    /// ratio at its last build. Scene key `world.rebuild_ratio` (> 1).
    Real rebuild_ratio = Real(1.5);
};

/// Wall-clock time per stage of the last step, in seconds, and the broad phase's counters.
struct StepStats {
    double integrate_s = 0;
    double volumes_s = 0;
    double broad_phase_s = 0;
    double narrow_phase_s = 0;
    double ccd_s = 0;       ///< continuous stage (0 when ccd is off)
    double response_s = 0;  ///< contact solver (0 when response is none)
    double total_s = 0;
    collision::BroadPhaseCounters broad;
    std::int64_t narrow_tests = 0;
    std::int64_t triangle_tests = 0;  ///< triangle-level tests of the narrow phase (meshes)
    std::int64_t bv_tests = 0;        ///< mesh-hierarchy node tests of the narrow phase
    std::int64_t toi_queries = 0;     ///< timeOfImpact calls in the continuous stage
    std::int64_t toi_events = 0;      ///< pairs stopped at their time of impact
    std::int64_t toi_iterations = 0;  ///< iterations (distance queries / roots) of those calls
    std::int64_t contact_points = 0;  ///< manifold points the contact solver handled
    /// The contact and continuous stages' own instances of the scene's broad phase (over the
    /// boxes grown by the contact margin, and over the swept bounds): their counters, and the
    /// candidate pairs they kept (after the exact box filter). Zero for a stage that is off.
    collision::BroadPhaseCounters response_broad;
    std::int64_t response_pairs = 0;
    collision::BroadPhaseCounters ccd_broad;
    std::int64_t ccd_pairs = 0;
    /// Intersecting non-adjacent triangle pairs within self_collision mesh bodies (their
    /// traversals' node and triangle tests are in bv_tests and triangle_tests).
    std::int64_t self_pairs = 0;
    /// Deforming mesh bodies: hierarchy nodes refitted (the cost model's Nu), the time of moving
    /// their vertices and refitting (and rebuilding) their hierarchies, and the rebuilds.
    std::int64_t refit_nodes = 0;
    double refit_s = 0;
    std::int64_t rebuilds = 0;
};

class BoxPairFinder;
class ResponseStage;
// The World's private per-body records (engine/src/world_records.h).
struct SweptBody;
struct LinkOf;
struct ChainState;
struct DeformingMesh;

/// Colours and sizes of World::drawHierarchyLevels and World::drawContacts: the caller's palette.
struct ContactDrawStyle {
    collision::Color node_apart;  ///< hierarchy nodes by collision::BvhNodeState
    collision::Color node_overlapping;
    collision::Color node_confirmed;
    collision::Color contact;  ///< witness crosses and normals
    /// Cross half-length and normal length, as fractions of the pair's smaller bounding radius.
    Real cross_fraction = Real(0.06);
    Real normal_fraction = Real(0.5);
};

/// The state left what double precision represents: a body's position, orientation or momentum
/// is no longer finite. what() names the body, the quantity and the step; the world is left as
/// it was after the step that broke it, and stepping it further is meaningless.
class SimulationError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

class World;

/// A world's whole state between two steps (World::snapshot): bodies, time and step count, the
/// broad phase with its coherence state, the contact and continuous stages' pair finders, the
/// solver's warm starts, the chains' clocks, the deforming meshes and their hierarchies, the last
/// step's pairs, states, events and counters. Immutable; copies share it.
class WorldSnapshot {
public:
    /// Holds nothing: World::restore refuses it.
    WorldSnapshot() = default;
    bool empty() const { return world_ == nullptr; }
    Real time() const;          ///< the world's time() when taken
    std::int64_t steps() const;  ///< the world's stepCount() when taken

private:
    friend class World;
    std::shared_ptr<const World> world_;
};

class World {
public:
    /// Throws std::invalid_argument when the broad phase name is unknown.
    explicit World(WorldSettings settings);
    ~World();
    World(World&&) noexcept;
    World& operator=(World&&) noexcept;

    /// The whole state now, between steps. restore() of it and then step() give bit-identical
    /// states, pairs, results and counters (so frames and HUDs) to never having stopped. Costs a
    /// copy of every body, volume, broad-phase structure and stage's scratch.
    WorldSnapshot snapshot() const;
    /// Puts this world in the state `snapshot` holds (taken of this world, or of another made
    /// from the same scene: it replaces everything, settings and bodies too). Throws
    /// std::invalid_argument for an empty snapshot.
    void restore(const WorldSnapshot& snapshot);

    /// Time, step count, every body's motion and every chain's clock now.
    WorldState state() const;
    /// Shows `state` (taken of a world made from the same scene): puts its time, motion and
    /// clocks in place, moves deforming meshes to its time, detects, and then reports `impacts`
    /// as the last step's times of impact and `reported`, when given, as its statistics (else
    /// the detection's): the recorded step's events and counters, which a frame and a HUD show.
    /// Volumes, pairs, overlap states and contacts are then those of the recorded state with
    /// this world's broad phase, so stateHash() is the recorded hash when it is the recorded
    /// broad phase (or one testing the same volume kind). A deforming mesh's hierarchy is refitted from wherever it was, so its nodes
    /// may differ from the recorded run's (its triangles, hull and pairs do not). Stepping on
    /// from a placed world is not the recorded run's continuation. Throws std::invalid_argument
    /// when the body or chain count is not this world's.
    void place(const WorldState& state, std::span<const ToiEvent> impacts = {},
               const std::optional<StepStats>& reported = std::nullopt);

    BodyId addBody(Body body);
    /// Adds a chain whose links are bodies already added (ChainSpec::links, each in one chain
    /// only): makes them kinematic (Body::kinematic, static: infinite mass, zero momenta) and
    /// places them at the chain's frames at time(). Every step sets them to the frames at the
    /// step's end time (world_chains.cpp). Throws std::invalid_argument on a bad spec.
    void addChain(ChainSpec chain);

    /// One time step: integrate (settings().integrator); with ccd on, stop every pair at its time
    /// of impact (see world.cpp); reflect off the bounds; then detect. Throws SimulationError,
    /// before any volume is updated, when a body's state is no longer finite (so NaN and inf never
    /// reach the broad phase).
    void step();
    /// Recomputes volumes, pairs and states at the current state, without moving anything.
    void detect();
    /// Replaces the broad phase (state kept; it writes in settings().pair_order) and, once the
    /// world has been detected, detects again on the current state, so flaggedPairs(), states()
    /// and the structure drawn are the new broad phase's; throws std::invalid_argument on an
    /// unknown name.
    void setBroadPhase(const std::string& name);

    const WorldSettings& settings() const { return settings_; }
    std::span<const Body> bodies() const { return bodies_; }
    std::span<const collision::ProxyVolumes> volumes() const { return volumes_; }
    std::span<const BodyState> states() const { return states_; }
    /// Pairs whose volumes overlap according to the broad phase (a < b, each once), in
    /// settings().pair_order: sorted by default.
    std::span<const collision::ProxyPair> flaggedPairs() const { return flagged_; }
    /// Flagged pairs the narrow phase confirmed (touching or penetrating), in flaggedPairs()
    /// order (so sorted by default).
    std::span<const collision::ProxyPair> collidingPairs() const { return colliding_; }
    /// Pairs the contact solver pushed apart in the last step (a positive normal impulse, which
    /// includes speculative contacts that had not touched yet), sorted; empty without response.
    std::span<const collision::ProxyPair> pushedPairs() const;
    const collision::BroadPhase& broadPhase() const { return *broad_phase_; }
    const StepStats& lastStats() const { return stats_; }
    /// Times of impact acted on in the last step, sorted by (t, a, b); empty when ccd is off.
    std::span<const ToiEvent> toiEvents() const { return toi_events_; }
    /// Body `id`'s own intersecting triangle pairs at the current state (mesh triangle indices,
    /// a < b, sorted; triangles sharing a vertex index excluded); empty unless the body is a mesh
    /// with self_collision. Asserts a valid id.
    std::span<const collision::TrianglePair> selfPairs(BodyId id) const;
    Real time() const { return time_; }
    std::int64_t stepCount() const { return step_count_; }
    std::span<const ChainSpec> chains() const { return chains_; }
    /// The time (s) chain `chain`'s links are posed at: time() while it runs; once halted
    /// (on_impact: stop), the time of impact it halted at. Asserts a valid index.
    Real chainTime(std::size_t chain) const;
    /// The chain halted at a time of impact (on_impact: stop).
    bool chainHalted(std::size_t chain) const;
    /// False only for a parent-child pair of links of a chain without collide_adjacent: such a
    /// pair is never flagged, tested, coloured or stopped.
    bool pairAllowed(BodyId a, BodyId b) const;

    /// FNV-1a over the bit patterns of every body's state: equal hashes = bit-identical states.
    std::uint64_t stateHash() const;

    /// The detail of every colliding pair, in collidingPairs() order: confirmed triangles,
    /// witnesses and depth (collision::pairContacts). Derived by the narrow phase's own queries
    /// the first time it is asked for after a step or detect(), then kept until the next one, so
    /// every reader (drawing, the sweep) shares one computation. Not thread-safe.
    std::span<const collision::PairContacts> contactDetails() const;
    /// The deepest penetration over the colliding pairs of two convex shapes (contact()), 0 when
    /// none; computes only those pairs' details.
    Real deepestPenetration() const;
    /// Draws every mesh body's hierarchy cut at `depth` (draw.bvh_depth), each node coloured by
    /// its highest state over the flagged pairs: Overlapping where its volume overlaps the other
    /// body's (collision::markBvhLevels, markBvhLevel), Confirmed where its subtree holds a
    /// confirmed triangle (contactDetails()). A flagged pair is not confirmed when its bounding
    /// volumes overlap but its shapes do not; a pair not flagged leaves its nodes Apart even if a
    /// node's volume reaches outside the body's bounding volume.
    void drawHierarchyLevels(collision::DebugDraw& draw, int depth,
                             const ContactDrawStyle& style) const;
    /// Draws the witnesses of every colliding pair (draw.contacts): a cross at each witness point
    /// and the normal from A's, sized by the smaller body so the marks stay on the pair.
    void drawContacts(collision::DebugDraw& draw, const ContactDrawStyle& style) const;
    /// Draws every chain's skeleton at its clock: a line from each link's parent frame origin
    /// (the base's for a root link) to its own frame origin, the joint; zero lengths skipped.
    void drawChainSkeletons(collision::DebugDraw& draw, const collision::Color& color) const;

private:
    // Copies are snapshots' business: a plain copy would share the deforming meshes, which a step
    // changes in place (ownDeformingGeometry gives the copy its own).
    World(const World&);
    World& operator=(const World&);
    void ownDeformingGeometry();
    void integrate(Real dt, const Vec3& gravity);
    void integrateExplicitEuler(Real dt, const Vec3& gravity);
    void integrateSemiImplicitEuler(Real dt, const Vec3& gravity);
    void integrateRk4(Real dt, const Vec3& gravity);
    void reflectOffBounds();
    void checkFiniteState() const;
    void updateVolumes();
    void updateVolume(std::size_t i);
    // The continuous stage (world_continuous.cpp), in its order.
    void resolveContinuous();
    void buildSweeps();
    void queryTimesOfImpact();
    void stopAtImpacts();
    void applyImpactImpulses();
    void runCollisionPipeline();
    void findSelfPairs();  // self_collision mesh bodies: self_pairs_ and stats_
    /// Derives the contact details of the colliding pairs of two convex shapes and/or of the
    /// pairs with a mesh, each group at most once per state.
    void computeDetails(bool convex_pairs, bool mesh_pairs) const;

    WorldSettings settings_;
    std::vector<Body> bodies_;
    std::vector<collision::ProxyVolumes> volumes_;
    std::vector<BodyState> states_;
    std::vector<collision::ProxyPair> flagged_;
    std::vector<collision::ProxyPair> colliding_;
    ClonePtr<collision::BroadPhase> broad_phase_;
    // Chains (world_chains.cpp): links to their frames at the end of the step, the parent-child
    // pairs dropped, the links' swept bounds and articulated times of impact, halting.
    void moveChains();
    void dropExcludedPairs(std::vector<collision::ProxyPair>& pairs) const;
    void sweepLink(std::size_t i, SweptBody& s) const;
    void queryLinkImpact(const collision::ProxyPair& pair);
    /// The event of a Hit or Failed query of `pair` at the poses of its time
    /// (world_continuous.cpp).
    static ToiEvent impactEvent(const collision::ProxyPair& pair, const collision::ToiOutput& out,
                                const Pose& pose_a, const Pose& pose_b);
    void stopChainsAtImpacts();
    /// Velocity (m/s) of the material point at world `point` of body `id` at step fraction `s`
    /// if it is a link of a chain moving in this step, else zero.
    Vec3 linkPointVelocity(BodyId id, const Vec3& point, Real s) const;
    void poseChain(std::size_t c, Real t);  ///< the links of chain c at its time t
    std::vector<ChainSpec> chains_;
    std::vector<ChainState> chain_state_;
    std::vector<LinkOf> link_of_;        ///< per body; shorter than bodies_ past the last link
    mutable std::vector<Pose> frames_;   ///< chainFrames scratch
    mutable std::vector<Pose> frames2_;  ///< second scratch (finite differences)
    std::vector<Pose> step_start_;
    std::vector<Vec3> step_rotation_;  ///< semi-implicit Euler's rotation of the step (ccd on)
    std::vector<Vec3> step_spin_;
    std::vector<SweptBody> swept_;  ///< continuous stage scratch, reused across steps
    std::vector<collision::Aabb> swept_boxes_;  ///< swept_[i].box, contiguous for ccd_finder_
    ClonePtr<BoxPairFinder> ccd_finder_;  ///< only with ccd on
    std::vector<collision::ProxyPair> ccd_pairs_;
    std::vector<ToiEvent> toi_events_;
    std::vector<std::vector<collision::TrianglePair>> self_pairs_;  ///< per body
    std::vector<DeformingMesh> deforming_;
    void addDeforming(BodyId id);            // addBody of a deforming mesh body: its own geometry
    void deformBody(DeformingMesh& d);       // vertices at time_, refit or rebuild, hull, bounds
    ClonePtr<ResponseStage> response_;  ///< only with response: impulse
    StepStats stats_;
    // contactDetails(): derived on request, dropped by the next collision pipeline run.
    mutable std::vector<collision::PairContacts> details_;
    mutable bool convex_details_ = false;  ///< details_ holds the convex pairs' details
    mutable bool mesh_details_ = false;    ///< details_ holds the mesh pairs' details
    Real time_ = 0;
    std::int64_t step_count_ = 0;
    bool proxies_inserted_ = false;
};

}  // namespace engine
