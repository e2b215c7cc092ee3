// engine/src/scene_parser.cpp -- SceneParser's frame: the YAML helpers (typed reads that check
// every value, error messages with the node's position), the whole-document checks, --set
// overrides, and parse(), which reads the sections in order (scene_parser.h).
#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <utility>

#include "collision/broadphase/broad_phase.h"
#include "collision/bvh/bvh.h"
#include "collision/geometry/convex_hull.h"
#include "engine/mass_properties.h"
#include "engine/mesh_import.h"
#include "scene_parser.h"

namespace engine::scene_parsing {

namespace {

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

}  // namespace

Quat eulerDegrees(const Vec3& deg) {
    const Vec3 rad = deg * (std::numbers::pi_v<Real> / 180);
    Quat q = Quat(Eigen::AngleAxis<Real>(rad.x(), Vec3::UnitX())) *
             Quat(Eigen::AngleAxis<Real>(rad.y(), Vec3::UnitY())) *
             Quat(Eigen::AngleAxis<Real>(rad.z(), Vec3::UnitZ()));
    q.normalize();
    return q;
}

std::string formatLimit(Real v) {
    std::ostringstream s;
    s << std::setprecision(6) << v;
    return s.str();
}

std::string speedProblem(Real speed, const WorldSettings& world) {
    const Real diagonal = (world.bounds.max - world.bounds.min).norm();
    const Real limit = kMaxTravelPerStep * diagonal / world.time_step;
    if (std::isfinite(speed) && speed <= limit) return "";
    return "speed " + formatLimit(speed) + " m/s is beyond what the world can integrate: at most " +
           formatLimit(limit) + " m/s (" + formatLimit(kMaxTravelPerStep) +
           " world diagonals per time step)";
}

std::string spinProblem(Real rate, const WorldSettings& world) {
    const Real limit = kMaxTurnPerStep / world.time_step;
    if (std::isfinite(rate) && rate <= limit) return "";
    return "angular speed " + formatLimit(rate) +
           " rad/s is beyond what the world can integrate: " + "at most " + formatLimit(limit) +
           " rad/s (" + formatLimit(kMaxTurnPerStep) + " rad per time step)";
}

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

YAML::Node SceneParser::loadDocument(const std::string& text) const {
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
    // The first document parsed, so the probe's parser (the same one) cannot throw before it
    // reaches the second.
    if (const std::optional<DocumentProbe::Second> second = DocumentProbe::secondDocument(text)) {
        if (second->stalled)
            fail(second->start, "malformed YAML",
                 "text the YAML parser cannot place in the document");
        fail(second->start, "scene",
             "a second YAML document: a file holds exactly one (remove the '---' or '...' "
             "and what follows, or merge it into the first)");
    }
    return root;
}

Scene SceneParser::parse(const std::string& text) {
    YAML::Node root = loadDocument(text);
    applyOverrides(root);
    Scene scene;
    scene.name = fs::path(file_).stem().string();
    if (!root.IsMap()) {
        fail(root, "scene",
             "expected a mapping with keys: world, broadphase, pair_order, output, camera, draw, "
             "bodies, chains, expect, events");
    }
    const std::vector<Entry> es = entries(root, "",
                                          {"world", "broadphase", "pair_order", "output", "camera",
                                           "draw", "bodies", "chains", "expect", "events"});
    // The output's frame rate first: the world's default time step is derived from it.
    if (const Entry* output = find(es, "output")) parseOutput(output->value, scene);
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
        } else if (e.key == "pair_order") {
            const std::string name = readString(e.value, "pair_order");
            const std::optional<collision::PairOrder> order = collision::findPairOrder(name);
            if (!order) {
                fail(e.value, "pair_order",
                     "unknown pair order '" + name +
                         "' (expected one of: " + collision::pairOrderNames() + ")");
            }
            scene.world.pair_order = *order;
        } else if (e.key == "camera") {
            parseCamera(e.value, scene);
        } else if (e.key == "draw") {
            parseDraw(e.value, scene);
        } else if (e.key == "bodies") {
            if (e.value.IsNull()) continue;  // "bodies:" with nothing after it: no bodies
            if (!e.value.IsSequence()) fail(e.value, "bodies", "expected a list of bodies");
            std::unordered_map<std::string, std::size_t> first_entry_of_name;
            for (std::size_t i = 0; i < e.value.size(); ++i) {
                if (scene.bodies.size() >= kMaxBodies) {
                    fail(e.value[i], indexPath("bodies", i),
                         "more than " + std::to_string(kMaxBodies) + " bodies in a scene");
                }
                std::vector<Body> made = parseBody(e.value[i], i, scene);
                for (Body& b : made) {
                    requireUniqueName(b.name, e.value[i], i, first_entry_of_name);
                    scene.bodies.push_back(std::move(b));
                }
            }
        }
    }
    if (const Entry* chains = find(es, "chains")) parseChains(*chains, scene);
    if (scene.bodies.empty()) {
        const Entry* bodies = find(es, "bodies");
        fail(bodies != nullptr ? bodies->key_node : root, "bodies",
             "a scene needs at least one body (a list under 'bodies:', or a chain's links)");
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
    if (const Entry* e = find(es, "expect")) {
        parseExpect(*e, scene, scene.expect, find(es, "events") != nullptr);
    }
    if (const Entry* e = find(es, "events")) parseEvents(*e, scene);
    scene.notes = std::move(notes_);
    return scene;
}

void SceneParser::requireUniqueName(
    const std::string& name, const YAML::Node& entry, std::size_t index,
    std::unordered_map<std::string, std::size_t>& first_entry_of_name) const {
    // Expectations, traces, pause dumps and --set refer to bodies by name, so a name that two
    // bodies share would refer to neither.
    const auto [it, inserted] = first_entry_of_name.emplace(name, index);
    if (inserted) return;
    const YAML::Node name_node = entry.IsMap() ? entry["name"] : YAML::Node();
    const bool generated = entry.IsMap() && entry["repeat"];
    std::string what = "the body name '" + name + "' is already taken by bodies[" +
                       std::to_string(it->second) + "]";
    if (it->second == index) what = "repeat generates the name '" + name + "' twice";
    if (generated) {
        what += " (repeat names its bodies <name>_0, <name>_1, ...)";
    } else if (!name_node) {
        what += " (a body without a name is called <shape><index>)";
    }
    fail(name_node ? name_node : entry, name_node ? childPath(indexPath("bodies", index), "name")
                                                  : indexPath("bodies", index),
         what + "; body names must be unique");
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

}  // namespace engine::scene_parsing
