// engine/src/scene_parser.h -- the scene loader's insides (private to engine): the limits a
// scene must stay within, the YAML helpers that check every value where it is read, and
// SceneParser, whose parts live in scene_parser.cpp (reading, overrides), scene_settings.cpp
// (world, output, camera, draw), scene_bodies.cpp (bodies, meshes, repeat) and scene_expect.cpp
// (expectations).
#pragma once

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <initializer_list>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

#include "engine/mass_properties.h"
#include "engine/mesh_import.h"
#include "engine/scene.h"

namespace engine::scene_parsing {

namespace fs = std::filesystem;

using collision::Shape;
using collision::ShapeType;

// A unit quaternion is recovered from wxyz only when its length is clearly non-zero.
inline constexpr Real kMinQuaternionNorm = Real(1e-6);

// `up` and the view direction count as parallel when the sine of their angle is below this.
inline constexpr Real kMinUpSine = Real(1e-6);

// Zero-volume boxes (allowed, with an explicit mass) keep every principal moment at least
// m (kMinGyrationFraction L)^2, L = largest half extent (at least 1 mm), so I stays invertible.
inline constexpr Real kMinGyrationFraction = Real(1e-3);

inline constexpr std::string_view kBodyKeys[] = {
    "name",  "shape",    "radius",           "half_height", "half_extents", "file",
    "scale", "position", "orientation_wxyz", "euler_deg",   "velocity",     "angular_velocity",
    "mass",  "density",  "repeat",           "static",      "restitution",  "friction",
    "inertia", "self_collision", "deform"};

inline constexpr std::string_view kRepeatKeys[] = {
    "count", "seed", "region", "speed", "spin", "random_orientation", "separated"};

// `repeat` with separated: true (the default) draws at most this many random centres for an
// entry of n bodies before it gives up: 100 n on average plus a reserve for the last, hardest
// places (random sequential addition slows down sharply near its jamming limit).
inline constexpr std::int64_t kRepeatAttemptsPerBody = 100;
inline constexpr std::int64_t kRepeatAttemptsReserve = 1000000;
// The volume fraction beyond which separated `repeat` placement is refused without trying.
inline constexpr double kMaxRepeatPacking = 0.5;

// Keys that `repeat` generates itself.
inline constexpr std::string_view kGeneratedKeys[] = {"position", "velocity", "angular_velocity",
                                               "orientation_wxyz", "euler_deg"};

inline constexpr int kMaxRepeat = 1000000;

// Bodies in a whole scene, however they are written (a 1.7 KB file aliasing one 10^6-body
// `repeat` 200 times asked for 2e8 bodies and ran out of memory at 5.9 GB): refused before the
// bodies are made.
inline constexpr std::size_t kMaxBodies = 1000000;

// Magnitudes double precision can integrate. Coordinates of the bounds stay within 1e150, so a
// squared distance between two points of the world (at most 3 (2e150)^2 = 1.2e301) is finite.
// In one step a body may cross at most kMaxTravelPerStep world diagonals (|v| dt, and |g| dt^2
// for gravity) and turn at most kMaxTurnPerStep radians (|w| dt): beyond, reflection and the
// broad phases see meaningless jumps and kinetic energies approach overflow. These refuse the
// absurd (1e308 m/s in a 20 m world) at its line; the world also checks its state every step.
inline constexpr Real kMaxWorldCoordinate = Real(1e150);

inline constexpr Real kMaxTravelPerStep = Real(1e6);

inline constexpr Real kMaxTurnPerStep = Real(1e3);

inline constexpr Real kMinMeshScale = Real(1e-50);

inline constexpr Real kMaxMeshScale = Real(1e50);

// Upper bounds of a run's length: larger values are typing mistakes, not experiments.
inline constexpr int kMaxStepsPerFrame = 100000;

inline constexpr int kMaxFrames = 1000000;

// Steps per second of simulated time when a scene gives neither time_step nor steps_per_frame.
inline constexpr int kDefaultMaxStepRate = 60;

struct Entry {
    std::string key;
    YAML::Node key_node;
    YAML::Node value;
};

// The values of one `bodies` entry as read and checked, before its shape is built.
struct BodyValues {
    std::string name;
    Vec3 position = Vec3::Zero();
    Quat orientation = Quat::Identity();
    Vec3 velocity = Vec3::Zero();
    Vec3 angular_velocity = Vec3::Zero();
    Real radius = 0;
    Real half_height = 0;
    Vec3 half_extents = Vec3::Zero();
    Real scale = 1;
    const Entry* file_entry = nullptr;
    const Entry* mass_entry = nullptr;
    const Entry* density_entry = nullptr;
    const Entry* inertia_entry = nullptr;  ///< `inertia:` given (with `mass:`)
    Mat3 inertia = Mat3::Zero();           ///< kg m^2 about the centre of mass, body frame
    Real mass = 0;
    Real density = 1000;
    bool is_static = false;
    Real restitution = 0;
    Real friction = 0;
};

// Geometry imported for hull and mesh bodies: re-centred shape and its properties at density 1.
/// A body entry's `repeat:` as read: how many copies, where and how fast.
struct RepeatSpec {
    int count = 0;
    std::uint64_t seed = 1;
    collision::Aabb region;       ///< where the centres are drawn (default: the world bounds)
    Real speed = 0;               ///< m/s, upper bound of each body's speed
    Real spin = 0;                ///< rad/s, upper bound of each body's angular speed
    bool random_orientation = true;
    /// Redraw a centre until the body's bounding sphere is apart from every body placed before
    /// it (this entry's and earlier entries'), so that nothing overlaps at frame 0.
    bool separated = true;
    YAML::Node node;              ///< the `repeat:` mapping, for errors
};

struct PreparedShape {
    Shape shape;
    MassProperties unit;  // mass = volume
    /// Mesh: its boundary edges (0: closed). An open mesh's `unit` is its convex hull's.
    std::int64_t boundary_edges = 0;
    /// Mesh: why its own volume gives no mass properties although it is closed (inward, no
    /// volume), or "". Then `unit` is its hull's and only `mass` + `inertia` make it a body.
    std::string volume_error;
};

class SceneParser {
    friend class ExpectReader;  // scene_expect.cpp: reads through fail() and the typed reads
    friend class EventReader;   // scene_events.cpp: the same

public:
    SceneParser(std::string display_name, fs::path base_dir)
        : file_(std::move(display_name)), base_dir_(std::move(base_dir)) {}

    Scene parse(const std::string& text);
    /// A document with the key `events:` and an optional `expect:`, read against `scene`
    /// (scene_events.cpp).
    EventTrack parseEventsDocument(const std::string& text, const Scene& scene) const;
    /// A document holding one set of commands (a mapping), read against `scene`.
    DemoCommands parseCommandsDocument(const std::string& text, const Scene& scene) const;
    void setOverrides(std::vector<SceneOverride> overrides) { overrides_ = std::move(overrides); }

private:
    [[noreturn]] void fail(const YAML::Mark& mark, const std::string& path,
                           const std::string& what) const;
    /// At a node; one that came from an override's value is reported as the option that set
    /// it (`FILE: --set KEY=VALUE: path: what`), since its line and column are not the file's.
    [[noreturn]] void fail(const YAML::Node& node, const std::string& path,
                           const std::string& what) const;
    [[noreturn]] void failOverride(const SceneOverride& o, const std::string& path,
                                   const std::string& what) const;

    std::vector<Entry> entries(const YAML::Node& map, const std::string& path,
                               std::initializer_list<std::string_view> allowed) const;
    std::vector<Entry> entries(const YAML::Node& map, const std::string& path,
                               const std::vector<std::string_view>& allowed) const;
    const Entry* find(const std::vector<Entry>& es, std::string_view key) const;
    const Entry& require(const std::vector<Entry>& es, std::string_view key,
                         const YAML::Node& parent, const std::string& path) const;

    Real readReal(const YAML::Node& n, const std::string& path) const;
    int readInt(const YAML::Node& n, const std::string& path) const;
    bool readBool(const YAML::Node& n, const std::string& path) const;
    std::string readString(const YAML::Node& n, const std::string& path) const;
    Vec3 readVec3(const YAML::Node& n, const std::string& path) const;
    /// `inertia:` as [ix, iy, iz] (principal, diagonal) or a 3x3 list of rows, validated.
    Mat3 readInertia(const YAML::Node& n, const std::string& path) const;

    void parseWorld(const YAML::Node& n, Scene& scene) const;
    void parseOutput(const YAML::Node& n, Scene& scene) const;
    /// Fails at the `bodies` entry (its `name` key when written) whose body `name` an earlier
    /// body already has; records the name otherwise.
    void requireUniqueName(const std::string& name, const YAML::Node& entry, std::size_t index,
                           std::unordered_map<std::string, std::size_t>& first_entry_of_name) const;
    /// Fills in whichever of time_step and steps_per_frame the scene left out so that a frame
    /// spans 1/fps s of simulated time (output.fps must be parsed already).
    static void defaultTiming(bool has_time_step, bool has_steps_per_frame, Scene& scene);
    void parseCamera(const YAML::Node& n, Scene& scene) const;
    void parseDraw(const YAML::Node& n, Scene& scene) const;
    /// One body, or the `repeat.count` bodies a `repeat` entry generates.
    std::vector<Body> parseBody(const YAML::Node& n, std::size_t index, const Scene& scene);
    Deformation readDeformation(const YAML::Node& n, const std::string& path) const;
    ShapeType bodyShape(const std::vector<Entry>& es, const YAML::Node& n, const std::string& path,
                        std::string& shape_name, std::vector<std::string_view>& shape_keys) const;
    BodyValues readBodyValues(const std::vector<Entry>& es, const YAML::Node& n,
                              const std::string& path, std::string default_name,
                              const std::vector<std::string_view>& shape_keys,
                              const Scene& scene, bool needs_position = true) const;
    MassProperties bodyMassProperties(const std::vector<Entry>& es, const std::string& path,
                                      ShapeType type,
                                      const std::vector<std::string_view>& shape_keys,
                                      const BodyValues& b, const Scene& scene, Shape& shape);
    /// `bvh_name`: the volume type of a mesh's hierarchy (validated by parseWorld).
    const PreparedShape& prepareMeshShape(ShapeType type, const std::string& file, Real scale,
                                          const Entry& file_entry, const std::string& path,
                                          const std::string& bvh_name);
    void noteMeshMass(const PreparedShape& prepared, const BodyValues& b, const std::string& path);
    [[noreturn]] void failFlatMesh(ShapeType type, const std::string& hull_error,
                                   const collision::TriangleMesh& mesh, const fs::path& resolved,
                                   const Entry& file_entry, const std::string& path) const;
    /// `events:` (after the bodies and the frame count, which it refers to).
    void parseEvents(const Entry& entry, Scene& scene) const;
    /// Any document's root, with the parser's care for malformed YAML (scene_parser.cpp).
    YAML::Node loadDocument(const std::string& text) const;
    /// `expect:` of `scene` or of an events file played on it (after the bodies, whose names
    /// it refers to) into `ex`. `through_events`: the run follows an events track, which
    /// refuses what such a run cannot grade (requireGradableThroughEvents).
    void parseExpect(const Entry& entry, const Scene& scene, Expectations& ex,
                     bool through_events) const;
    /// `chains:` (scene_chains.cpp, after the bodies): each link becomes a kinematic body
    /// appended to scene.bodies, named uniquely among all bodies (`names`: body name -> path).
    void parseChains(const Entry& entry, Scene& scene);
    void parseChain(const YAML::Node& n, std::size_t index, Scene& scene,
                    std::map<std::string, std::string>& names);
    void parseLink(const YAML::Node& n, const std::string& path, const std::string& chain_name,
                   std::size_t index, Scene& scene, ChainSpec& chain,
                   std::map<std::string, std::string>& names,
                   std::map<std::string, int>& link_index);
    collision::ChainJoint readJoint(const YAML::Node& n, const std::string& path) const;
    collision::JointTrajectory readMotion(const YAML::Node& n, const std::string& path,
                                          Real unit) const;
    /// `{position: [x, y, z], euler_deg: [rx, ry, rz]}`, both optional (identity).
    Pose readPlacement(const YAML::Node& n, const std::string& path) const;
    RepeatSpec readRepeat(const Entry& entry, const std::string& path, const Scene& scene) const;
    void requireRoomToSeparate(const RepeatSpec& r, Real radius, const std::string& path) const;
    template <typename Place>
    std::vector<Body> repeatBody(const Body& base, const Entry& entry, const std::string& path,
                                 const Scene& scene, Place&& place) const;

    void applyOverrides(YAML::Node& root);
    void collectOverrideNodes(const YAML::Node& node, const SceneOverride& o);

    std::string file_;
    fs::path base_dir_;
    std::vector<SceneOverride> overrides_;
    // Every node of every override's value, with its override (see fail()).
    std::vector<std::pair<YAML::Node, const SceneOverride*>> override_nodes_;
    std::map<std::string, std::shared_ptr<const MeshImportOutput>> import_cache_;  // scale 1
    std::map<std::tuple<std::string, Real, int>, PreparedShape> mesh_cache_;
    std::vector<std::string> notes_;  // Scene::notes
};

/// The rotation of scene key `euler_deg`: intrinsic X, then Y, then Z (R = Rx Ry Rz), degrees.
Quat eulerDegrees(const Vec3& deg);

/// `v` with 6 significant digits, for limits in messages.
std::string formatLimit(Real v);

/// Empty when a body moving at `speed` (m/s) stays within kMaxTravelPerStep diagonals a step.
std::string speedProblem(Real speed, const WorldSettings& world);

/// Empty when a body spinning at `rate` (rad/s) turns at most kMaxTurnPerStep radians a step.
std::string spinProblem(Real rate, const WorldSettings& world);

/// Pairs of overlapping world AABBs at the bodies' starting poses, estimated from a fixed sample
/// of bodies, each tested against every body: exact up to 256 bodies, then about 2.6e7 box tests
/// in all (at least 32 samples; 0.2 s at 10^6 bodies). Deterministic: the sample is evenly spaced
/// in body order. A dense cluster the sample misses is caught after the first step instead
/// (World's kMaxCandidatePairs check), so this only has to be right for scenes that overlap en
/// masse, where it is.
double estimateStartPairs(const std::vector<Body>& bodies);

/// "a, b, c": the choices a message lists.
std::string join(std::initializer_list<std::string_view> names);

/// Key paths of messages: "world.time_step", "bodies[3]".
std::string childPath(const std::string& path, const std::string& key);
std::string indexPath(const std::string& path, std::size_t i);

/// Control characters from the file are escaped and very long messages are cut, so an error
/// line stays one printable line whatever the input.
std::string printable(const std::string& text);

/// "FILE:LINE:COL: key.path: what" (1:1 when the mark is null), made printable.
std::string formatMessage(const std::string& file, const YAML::Mark& mark, const std::string& path,
                          const std::string& what);

}  // namespace engine::scene_parsing
