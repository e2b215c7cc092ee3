// engine/src/scene.cpp -- YAML scene files -> Scene (validated) -> World. yaml-cpp stays here.
// Every value is checked where it is read, and every failure throws SceneError with the yaml
// node's position, "FILE:LINE:COL: key.path: what is wrong", so no NaN/Inf, unknown key or
// out-of-range value gets past this file. Hull and mesh bodies are built once per
// (file, scale, shape) and share their geometry.
//
// Conventions: `position` is the body's centre of mass (hull and mesh vertices are re-centred
// on it); `euler_deg: [x, y, z]` is intrinsic X, then Y, then Z, i.e. R = Rx(x) Ry(y) Rz(z);
// `angular_velocity` is in the world frame.
#include "engine/scene.h"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <iomanip>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <system_error>
#include <tuple>
#include <utility>

#include "collision/broadphase/broad_phase.h"
#include "collision/bvh/bvh.h"
#include "collision/geometry/convex_hull.h"
#include "engine/mass_properties.h"
#include "engine/mesh_import.h"

namespace engine {

namespace {

namespace fs = std::filesystem;
using collision::Shape;
using collision::ShapeType;

// A unit quaternion is recovered from wxyz only when its length is clearly non-zero.
constexpr Real kMinQuaternionNorm = Real(1e-6);
// `up` and the view direction count as parallel when the sine of their angle is below this.
constexpr Real kMinUpSine = Real(1e-6);
// Zero-volume boxes (allowed, with an explicit mass) keep every principal moment at least
// m (kMinGyrationFraction L)^2, L = largest half extent (at least 1 mm), so I stays invertible.
constexpr Real kMinGyrationFraction = Real(1e-3);

constexpr std::string_view kBodyKeys[] = {
    "name",  "shape",    "radius",           "half_height", "half_extents", "file",
    "scale", "position", "orientation_wxyz", "euler_deg",   "velocity",     "angular_velocity",
    "mass",  "density",  "repeat",           "static",      "restitution",  "friction"};
constexpr std::string_view kRepeatKeys[] = {"count", "seed", "region",
                                            "speed", "spin", "random_orientation"};
// Keys that `repeat` generates itself.
constexpr std::string_view kGeneratedKeys[] = {"position", "velocity", "angular_velocity",
                                               "orientation_wxyz", "euler_deg"};
constexpr int kMaxRepeat = 1000000;
// Bodies in a whole scene, however they are written (a 1.7 KB file aliasing one 10^6-body
// `repeat` 200 times asked for 2e8 bodies and ran out of memory at 5.9 GB): refused before the
// bodies are made.
constexpr std::size_t kMaxBodies = 1000000;

// Magnitudes double precision can integrate. Coordinates of the bounds stay within 1e150, so a
// squared distance between two points of the world (at most 3 (2e150)^2 = 1.2e301) is finite.
// In one step a body may cross at most kMaxTravelPerStep world diagonals (|v| dt, and |g| dt^2
// for gravity) and turn at most kMaxTurnPerStep radians (|w| dt): beyond, reflection and the
// broad phases see meaningless jumps and kinetic energies approach overflow. These refuse the
// absurd (1e308 m/s in a 20 m world) at its line; the world also checks its state every step.
constexpr Real kMaxWorldCoordinate = Real(1e150);
constexpr Real kMaxTravelPerStep = Real(1e6);
constexpr Real kMaxTurnPerStep = Real(1e3);
constexpr Real kMinMeshScale = Real(1e-50);
constexpr Real kMaxMeshScale = Real(1e50);
// Upper bounds of a run's length: larger values are typing mistakes, not experiments.
constexpr int kMaxStepsPerFrame = 100000;
constexpr int kMaxFrames = 1000000;

std::string formatLimit(Real v) {
    std::ostringstream s;
    s << std::setprecision(6) << v;
    return s.str();
}

// Empty when a body moving at `speed` (m/s) stays within kMaxTravelPerStep diagonals a step.
std::string speedProblem(Real speed, const WorldSettings& world) {
    const Real diagonal = (world.bounds.max - world.bounds.min).norm();
    const Real limit = kMaxTravelPerStep * diagonal / world.time_step;
    if (std::isfinite(speed) && speed <= limit) return "";
    return "speed " + formatLimit(speed) + " m/s is beyond what the world can integrate: at most " +
           formatLimit(limit) + " m/s (" + formatLimit(kMaxTravelPerStep) +
           " world diagonals per time step)";
}

// Empty when a body spinning at `rate` (rad/s) turns at most kMaxTurnPerStep radians a step.
std::string spinProblem(Real rate, const WorldSettings& world) {
    const Real limit = kMaxTurnPerStep / world.time_step;
    if (std::isfinite(rate) && rate <= limit) return "";
    return "angular speed " + formatLimit(rate) +
           " rad/s is beyond what the world can integrate: " + "at most " + formatLimit(limit) +
           " rad/s (" + formatLimit(kMaxTurnPerStep) + " rad per time step)";
}

// Pairs of overlapping world AABBs at the bodies' starting poses, estimated from a fixed sample
// of bodies, each tested against every body: exact up to 256 bodies, then about 2.6e7 box tests
// in all (at least 32 samples; 0.2 s at 10^6 bodies). Deterministic: the sample is evenly spaced
// in body order. A dense cluster the sample misses is caught after the first step instead
// (World's kMaxCandidatePairs check), so this only has to be right for scenes that overlap en
// masse, where it is.
double estimateStartPairs(const std::vector<Body>& bodies) {
    const std::size_t n = bodies.size();
    if (n < 2) return 0;
    // Structure of arrays, so the inner loop is six compares and an add per box.
    std::array<std::vector<Real>, 6> box;
    for (auto& column : box) column.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const collision::Aabb b = collision::computeWorldAabb(bodies[i].shape, bodies[i].pose());
        for (int a = 0; a < 3; ++a) {
            box[a][i] = b.min[a];
            box[3 + a][i] = b.max[a];
        }
    }
    const std::size_t samples = std::min(n, std::clamp<std::size_t>(26'000'000 / n, 32, 256));
    std::uint64_t hits = 0;
    for (std::size_t k = 0; k < samples; ++k) {
        const std::size_t i = k * n / samples;
        const Real lo[3] = {box[0][i], box[1][i], box[2][i]};
        const Real hi[3] = {box[3][i], box[4][i], box[5][i]};
        std::uint64_t count = 0;
        for (std::size_t j = 0; j < n; ++j) {
            // Bitwise on 0/1 integers: no branch per comparison.
            const unsigned x = unsigned(box[0][j] <= hi[0]) & unsigned(lo[0] <= box[3][j]);
            const unsigned y = unsigned(box[1][j] <= hi[1]) & unsigned(lo[1] <= box[4][j]);
            const unsigned z = unsigned(box[2][j] <= hi[2]) & unsigned(lo[2] <= box[5][j]);
            count += x & y & z;
        }
        hits += count - 1;  // itself
    }
    return double(hits) * double(n) / double(samples) / 2;
}

struct Entry {
    std::string key;
    YAML::Node key_node;
    YAML::Node value;
};

std::string join(std::initializer_list<std::string_view> names) {
    std::string out;
    for (const std::string_view n : names) {
        if (!out.empty()) out += ", ";
        out += n;
    }
    return out;
}

std::string childPath(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
}

std::string indexPath(const std::string& path, std::size_t i) {
    return path + "[" + std::to_string(i) + "]";
}

// Geometry imported for hull and mesh bodies: re-centred shape and its properties at density 1.
struct PreparedShape {
    Shape shape;
    MassProperties unit;  // mass = volume
};

// Where the second YAML document of a stream starts, if there is one. YAML::Load reads the first
// document and ignores the rest, so a scene split by a "---" would lose its second half without a
// word. yaml-cpp's LoadAll cannot be used to count documents: on some malformed streams its
// HandleNextDocument keeps returning an empty document without consuming the offending token
// (jbeder/yaml-cpp#1319), and LoadAll then loops allocating nodes. Here the parser is asked for
// at most two documents, and the events build nothing.
class DocumentProbe final : public YAML::EventHandler {
public:
    struct Second {
        YAML::Mark start;
        bool stalled;  ///< the parser did not move on: a token it cannot place, not a "---"
    };
    /// Null when the stream holds at most one document; else where the second one starts.
    static std::optional<Second> secondDocument(const std::string& text) {
        std::istringstream in(text);
        YAML::Parser parser(in);
        DocumentProbe first;
        if (!parser.HandleNextDocument(first)) return std::nullopt;
        DocumentProbe second;
        if (!parser.HandleNextDocument(second)) return std::nullopt;
        return Second{second.start_, second.start_.pos <= first.start_.pos};
    }

    void OnDocumentStart(const YAML::Mark& mark) override { start_ = mark; }
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
    void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
    void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  const std::string&) override {}
    void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                         YAML::EmitterStyle::value) override {}
    void OnSequenceEnd() override {}
    void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                    YAML::EmitterStyle::value) override {}
    void OnMapEnd() override {}

private:
    YAML::Mark start_ = YAML::Mark::null_mark();
};

class SceneParser {
public:
    SceneParser(std::string display_name, fs::path base_dir)
        : file_(std::move(display_name)), base_dir_(std::move(base_dir)) {}

    Scene parse(const std::string& text);
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

    void parseWorld(const YAML::Node& n, Scene& scene) const;
    void parseOutput(const YAML::Node& n, Scene& scene) const;
    void parseCamera(const YAML::Node& n, Scene& scene) const;
    void parseDraw(const YAML::Node& n, Scene& scene) const;
    /// One body, or the `repeat.count` bodies a `repeat` entry generates.
    std::vector<Body> parseBody(const YAML::Node& n, std::size_t index, const Scene& scene);
    /// `bvh_name`: the volume type of a mesh's hierarchy (validated by parseWorld).
    const PreparedShape& prepareMeshShape(ShapeType type, const std::string& file, Real scale,
                                          const Entry& file_entry, const std::string& path,
                                          const std::string& bvh_name);
    /// `expect:` (after the bodies, whose names it refers to).
    void parseExpect(const Entry& entry, Scene& scene) const;
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
};

// Control characters from the file are escaped and very long messages are cut, so an error
// line stays one printable line whatever the input.
std::string printable(const std::string& text) {
    constexpr std::size_t kMaxMessage = 1000;
    std::string out;
    for (const char ch : text) {
        const auto c = static_cast<unsigned char>(ch);
        if (c < 0x20 || c == 0x7f) {
            constexpr char kHex[] = "0123456789abcdef";
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 15];
        } else {
            out += ch;
        }
        if (out.size() > kMaxMessage) return out + "...";
    }
    return out;
}

std::string formatMessage(const std::string& file, const YAML::Mark& mark, const std::string& path,
                          const std::string& what) {
    const int line = mark.is_null() || mark.line < 0 ? 1 : mark.line + 1;
    const int col = mark.is_null() || mark.column < 0 ? 1 : mark.column + 1;
    // The key path is escaped too: a quoted key may hold a newline or any control character.
    return file + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " +
           printable(path.empty() ? "scene" : path) + ": " + printable(what);
}

void SceneParser::fail(const YAML::Mark& mark, const std::string& path,
                       const std::string& what) const {
    throw SceneError(formatMessage(file_, mark, path, what));
}

void SceneParser::fail(const YAML::Node& node, const std::string& path,
                       const std::string& what) const {
    if (node.IsDefined()) {
        for (const auto& [value_node, o] : override_nodes_) {
            if (value_node.is(node)) failOverride(*o, path, what);
        }
    }
    fail(node.Mark(), path, what);
}

void SceneParser::failOverride(const SceneOverride& o, const std::string& path,
                               const std::string& what) const {
    throw SceneError(file_ + ": " + printable(o.option + " " + o.key + "=" + o.value) + ": " +
                     printable(path.empty() ? "scene" : path) + ": " + printable(what));
}

std::vector<Entry> SceneParser::entries(const YAML::Node& map, const std::string& path,
                                        std::initializer_list<std::string_view> allowed) const {
    return entries(map, path, std::vector<std::string_view>(allowed));
}

// The keys of a mapping, in file order; unknown and duplicate keys are errors at the key.
std::vector<Entry> SceneParser::entries(const YAML::Node& map, const std::string& path,
                                        const std::vector<std::string_view>& allowed) const {
    if (!map.IsMap()) {
        std::string list;
        for (const std::string_view a : allowed)
            list += (list.empty() ? "" : ", ") + std::string(a);
        fail(map, path, "expected a mapping with keys: " + list);
    }
    std::vector<Entry> out;
    std::set<std::string> seen;
    for (YAML::const_iterator it = map.begin(); it != map.end(); ++it) {
        const YAML::Node key = it->first;
        if (!key.IsScalar()) fail(key, path, "keys must be plain names");
        const std::string name = key.Scalar();
        bool known = false;
        for (const std::string_view a : allowed) known = known || a == name;
        if (!known) {
            std::string list;
            for (const std::string_view a : allowed) {
                list += (list.empty() ? "" : ", ") + std::string(a);
            }
            fail(key, childPath(path, name),
                 "unknown key '" + name + "' (expected one of: " + list + ")");
        }
        if (!seen.insert(name).second) fail(key, childPath(path, name), "duplicate key");
        out.push_back(Entry{name, key, it->second});
    }
    return out;
}

const Entry* SceneParser::find(const std::vector<Entry>& es, std::string_view key) const {
    for (const Entry& e : es) {
        if (e.key == key) return &e;
    }
    return nullptr;
}

const Entry& SceneParser::require(const std::vector<Entry>& es, std::string_view key,
                                  const YAML::Node& parent, const std::string& path) const {
    const Entry* e = find(es, key);
    if (e == nullptr) fail(parent, childPath(path, std::string(key)), "required key is missing");
    return *e;
}

// yaml-cpp tags a quoted scalar "!" and a plain one "?": "0.5" in quotes is a string, and a
// number read from it would hide a typing mistake in the file.
bool isQuoted(const YAML::Node& n) { return n.Tag() == "!"; }

Real SceneParser::readReal(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar()) fail(n, path, "expected a number");
    if (isQuoted(n)) fail(n, path, "expected a number, got the string \"" + n.Scalar() + "\"");
    double v = 0;
    try {
        v = n.as<double>();
    } catch (const YAML::Exception&) {
        fail(n, path, "expected a number, got '" + n.Scalar() + "'");
    }
    if (!std::isfinite(v)) fail(n, path, "must be finite, got '" + n.Scalar() + "'");
    const auto r = static_cast<Real>(v);
    if (!std::isfinite(r)) fail(n, path, "out of range, got '" + n.Scalar() + "'");
    return r;
}

int SceneParser::readInt(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar()) fail(n, path, "expected an integer");
    if (isQuoted(n)) fail(n, path, "expected an integer, got the string \"" + n.Scalar() + "\"");
    int value = 0;
    try {
        value = n.as<int>();
    } catch (const YAML::Exception&) {
        fail(n, path, "expected an integer, got '" + n.Scalar() + "'");
    }
    // Decimal only: YAML 1.1 (yaml-cpp) reads 0300 as octal 192 and 0x10 as 16.
    const std::string& text = n.Scalar();
    const std::size_t digits = text.find_first_not_of("+-");
    const bool decimal = digits <= 1 && digits < text.size() &&
                         text.find_first_not_of("0123456789", digits) == std::string::npos &&
                         (text[digits] != '0' || digits + 1 == text.size());
    if (!decimal) {
        fail(n, path, "expected a decimal integer without leading zeros, got '" + text + "'");
    }
    return value;
}

bool SceneParser::readBool(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar()) fail(n, path, "expected true or false");
    try {
        return n.as<bool>();
    } catch (const YAML::Exception&) {
        fail(n, path, "expected true or false, got '" + n.Scalar() + "'");
    }
}

std::string SceneParser::readString(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar()) fail(n, path, "expected a string");
    return n.Scalar();
}

Vec3 SceneParser::readVec3(const YAML::Node& n, const std::string& path) const {
    if (!n.IsSequence() || n.size() != 3) fail(n, path, "expected a list of 3 numbers");
    Vec3 v;
    for (std::size_t i = 0; i < 3; ++i) {
        const YAML::Node e = n[i];
        if (!e.IsScalar()) fail(e, indexPath(path, i), "expected a number");
        v[static_cast<Eigen::Index>(i)] = readReal(e, indexPath(path, i));
    }
    return v;
}

void SceneParser::parseWorld(const YAML::Node& n, Scene& scene) const {
    const std::string path = "world";
    const std::vector<Entry> es = entries(
        n, path,
        {"bounds", "gravity", "time_step", "steps_per_frame", "frames", "mesh_bvh", "integrator",
         "ccd", "ccd_tolerance", "ccd_target_gap", "response", "restitution", "friction"});
    {
        const Entry& b = require(es, "bounds", n, path);
        const std::string bp = childPath(path, "bounds");
        const std::vector<Entry> be = entries(b.value, bp, {"min", "max"});
        const Entry& lo = require(be, "min", b.value, bp);
        const Entry& hi = require(be, "max", b.value, bp);
        scene.world.bounds.min = readVec3(lo.value, childPath(bp, "min"));
        scene.world.bounds.max = readVec3(hi.value, childPath(bp, "max"));
        for (int a = 0; a < 3; ++a) {
            if (!(scene.world.bounds.min[a] < scene.world.bounds.max[a])) {
                fail(hi.value, childPath(bp, "max"),
                     std::string("must be greater than min on every axis (axis ") + "xyz"[a] + ")");
            }
        }
        for (const Entry* corner : {&lo, &hi}) {
            const Vec3& c = corner == &lo ? scene.world.bounds.min : scene.world.bounds.max;
            if (!(c.cwiseAbs().maxCoeff() <= kMaxWorldCoordinate)) {
                fail(corner->value, childPath(bp, corner->key),
                     "coordinates must lie within +-" + formatLimit(kMaxWorldCoordinate) +
                         " (squared distances must stay finite in double precision)");
            }
        }
    }
    for (const Entry& e : es) {
        const std::string p = childPath(path, e.key);
        if (e.key == "gravity") {
            scene.world.gravity = readVec3(e.value, p);
        } else if (e.key == "time_step") {
            const Real dt = readReal(e.value, p);
            if (!(dt > 0 && dt <= 1)) fail(e.value, p, "must be > 0 and <= 1 (seconds)");
            scene.world.time_step = dt;
        } else if (e.key == "steps_per_frame") {
            scene.steps_per_frame = readInt(e.value, p);
            if (scene.steps_per_frame < 1) fail(e.value, p, "must be >= 1");
            if (scene.steps_per_frame > kMaxStepsPerFrame) {
                fail(e.value, p, "must be <= " + std::to_string(kMaxStepsPerFrame));
            }
        } else if (e.key == "frames") {
            scene.frames = readInt(e.value, p);
            if (scene.frames < 1) fail(e.value, p, "must be >= 1");
            if (scene.frames > kMaxFrames)
                fail(e.value, p, "must be <= " + std::to_string(kMaxFrames));
        } else if (e.key == "mesh_bvh") {
            const std::string name = readString(e.value, p);
            const auto& names = collision::bvhVolumeNames();
            if (std::find(names.begin(), names.end(), name) == names.end()) {
                std::string list;
                for (const std::string_view v : names) {
                    list += (list.empty() ? "" : ", ") + std::string(v);
                }
                fail(e.value, p,
                     "unknown bounding volume '" + name + "' (expected one of: " + list + ")");
            }
            scene.world.mesh_bvh = name;
        } else if (e.key == "response") {
            const std::string name = readString(e.value, p);
            if (!findResponse(name, scene.world.response)) {
                fail(e.value, p,
                     "unknown response '" + name + "' (expected one of: none, impulse)");
            }
        } else if (e.key == "restitution") {
            scene.world.restitution = readReal(e.value, p);
            if (!(scene.world.restitution >= 0 && scene.world.restitution <= 1)) {
                fail(e.value, p, "must be in [0, 1]");
            }
        } else if (e.key == "friction") {
            scene.world.friction = readReal(e.value, p);
            if (!(scene.world.friction >= 0)) fail(e.value, p, "must be >= 0");
        } else if (e.key == "ccd") {
            const std::string name = readString(e.value, p);
            if (!findCcdMethod(name, scene.world.ccd)) {
                fail(e.value, p,
                     "unknown ccd method '" + name + "' (expected one of: " + ccdMethodNames() +
                         ")");
            }
        } else if (e.key == "ccd_tolerance") {
            // Fractions of the pair's smaller bounding radius (WorldSettings). 0 would ask the
            // advancement for exact contact, which it only approaches (Failed at the cap).
            const Real v = readReal(e.value, p);
            if (!(v > 0 && v <= 1)) {
                fail(e.value, p, "must be > 0 and <= 1 (fraction of the smaller bounding radius)");
            }
            scene.world.ccd_tolerance = v;
        } else if (e.key == "ccd_target_gap") {
            const Real v = readReal(e.value, p);
            if (!(v >= 0 && v <= 1)) {
                fail(e.value, p, "must be in [0, 1] (fraction of the smaller bounding radius)");
            }
            scene.world.ccd_target_gap = v;
        } else if (e.key == "integrator") {
            const std::string name = readString(e.value, p);
            if (!findIntegrator(name, scene.world.integrator)) {
                fail(e.value, p,
                     "unknown integrator '" + name + "' (expected one of: " + integratorNames() +
                         ")");
            }
        }
    }
    // Gravity against the time step, once both are known: |g| dt is a speed gained per step.
    if (const Entry* g = find(es, "gravity")) {
        const std::string problem =
            speedProblem(scene.world.gravity.stableNorm() * scene.world.time_step, scene.world);
        if (!problem.empty()) {
            fail(g->value, childPath(path, "gravity"),
                 "too strong for the time step: the " + problem + " (gained in one step)");
        }
    }
}

void SceneParser::parseOutput(const YAML::Node& n, Scene& scene) const {
    const std::string path = "output";
    for (const Entry& e : entries(n, path, {"width", "height", "fps"})) {
        const std::string p = childPath(path, e.key);
        const int v = readInt(e.value, p);
        if (e.key == "fps") {
            if (v < 1 || v > 240) fail(e.value, p, "must be in 1..240");
            scene.output.fps = v;
        } else {
            if (v < 16 || v > 8192) fail(e.value, p, "must be in 16..8192");
            if (v % 2 != 0) fail(e.value, p, "must be even (video encoders need it)");
            (e.key == "width" ? scene.output.width : scene.output.height) = v;
        }
    }
}

void SceneParser::parseCamera(const YAML::Node& n, Scene& scene) const {
    const std::string path = "camera";
    const std::vector<Entry> es = entries(n, path, {"position", "look_at", "up", "fov_deg"});
    CameraSettings& cam = scene.camera;
    for (const Entry& e : es) {
        const std::string p = childPath(path, e.key);
        if (e.key == "position" || e.key == "look_at" || e.key == "up") {
            const Vec3 v = readVec3(e.value, p);
            // The view's cross products square these: past 1e150 they overflow, and the camera
            // would be reported as looking along `up` ("up must not be parallel" at 1e308).
            if (!(v.cwiseAbs().maxCoeff() <= kMaxWorldCoordinate)) {
                fail(e.value, p,
                     "coordinates must lie within +-" + formatLimit(kMaxWorldCoordinate) +
                         " (the view's products must stay finite in double precision)");
            }
            (e.key == "position" ? cam.position : e.key == "look_at" ? cam.look_at : cam.up) = v;
        }
        if (e.key == "fov_deg") {
            cam.fov_deg = readReal(e.value, p);
            if (!(cam.fov_deg > 0 && cam.fov_deg < 180)) {
                fail(e.value, p, "must be > 0 and < 180 (degrees)");
            }
        }
    }
    // Report a bad view at the key that was given last among the three.
    const Entry* at = nullptr;
    for (const Entry& e : es) {
        if (e.key == "position" || e.key == "look_at" || e.key == "up") at = &e;
    }
    const YAML::Node where = at != nullptr ? at->value : n;
    const std::string where_path = at != nullptr ? childPath(path, at->key) : path;
    const Vec3 view = cam.look_at - cam.position;
    const Real view_len = view.norm();
    const Real up_len = cam.up.norm();
    if (!(view_len > 0)) fail(where, where_path, "position and look_at must differ");
    if (!(up_len > 0)) fail(where, where_path, "up must not be zero");
    if (!(view.cross(cam.up).norm() > kMinUpSine * view_len * up_len)) {
        fail(where, where_path, "up must not be parallel to the view direction");
    }
}

void SceneParser::parseDraw(const YAML::Node& n, Scene& scene) const {
    const std::string path = "draw";
    DrawSettings& d = scene.draw;
    for (const Entry& e :
         entries(n, path,
                 {"bodies", "volumes", "bounds", "hud", "structure", "bvh_depth", "contacts"})) {
        const std::string p = childPath(path, e.key);
        if (e.key == "bodies") d.bodies = readBool(e.value, p);
        if (e.key == "bounds") d.bounds = readBool(e.value, p);
        if (e.key == "hud") d.hud = readBool(e.value, p);
        if (e.key == "structure") d.structure = readBool(e.value, p);
        if (e.key == "contacts") d.contacts = readBool(e.value, p);
        if (e.key == "bvh_depth") {
            d.bvh_depth = readInt(e.value, p);
            if (d.bvh_depth < -1) fail(e.value, p, "must be >= 0, or -1 for off");
        }
        if (e.key == "volumes") {
            if (!e.value.IsSequence()) fail(e.value, p, "expected a list of: sphere, aabb, obb");
            d.sphere = d.aabb = d.obb = false;
            for (std::size_t i = 0; i < e.value.size(); ++i) {
                const std::string ip = indexPath(p, i);
                const std::string v = readString(e.value[i], ip);
                if (v == "sphere") {
                    d.sphere = true;
                } else if (v == "aabb") {
                    d.aabb = true;
                } else if (v == "obb") {
                    d.obb = true;
                } else {
                    fail(e.value[i], ip,
                         "unknown volume '" + v + "' (expected one of: sphere, aabb, obb)");
                }
            }
        }
    }
}

const PreparedShape& SceneParser::prepareMeshShape(ShapeType type, const std::string& file,
                                                   Real scale, const Entry& file_entry,
                                                   const std::string& path,
                                                   const std::string& bvh_name) {
    fs::path resolved = fs::path(file);
    if (resolved.is_relative()) resolved = base_dir_ / resolved;
    std::error_code ec;
    fs::path canonical = fs::weakly_canonical(resolved, ec);
    if (ec) canonical = resolved.lexically_normal();
    const auto key = std::make_tuple(canonical.string(), scale, static_cast<int>(type));
    if (const auto it = mesh_cache_.find(key); it != mesh_cache_.end()) return it->second;

    // Errors about the file are reported at the `file:` key. One import per file, at scale 1,
    // shared by every hull and mesh body made from it: assimp is the slow part (under ASan one OBJ
    // import costs about half a second, so a scene with many scales of one file took seconds).
    auto import_it = import_cache_.find(canonical.string());
    if (import_it == import_cache_.end()) {
        import_it = import_cache_
                        .emplace(canonical.string(),
                                 std::make_shared<const MeshImportOutput>(importMesh(resolved, 1)))
                        .first;
    }
    // Scaling after the import gives importMesh(file, scale)'s mesh unless rounding at an extreme
    // scale made a kept triangle degenerate (vertices merge, or the area vanishes) or the file
    // only works at its scale (a failed import); then that scale is imported on its own, so the
    // welding and degenerate-triangle rules and the error messages are importMesh's exactly.
    MeshImportOutput imported = *import_it->second;
    bool exact = imported.ok;
    for (Vec3& v : imported.mesh.vertices) {
        v *= scale;
        exact = exact && v.allFinite();
    }
    for (const auto& t : imported.mesh.triangles) {
        if (!exact) break;
        const Vec3& a = imported.mesh.vertices[t[0]];
        const Vec3& b = imported.mesh.vertices[t[1]];
        const Vec3& c = imported.mesh.vertices[t[2]];
        exact = a != b && b != c && a != c && (b - a).cross(c - a).squaredNorm() > 0;
    }
    if (!exact) {
        imported = importMesh(resolved, scale);
        if (!imported.ok) fail(file_entry.key_node, path, imported.error);
    }
    const collision::ConvexHullOutput hull = collision::computeConvexHull(imported.mesh.vertices);
    if (!hull.ok) {
        // A flat or degenerate point set is the file's shape, not a failure of the hull: say so.
        const std::size_t n = imported.mesh.vertices.size();
        const std::string counts = std::to_string(n) + (n == 1 ? " vertex" : " vertices") + ", " +
                                   std::to_string(imported.mesh.triangles.size()) + " triangle" +
                                   (imported.mesh.triangles.size() == 1 ? "" : "s");
        std::string flat;
        if (hull.error == "points are coplanar" || n == 3) {
            flat = "lie in one plane";
        } else if (hull.error == "points are collinear" || n == 2) {
            flat = "lie on one line";
        } else if (hull.error == "all points coincide" || n < 2) {
            flat = "coincide";
        }
        if (!flat.empty()) {
            fail(
                file_entry.key_node, path,
                "'" + resolved.string() + "' has no volume: its points " + flat + " (" + counts +
                    "); a body is a solid, so its " +
                    (type == ShapeType::ConvexHull ? "hull" : "mesh's hull (for mass properties)") +
                    " needs points in three dimensions");
        }
        fail(file_entry.key_node, path,
             "cannot build the convex hull of '" + resolved.string() + "': " + hull.error);
    }
    // Mass properties of the solid the body is (the hull, or the mesh's own volume), then move
    // the geometry so that the local origin is the centre of mass.
    Shape raw =
        type == ShapeType::ConvexHull
            ? Shape::convexHull(std::make_shared<const collision::ConvexPolytope>(hull.hull))
            : Shape::triangleMesh(std::make_shared<const collision::TriangleMesh>(imported.mesh),
                                  std::make_shared<const collision::ConvexPolytope>(hull.hull),
                                  nullptr);  // only for the mass properties: no hierarchy
    const MassPropertiesOutput mp = computeMassProperties(raw, 1);
    if (!mp.ok) fail(file_entry.key_node, path, "'" + resolved.string() + "': " + mp.error);
    const Vec3 com = mp.props.center_of_mass;
    collision::ConvexPolytope centred_hull = hull.hull;
    for (Vec3& v : centred_hull.vertices) v -= com;
    PreparedShape prepared;
    prepared.unit = mp.props;
    if (type == ShapeType::ConvexHull) {
        prepared.shape = Shape::convexHull(
            std::make_shared<const collision::ConvexPolytope>(std::move(centred_hull)));
    } else {
        collision::TriangleMesh centred_mesh = imported.mesh;
        for (Vec3& v : centred_mesh.vertices) v -= com;
        // The hierarchy is built once here, in the body frame, and shared by every body made
        // from this file (rigid motion needs no rebuild).
        auto mesh = std::make_shared<const collision::TriangleMesh>(std::move(centred_mesh));
        std::shared_ptr<const collision::MeshBvh> bvh = collision::buildMeshBvh(bvh_name, *mesh);
        prepared.shape = Shape::triangleMesh(
            std::move(mesh),
            std::make_shared<const collision::ConvexPolytope>(std::move(centred_hull)),
            std::move(bvh));
    }
    return mesh_cache_.emplace(key, std::move(prepared)).first->second;
}

std::vector<Body> SceneParser::parseBody(const YAML::Node& n, std::size_t index,
                                         const Scene& scene) {
    const std::string path = indexPath("bodies", index);
    const std::vector<Entry> es =
        entries(n, path, std::vector<std::string_view>(std::begin(kBodyKeys), std::end(kBodyKeys)));

    // The shape first: it decides which keys apply.
    const Entry& shape_entry = require(es, "shape", n, path);
    const std::string shape_name = readString(shape_entry.value, childPath(path, "shape"));
    ShapeType type = ShapeType::Sphere;
    std::vector<std::string_view> shape_keys;
    if (shape_name == "sphere") {
        type = ShapeType::Sphere;
        shape_keys = {"radius"};
    } else if (shape_name == "box") {
        type = ShapeType::Box;
        shape_keys = {"half_extents"};
    } else if (shape_name == "capsule") {
        type = ShapeType::Capsule;
        shape_keys = {"radius", "half_height"};
    } else if (shape_name == "hull" || shape_name == "mesh") {
        type = shape_name == "hull" ? ShapeType::ConvexHull : ShapeType::Mesh;
        shape_keys = {"file", "scale"};
    } else {
        fail(shape_entry.value, childPath(path, "shape"),
             "unknown shape '" + shape_name +
                 "' (expected one of: " + join({"sphere", "box", "capsule", "hull", "mesh"}) + ")");
    }
    constexpr std::string_view kShapeSpecific[] = {"radius", "half_height", "half_extents", "file",
                                                   "scale"};
    for (const Entry& e : es) {
        for (const std::string_view k : kShapeSpecific) {
            if (e.key != k) continue;
            bool applies = false;
            for (const std::string_view s : shape_keys) applies = applies || s == k;
            if (!applies) {
                fail(e.key_node, childPath(path, e.key),
                     "does not apply to shape '" + shape_name + "'");
            }
        }
    }
    // Pairs that exclude each other: reported at whichever comes second in the file.
    constexpr std::pair<std::string_view, std::string_view> kExclusive[] = {
        {"mass", "density"}, {"orientation_wxyz", "euler_deg"}};
    for (const auto& [a, b] : kExclusive) {
        const Entry* ea = find(es, a);
        const Entry* eb = find(es, b);
        if (ea != nullptr && eb != nullptr) {
            const Entry* second = ea->key_node.Mark().pos > eb->key_node.Mark().pos ? ea : eb;
            fail(second->key_node, childPath(path, second->key),
                 "give either '" + std::string(a) + "' or '" + std::string(b) + "', not both");
        }
    }

    std::string name = shape_name + std::to_string(index);
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
    Real mass = 0;
    Real density = 1000;
    bool is_static = false;
    Real restitution = scene.world.restitution;
    Real friction = scene.world.friction;

    const Entry* repeat_entry = find(es, "repeat");
    if (repeat_entry != nullptr) {
        for (const Entry& e : es) {
            for (const std::string_view k : kGeneratedKeys) {
                if (e.key == k) {
                    fail(e.key_node, childPath(path, e.key),
                         "does not apply with 'repeat' (repeat generates it)");
                }
            }
        }
    } else {
        require(es, "position", n, path);
    }
    for (const std::string_view k : shape_keys) {
        if (k != "scale") require(es, k, n, path);
    }
    for (const Entry& e : es) {
        const std::string p = childPath(path, e.key);
        const YAML::Node& v = e.value;
        if (e.key == "name") {
            name = readString(v, p);
        } else if (e.key == "radius") {
            radius = readReal(v, p);
            if (!(radius > 0)) fail(v, p, "must be > 0");
        } else if (e.key == "half_height") {
            half_height = readReal(v, p);
            if (!(half_height >= 0)) fail(v, p, "must be >= 0");
        } else if (e.key == "half_extents") {
            half_extents = readVec3(v, p);
            for (int a = 0; a < 3; ++a) {
                if (!(half_extents[a] >= 0)) fail(v[a], indexPath(p, a), "must be >= 0");
            }
        } else if (e.key == "file") {
            readString(v, p);
            if (v.Scalar().empty()) fail(v, p, "must not be empty");
            file_entry = &e;
        } else if (e.key == "scale") {
            scale = readReal(v, p);
            if (!(scale > 0)) fail(v, p, "must be > 0");
            // The hull and mass properties multiply up to three coordinates: at 1e300 they
            // overflowed ("points are coplanar"), at 1e-300 underflowed ("no triangles").
            if (!(scale >= kMinMeshScale && scale <= kMaxMeshScale)) {
                fail(v, p,
                     "must be in [" + formatLimit(kMinMeshScale) + ", " +
                         formatLimit(kMaxMeshScale) +
                         "]: beyond, products of the scaled coordinates over- or underflow");
            }
        } else if (e.key == "position") {
            position = readVec3(v, p);
            if (!scene.world.bounds.contains(position)) {
                fail(v, p, "is outside the world bounds");
            }
        } else if (e.key == "orientation_wxyz") {
            if (!v.IsSequence() || v.size() != 4) fail(v, p, "expected a list of 4 numbers");
            Real q[4];
            for (std::size_t i = 0; i < 4; ++i) q[i] = readReal(v[i], indexPath(p, i));
            const Quat raw(q[0], q[1], q[2], q[3]);
            const Real len = raw.norm();
            if (!(len > kMinQuaternionNorm) || !std::isfinite(len)) {
                fail(v, p, "must be a non-zero quaternion (it is normalised)");
            }
            orientation = Quat(raw.coeffs() / len);
        } else if (e.key == "euler_deg") {
            const Vec3 deg = readVec3(v, p);
            const Vec3 rad = deg * (std::numbers::pi_v<Real> / 180);
            // Intrinsic X, then Y, then Z: R = Rx Ry Rz.
            orientation = Quat(Eigen::AngleAxis<Real>(rad.x(), Vec3::UnitX())) *
                          Quat(Eigen::AngleAxis<Real>(rad.y(), Vec3::UnitY())) *
                          Quat(Eigen::AngleAxis<Real>(rad.z(), Vec3::UnitZ()));
            orientation.normalize();
        } else if (e.key == "velocity") {
            velocity = readVec3(v, p);
            const std::string problem = speedProblem(velocity.stableNorm(), scene.world);
            if (!problem.empty()) fail(v, p, problem);
        } else if (e.key == "angular_velocity") {
            angular_velocity = readVec3(v, p);
            const std::string problem = spinProblem(angular_velocity.stableNorm(), scene.world);
            if (!problem.empty()) fail(v, p, problem);
        } else if (e.key == "mass") {
            mass = readReal(v, p);
            if (!(mass > 0)) fail(v, p, "must be > 0 (kg)");
            mass_entry = &e;
        } else if (e.key == "density") {
            density = readReal(v, p);
            if (!(density > 0)) fail(v, p, "must be > 0 (kg/m^3)");
            density_entry = &e;
        } else if (e.key == "static") {
            is_static = readBool(v, p);
        } else if (e.key == "restitution") {
            restitution = readReal(v, p);
            if (!(restitution >= 0 && restitution <= 1)) fail(v, p, "must be in [0, 1]");
        } else if (e.key == "friction") {
            friction = readReal(v, p);
            if (!(friction >= 0)) fail(v, p, "must be >= 0");
        }
    }
    if (is_static) {
        for (const Entry& e : es) {
            if (e.key == "velocity" || e.key == "angular_velocity") {
                fail(e.key_node, childPath(path, e.key), "a static body does not move");
            }
        }
    }

    // Geometry and its properties at density 1 (mass = volume).
    Shape shape;
    MassProperties unit;
    // Mass problems are reported at `mass` or `density`, else at the shape's size key.
    const Entry* mass_at = mass_entry != nullptr      ? mass_entry
                           : density_entry != nullptr ? density_entry
                                                      : find(es, shape_keys.front());
    const std::string mass_path = childPath(path, mass_at->key);
    const YAML::Node mass_node = mass_at->value;
    if (type == ShapeType::ConvexHull || type == ShapeType::Mesh) {
        const PreparedShape& prepared =
            prepareMeshShape(type, file_entry->value.Scalar(), scale, *file_entry,
                             childPath(path, "file"), scene.world.mesh_bvh);
        shape = prepared.shape;
        unit = prepared.unit;
    } else {
        shape = type == ShapeType::Sphere ? Shape::sphere(radius)
                : type == ShapeType::Box  ? Shape::box(half_extents)
                                          : Shape::capsule(radius, half_height);
        const MassPropertiesOutput mp = computeMassProperties(shape, 1);
        if (mp.ok) {
            unit = mp.props;
        } else if (type == ShapeType::Box) {
            // A flat or degenerate box: only an explicit mass defines it. Thin-plate / rod limit
            // of the cuboid formula, with a floor so that the inertia stays invertible.
            if (mass_entry == nullptr) {
                fail(find(es, "half_extents")->value, childPath(path, "half_extents"),
                     "a box with zero volume needs 'mass' (a density gives it no mass)");
            }
            const Vec3 h2 = half_extents.cwiseProduct(half_extents);
            const Real l = std::max(half_extents.maxCoeff(), Real(1e-3));
            const Real floor2 = (kMinGyrationFraction * l) * (kMinGyrationFraction * l);
            const Vec3 moments = (Vec3(h2.y() + h2.z(), h2.z() + h2.x(), h2.x() + h2.y()) / 3)
                                     .cwiseMax(Vec3::Constant(floor2));
            unit.mass = 1;  // per kg: scaled by the mass below
            unit.inertia = moments.asDiagonal();
        } else {
            fail(mass_node, mass_path, mp.error);
        }
    }
    const Real scale_to = mass_entry != nullptr ? mass / unit.mass : density;
    MassProperties props = unit;
    props.mass = unit.mass * scale_to;
    props.inertia = unit.inertia * scale_to;
    if (mass_entry != nullptr) props.mass = mass;
    const Mat3 inv = props.inertia.inverse();
    if (!std::isfinite(props.mass) || !(props.mass > 0) || !props.inertia.allFinite() ||
        !inv.allFinite() || !(props.inertia.diagonal().minCoeff() > 0)) {
        std::ostringstream what;
        what << "gives degenerate mass properties (mass " << props.mass
             << " kg): the body is too small, too large, too light or too heavy";
        fail(mass_node, mass_path, what.str());
    }

    Body body = makeBody(std::move(name), std::move(shape), props);
    body.restitution = restitution;
    body.friction = friction;
    auto place = [&props, is_static](Body& b, const Vec3& p, const Quat& q, const Vec3& v,
                                     const Vec3& w) {
        b.position = p;
        b.orientation = q;
        b.linear_momentum = props.mass * v;
        const Mat3 r = q.toRotationMatrix();
        b.angular_momentum = r * props.inertia * r.transpose() * w;
        if (is_static) setStatic(b);
    };
    if (repeat_entry == nullptr) {
        place(body, position, orientation, velocity, angular_velocity);
        return {std::move(body)};
    }
    return repeatBody(body, *repeat_entry, childPath(path, "repeat"), scene, place);
}

template <typename Place>
std::vector<Body> SceneParser::repeatBody(const Body& base, const Entry& entry,
                                          const std::string& path, const Scene& scene,
                                          Place&& place) const {
    const YAML::Node& n = entry.value;
    if (!n.IsMap())
        fail(n, path,
             "expected a mapping with keys: " +
                 join({"count", "seed", "region", "speed", "spin", "random_orientation"}));
    const std::vector<Entry> es = entries(
        n, path, std::vector<std::string_view>(std::begin(kRepeatKeys), std::end(kRepeatKeys)));
    const Entry& count_entry = require(es, "count", n, path);
    const int count = readInt(count_entry.value, childPath(path, "count"));
    if (count < 1 || count > kMaxRepeat) {
        fail(count_entry.value, childPath(path, "count"),
             "must be in 1.." + std::to_string(kMaxRepeat));
    }
    if (scene.bodies.size() + static_cast<std::size_t>(count) > kMaxBodies) {
        fail(count_entry.value, childPath(path, "count"),
             std::to_string(count) + " more bodies after " + std::to_string(scene.bodies.size()) +
                 " would pass the limit of " + std::to_string(kMaxBodies) + " bodies in a scene");
    }
    std::uint64_t seed = 1;
    collision::Aabb region = scene.world.bounds;
    Real speed = 0;
    Real spin = 0;
    bool random_orientation = true;
    for (const Entry& e : es) {
        const std::string p = childPath(path, e.key);
        if (e.key == "seed") {
            const int s = readInt(e.value, p);
            if (s < 0) fail(e.value, p, "must be >= 0");
            seed = static_cast<std::uint64_t>(s);
        } else if (e.key == "region") {
            const std::vector<Entry> r = entries(e.value, p, {"min", "max"});
            region.min = readVec3(require(r, "min", e.value, p).value, childPath(p, "min"));
            region.max = readVec3(require(r, "max", e.value, p).value, childPath(p, "max"));
            for (int a = 0; a < 3; ++a) {
                if (!(region.min[a] <= region.max[a])) {
                    fail(e.value, p, "min must be <= max on every axis");
                }
            }
            if (!scene.world.bounds.contains(region.min) ||
                !scene.world.bounds.contains(region.max)) {
                fail(e.value, p, "must lie inside the world bounds");
            }
        } else if (e.key == "speed") {
            speed = readReal(e.value, p);
            if (!(speed >= 0)) fail(e.value, p, "must be >= 0 (m/s)");
            const std::string problem = speedProblem(speed, scene.world);
            if (!problem.empty()) fail(e.value, p, problem);
        } else if (e.key == "spin") {
            spin = readReal(e.value, p);
            if (!(spin >= 0)) fail(e.value, p, "must be >= 0 (rad/s)");
            const std::string problem = spinProblem(spin, scene.world);
            if (!problem.empty()) fail(e.value, p, problem);
        } else if (e.key == "random_orientation") {
            random_orientation = readBool(e.value, p);
        }
    }
    // splitmix64: the same bodies from the same seed on every platform.
    std::uint64_t state = seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull;
    auto uniform = [&state]() {
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        z ^= z >> 31;
        return Real(z >> 11) * Real(0x1.0p-53);
    };
    auto direction = [&uniform]() {
        // Uniform on the sphere: z uniform in [-1, 1], azimuth uniform (Archimedes).
        const Real z = 2 * uniform() - 1;
        const Real phi = 2 * std::numbers::pi_v<Real> * uniform();
        const Real r = std::sqrt(std::max(Real(0), 1 - z * z));
        return Vec3(r * std::cos(phi), r * std::sin(phi), z);
    };
    std::vector<Body> out;
    out.reserve(static_cast<std::size_t>(count));
    for (int k = 0; k < count; ++k) {
        Body b = base;
        b.name = base.name + "_" + std::to_string(k);
        const Vec3 t(uniform(), uniform(), uniform());
        const Vec3 p = region.min + (region.max - region.min).cwiseProduct(t);
        Quat q = Quat::Identity();
        if (random_orientation) {
            // Shoemake's uniform random rotation.
            const Real u1 = uniform(), u2 = uniform(), u3 = uniform();
            const Real a = std::sqrt(1 - u1), c = std::sqrt(u1);
            const Real tau = 2 * std::numbers::pi_v<Real>;
            q = Quat(a * std::sin(tau * u2), a * std::cos(tau * u2), c * std::sin(tau * u3),
                     c * std::cos(tau * u3))
                    .normalized();
        }
        const Vec3 v = direction() * (speed * uniform());
        const Vec3 w = direction() * (spin * uniform());
        place(b, p, q, v, w);
        out.push_back(std::move(b));
    }
    return out;
}

// `expect:` states outcomes `cdlab check` verifies. Everything that can be checked without
// running is checked here: frames inside the run, body names that exist and are unique, broad
// phase names in the registry, colour names, contradictory pair states, and that the section
// states at least one expectation (an empty one would pass `cdlab check` having checked
// nothing).
void SceneParser::parseExpect(const Entry& entry, Scene& scene) const {
    const YAML::Node& n = entry.value;
    const std::string path = "expect";
    Expectations& ex = scene.expect;
    ex.present = true;
    const std::string kinds =
        "min_bodies, min_moving_rotating, broadphases, energy_drift_max, energy_rise_max, "
        "pause_dumps, pairs, colors, tunnelling, toi, rest";
    if (n.IsNull() || (n.IsMap() && n.size() == 0)) {
        fail(entry.key_node, path, "states no expectation (give at least one of: " + kinds + ")");
    }
    const std::vector<Entry> es =
        entries(n, path,
                {"frames", "min_bodies", "min_moving_rotating", "broadphases", "energy_drift_max",
                 "energy_rise_max", "pause_dumps", "pairs", "colors", "tunnelling", "toi", "rest"});
    // The run length first: every frame below must lie inside it.
    if (const Entry* f = find(es, "frames")) {
        const int v = readInt(f->value, childPath(path, "frames"));
        if (v < 1) fail(f->value, childPath(path, "frames"), "must be >= 1");
        ex.frames = v;
    }
    const int run_frames = ex.frames.value_or(scene.frames);
    auto readFrame = [&](const YAML::Node& v, const std::string& p) {
        const int f = readInt(v, p);
        if (f < 0 || f >= run_frames) {
            fail(v, p,
                 "frame out of range (the check runs frames 0.." + std::to_string(run_frames - 1) +
                     ")");
        }
        return f;
    };
    auto readFrames = [&](const YAML::Node& v, const std::string& p) {
        FrameRange r;
        if (v.IsSequence()) {
            if (v.size() != 2) fail(v, p, "expected a frame or a range [first, last]");
            r.first = readFrame(v[0], indexPath(p, 0));
            r.last = readFrame(v[1], indexPath(p, 1));
            if (r.last < r.first) fail(v[1], indexPath(p, 1), "must be >= the first frame");
        } else {
            r.first = r.last = readFrame(v, p);
        }
        return r;
    };
    auto readCount = [&](const YAML::Node& v, const std::string& p) {
        const int c = readInt(v, p);
        if (c < 0) fail(v, p, "must be >= 0");
        return c;
    };
    // A list of expectations that is empty states nothing, which is taken for a mistake; the
    // colour lists inside one expectation may be empty (`needs 'present' or 'absent'` guards).
    auto readList = [&](const YAML::Node& v, const std::string& p, bool may_be_empty = false) {
        if (!v.IsSequence()) fail(v, p, "expected a list");
        if (v.size() == 0 && !may_be_empty) fail(v, p, "empty list: states no expectation");
        std::vector<YAML::Node> out;
        for (std::size_t i = 0; i < v.size(); ++i) out.push_back(v[i]);
        return out;
    };
    // Body names -> index; a name given to several bodies cannot be referred to.
    std::map<std::string, std::vector<BodyId>> by_name;
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
        by_name[scene.bodies[i].name].push_back(static_cast<BodyId>(i));
    }
    auto readBody = [&](const YAML::Node& v, const std::string& p) {
        const std::string name = readString(v, p);
        const auto it = by_name.find(name);
        if (it == by_name.end()) fail(v, p, "no body is named '" + name + "'");
        if (it->second.size() > 1) {
            fail(v, p,
                 "the name '" + name + "' is given to " + std::to_string(it->second.size()) +
                     " bodies");
        }
        return it->second.front();
    };
    auto readState = [&](const YAML::Node& v, const std::string& p) {
        const std::string c = readString(v, p);
        if (c == "green") return BodyState::Apart;
        if (c == "yellow") return BodyState::Flagged;
        if (c == "red") return BodyState::Colliding;
        fail(v, p, "unknown colour '" + c + "' (expected one of: green, yellow, red)");
    };

    for (const Entry& e : es) {
        const std::string p = childPath(path, e.key);
        if (e.key == "min_bodies") {
            ex.min_bodies = readCount(e.value, p);
        } else if (e.key == "min_moving_rotating") {
            ex.min_moving_rotating = readCount(e.value, p);
        } else if (e.key == "energy_drift_max") {
            const Real d = readReal(e.value, p);
            if (!(d >= 0)) fail(e.value, p, "must be >= 0 (relative drift)");
            ex.energy_drift_max = d;
        } else if (e.key == "energy_rise_max") {
            const Real d = readReal(e.value, p);
            if (!(d >= 0)) fail(e.value, p, "must be >= 0 (relative rise)");
            ex.energy_rise_max = d;
        } else if (e.key == "tunnelling" || e.key == "toi") {
            const std::vector<YAML::Node> list = readList(e.value, p);
            for (std::size_t i = 0; i < list.size(); ++i) {
                const std::string ip = indexPath(p, i);
                const bool tunnel = e.key == "tunnelling";
                const std::vector<Entry> te =
                    tunnel ? entries(list[i], ip, {"a", "b", "passes"})
                           : entries(list[i], ip, {"a", "b", "time", "tolerance"});
                const Entry& a = require(te, "a", list[i], ip);
                const Entry& b = require(te, "b", list[i], ip);
                const BodyId ia = readBody(a.value, childPath(ip, "a"));
                const BodyId ib = readBody(b.value, childPath(ip, "b"));
                if (ia == ib) fail(b.value, childPath(ip, "b"), "must differ from 'a'");
                if (tunnel) {
                    TunnelExpectation t{ia, ib, a.value.Scalar(), b.value.Scalar()};
                    t.passes =
                        readBool(require(te, "passes", list[i], ip).value, childPath(ip, "passes"));
                    ex.tunnelling.push_back(std::move(t));
                } else {
                    ToiExpectation t{ia, ib, a.value.Scalar(), b.value.Scalar()};
                    const Entry& time = require(te, "time", list[i], ip);
                    t.time = readReal(time.value, childPath(ip, "time"));
                    if (!(t.time >= 0)) fail(time.value, childPath(ip, "time"), "must be >= 0");
                    const Entry& tol = require(te, "tolerance", list[i], ip);
                    t.tolerance = readReal(tol.value, childPath(ip, "tolerance"));
                    if (!(t.tolerance > 0)) {
                        fail(tol.value, childPath(ip, "tolerance"), "must be > 0");
                    }
                    ex.toi.push_back(std::move(t));
                }
            }
        } else if (e.key == "rest") {
            const std::vector<YAML::Node> list = readList(e.value, p);
            for (std::size_t i = 0; i < list.size(); ++i) {
                const std::string ip = indexPath(p, i);
                const std::vector<Entry> re =
                    entries(list[i], ip, {"body", "frames", "max_displacement", "max_speed"});
                const Entry& body = require(re, "body", list[i], ip);
                RestExpectation r;
                r.body = readBody(body.value, childPath(ip, "body"));
                r.name = body.value.Scalar();
                r.frames =
                    readFrames(require(re, "frames", list[i], ip).value, childPath(ip, "frames"));
                for (const char* key : {"max_displacement", "max_speed"}) {
                    const Entry* m = find(re, key);
                    if (m == nullptr) continue;
                    const Real v = readReal(m->value, childPath(ip, key));
                    if (!(v >= 0)) fail(m->value, childPath(ip, key), "must be >= 0");
                    (std::string_view(key) == "max_speed" ? r.max_speed : r.max_displacement) = v;
                }
                if (!r.max_displacement && !r.max_speed) {
                    fail(list[i], ip, "needs 'max_displacement' or 'max_speed' (or both)");
                }
                ex.rest.push_back(std::move(r));
            }
        } else if (e.key == "broadphases") {
            const std::vector<YAML::Node> list = readList(e.value, p);
            for (std::size_t i = 0; i < list.size(); ++i) {
                const std::string name = readString(list[i], indexPath(p, i));
                if (collision::findBroadPhase(name) == nullptr) {
                    fail(list[i], indexPath(p, i),
                         "unknown broad phase '" + name +
                             "' (expected one of: " + collision::broadPhaseNames() + ")");
                }
                ex.broad_phases.push_back(name);
            }
        } else if (e.key == "pause_dumps") {
            const std::vector<YAML::Node> list = readList(e.value, p);
            for (std::size_t i = 0; i < list.size(); ++i) {
                ex.pause_dumps.push_back(readFrame(list[i], indexPath(p, i)));
            }
        } else if (e.key == "pairs") {
            const std::vector<YAML::Node> list = readList(e.value, p);
            for (std::size_t i = 0; i < list.size(); ++i) {
                const std::string ip = indexPath(p, i);
                const std::vector<Entry> pe =
                    entries(list[i], ip, {"a", "b", "frames", "when", "colliding", "flagged"});
                PairExpectation pair;
                pair.line = list[i].Mark().line + 1;
                pair.column = list[i].Mark().column + 1;
                const Entry& a = require(pe, "a", list[i], ip);
                const Entry& b = require(pe, "b", list[i], ip);
                pair.a = readBody(a.value, childPath(ip, "a"));
                pair.b = readBody(b.value, childPath(ip, "b"));
                pair.a_name = a.value.Scalar();
                pair.b_name = b.value.Scalar();
                if (pair.a == pair.b) fail(b.value, childPath(ip, "b"), "must differ from 'a'");
                pair.frames =
                    readFrames(require(pe, "frames", list[i], ip).value, childPath(ip, "frames"));
                if (const Entry* w = find(pe, "when")) {
                    const std::string when = readString(w->value, childPath(ip, "when"));
                    if (when != "every" && when != "any") {
                        fail(w->value, childPath(ip, "when"),
                             "unknown '" + when + "' (expected one of: every, any)");
                    }
                    pair.every = when == "every";
                }
                if (const Entry* c = find(pe, "colliding")) {
                    pair.colliding = readBool(c->value, childPath(ip, "colliding"));
                }
                if (const Entry* f = find(pe, "flagged")) {
                    pair.flagged = readBool(f->value, childPath(ip, "flagged"));
                }
                if (!pair.colliding && !pair.flagged) {
                    fail(list[i], ip, "needs 'colliding' or 'flagged' (or both)");
                }
                // Confirmed pairs are a subset of flagged pairs.
                if (pair.colliding == true && pair.flagged == false) {
                    fail(find(pe, "flagged")->value, childPath(ip, "flagged"),
                         "a colliding pair is always flagged: 'colliding: true' with "
                         "'flagged: false' can never hold");
                }
                ex.pairs.push_back(std::move(pair));
            }
        } else if (e.key == "colors") {
            const std::vector<YAML::Node> list = readList(e.value, p);
            for (std::size_t i = 0; i < list.size(); ++i) {
                const std::string ip = indexPath(p, i);
                const std::vector<Entry> ce =
                    entries(list[i], ip, {"frame", "present", "absent", "min_pixels"});
                ColorExpectation color;
                color.line = list[i].Mark().line + 1;
                color.column = list[i].Mark().column + 1;
                color.frame =
                    readFrame(require(ce, "frame", list[i], ip).value, childPath(ip, "frame"));
                for (const Entry& c : ce) {
                    const std::string cp = childPath(ip, c.key);
                    if (c.key == "present" || c.key == "absent") {
                        const std::vector<YAML::Node> names = readList(c.value, cp, true);
                        for (std::size_t k = 0; k < names.size(); ++k) {
                            const BodyState st = readState(names[k], indexPath(cp, k));
                            (c.key == "present" ? color.present : color.absent).push_back(st);
                        }
                    } else if (c.key == "min_pixels") {
                        color.min_pixels = readInt(c.value, cp);
                        if (color.min_pixels < 1) fail(c.value, cp, "must be >= 1");
                    }
                }
                for (const BodyState st : color.present) {
                    for (const BodyState other : color.absent) {
                        if (st == other) {
                            fail(list[i], ip, "a colour cannot be both present and absent");
                        }
                    }
                }
                if (color.present.empty() && color.absent.empty()) {
                    fail(list[i], ip, "needs 'present' or 'absent'");
                }
                ex.colors.push_back(std::move(color));
            }
        }
    }
    // `frames` alone sets the run length and checks nothing.
    const bool states_something =
        ex.min_bodies || ex.min_moving_rotating || !ex.broad_phases.empty() ||
        ex.energy_drift_max || ex.energy_rise_max || !ex.pause_dumps.empty() || !ex.pairs.empty() ||
        !ex.colors.empty() || !ex.tunnelling.empty() || !ex.toi.empty() || !ex.rest.empty();
    if (!states_something) {
        fail(entry.key_node, path, "states no expectation (give at least one of: " + kinds + ")");
    }
}

Scene SceneParser::parse(const std::string& text) {
    YAML::Node root;
    try {
        root = YAML::Load(text);
    } catch (const YAML::DeepRecursion& e) {
        fail(e.mark, "malformed YAML", "nesting is too deep");
    } catch (const YAML::ParserException& e) {
        fail(e.mark, "malformed YAML", e.msg);
    } catch (const YAML::Exception& e) {
        fail(e.mark, "malformed YAML", e.msg);
    }
    applyOverrides(root);
    Scene scene;
    scene.name = fs::path(file_).stem().string();
    if (!root.IsMap()) {
        fail(root, "scene",
             "expected a mapping with keys: world, broadphase, output, camera, draw, bodies, "
             "expect");
    }
    // The first document parsed, so the probe's parser (the same one) cannot throw before it
    // reaches the second.
    if (const std::optional<DocumentProbe::Second> second = DocumentProbe::secondDocument(text)) {
        if (second->stalled)
            fail(second->start, "malformed YAML",
                 "text the YAML parser cannot place in the document");
        fail(second->start, "scene",
             "a second YAML document: a scene file holds exactly one (remove the '---' or '...' "
             "and what follows, or merge it into the first)");
    }
    const std::vector<Entry> es =
        entries(root, "", {"world", "broadphase", "output", "camera", "draw", "bodies", "expect"});
    parseWorld(require(es, "world", root, "").value, scene);
    for (const Entry& e : es) {
        if (e.key == "broadphase") {
            const std::string name = readString(e.value, "broadphase");
            if (collision::findBroadPhase(name) == nullptr) {
                fail(e.value, "broadphase",
                     "unknown broad phase '" + name +
                         "' (expected one of: " + collision::broadPhaseNames() + ")");
            }
            scene.world.broad_phase = name;
        } else if (e.key == "output") {
            parseOutput(e.value, scene);
        } else if (e.key == "camera") {
            parseCamera(e.value, scene);
        } else if (e.key == "draw") {
            parseDraw(e.value, scene);
        } else if (e.key == "bodies") {
            if (e.value.IsNull()) continue;  // "bodies:" with nothing after it: no bodies
            if (!e.value.IsSequence()) fail(e.value, "bodies", "expected a list of bodies");
            for (std::size_t i = 0; i < e.value.size(); ++i) {
                if (scene.bodies.size() >= kMaxBodies) {
                    fail(e.value[i], indexPath("bodies", i),
                         "more than " + std::to_string(kMaxBodies) + " bodies in a scene");
                }
                std::vector<Body> made = parseBody(e.value[i], i, scene);
                for (Body& b : made) scene.bodies.push_back(std::move(b));
            }
        }
    }
    if (const Entry* bodies = find(es, "bodies")) {
        const double pairs = estimateStartPairs(scene.bodies);
        if (pairs > double(kMaxCandidatePairs)) {
            fail(bodies->key_node, "bodies",
                 "the bodies' bounding boxes overlap in about " + formatLimit(Real(pairs)) +
                     " pairs at the start, more than the " + std::to_string(kMaxCandidatePairs) +
                     " a step may flag (spread them over a larger repeat.region, or use fewer)");
        }
    }
    if (const Entry* e = find(es, "expect")) parseExpect(*e, scene);
    return scene;
}

void SceneParser::collectOverrideNodes(const YAML::Node& node, const SceneOverride& o) {
    override_nodes_.emplace_back(node, &o);
    if (node.IsSequence()) {
        for (const YAML::Node& child : node) collectOverrideNodes(child, o);
    } else if (node.IsMap()) {
        for (const auto& kv : node) {
            collectOverrideNodes(kv.first, o);
            collectOverrideNodes(kv.second, o);
        }
    }
}

void SceneParser::applyOverrides(YAML::Node& root) {
    for (const SceneOverride& o : overrides_) {
        std::vector<std::string> parts;
        for (std::size_t from = 0;;) {
            const std::size_t dot = o.key.find('.', from);
            parts.push_back(o.key.substr(from, dot == std::string::npos ? dot : dot - from));
            if (dot == std::string::npos) break;
            from = dot + 1;
        }
        for (const std::string& p : parts) {
            if (p.empty()) failOverride(o, o.key, "empty key in the path");
        }
        YAML::Node value;
        try {
            value = YAML::Load(o.value);
        } catch (const YAML::Exception& e) {
            failOverride(o, o.key, "malformed YAML value: " + e.msg);
        }
        collectOverrideNodes(value, o);
        if (!root.IsDefined() || root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
        // Node::reset rebinds; plain assignment between nodes would overwrite the content.
        YAML::Node node;
        node.reset(root);
        for (std::size_t i = 0; i < parts.size(); ++i) {
            const std::string& p = parts[i];
            const bool last = i + 1 == parts.size();
            if (node.IsSequence()) {
                const bool digits =
                    std::all_of(p.begin(), p.end(), [](char c) { return c >= '0' && c <= '9'; });
                const std::size_t index = digits && p.size() < 9 ? std::stoul(p) : node.size();
                if (index >= node.size()) {
                    failOverride(o, o.key,
                                 "'" + p + "' is not an index of this list of " +
                                     std::to_string(node.size()));
                }
                if (last) {
                    node[index] = value;
                } else {
                    YAML::Node child = node[index];
                    node.reset(child);
                }
            } else if (node.IsMap() || node.IsNull()) {
                if (last) {
                    node[p] = value;
                } else {
                    YAML::Node child = node[p];
                    if (!child.IsDefined() || child.IsNull()) {
                        node[p] = YAML::Node(YAML::NodeType::Map);
                        child = node[p];
                    }
                    node.reset(child);
                }
            } else {
                failOverride(o, o.key, "'" + p + "' is below a value, not a mapping or list");
            }
        }
    }
}

}  // namespace

namespace {

// Runs the parser; any failure that escaped its key still names a position.
Scene runParser(SceneParser& parser, const std::string& text, const std::string& display_name) {
    try {
        return parser.parse(text);
    } catch (const SceneError&) {
        throw;
    } catch (const YAML::Exception& e) {
        throw SceneError(formatMessage(display_name, e.mark, "scene", e.msg));
    } catch (const std::exception& e) {
        throw SceneError(formatMessage(display_name, YAML::Mark::null_mark(), "scene", e.what()));
    }
}

}  // namespace

Scene parseScene(const std::string& yaml_text, const std::string& display_name,
                 const std::filesystem::path& base_dir) {
    return parseScene(yaml_text, display_name, base_dir, {});
}

Scene parseScene(const std::string& yaml_text, const std::string& display_name,
                 const std::filesystem::path& base_dir,
                 const std::vector<SceneOverride>& overrides) {
    SceneParser parser(display_name, base_dir);
    parser.setOverrides(overrides);
    return runParser(parser, yaml_text, display_name);
}

Scene loadScene(const std::filesystem::path& file) { return loadScene(file, {}); }

Scene loadScene(const std::filesystem::path& file, const std::vector<SceneOverride>& overrides) {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) {
        throw SceneError(file.string() + ":1:1: scene: cannot open the file (" +
                         (fs::exists(file, ec) ? "not a regular file" : "no such file") + ")");
    }
    // yaml-cpp's nodes take about 100 bytes of memory per byte of a long list (a 50 MB file took
    // 4.8 GB): files past kMaxSceneBytes are refused before parsing. Large populations belong in
    // `repeat:`, which costs a few lines.
    constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t(16) << 20;
    const std::uintmax_t bytes = fs::file_size(file, ec);
    if (!ec && bytes > kMaxSceneBytes) {
        throw SceneError(file.string() + ":1:1: scene: the file has " + std::to_string(bytes) +
                         " bytes, more than the limit of " + std::to_string(kMaxSceneBytes) +
                         " (16 MiB); describe large populations with repeat:");
    }
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in.good() && !in.eof()) {
        throw SceneError(file.string() + ":1:1: scene: cannot read the file");
    }
    fs::path base = file.parent_path();
    if (base.empty()) base = ".";
    SceneParser parser(file.string(), base);
    parser.setOverrides(overrides);
    return runParser(parser, text.str(), file.string());
}

World makeWorld(const Scene& scene) {
    World world(scene.world);
    for (const Body& b : scene.bodies) world.addBody(b);
    world.detect();
    return world;
}

}  // namespace engine
