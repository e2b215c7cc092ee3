// engine/src/scene_chains.cpp -- the scene's `chains:` section: articulated chains of links
// joined by revolute, prismatic or fixed joints with prescribed trajectories. Each link is read
// with the bodies' own shape keys (scene_bodies.cpp) and becomes a kinematic body appended to
// the scene's bodies; link names are unique among all bodies, so expectations name links.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "scene_parser.h"

namespace engine::scene_parsing {

namespace {

constexpr std::string_view kChainKeys[] = {"name", "base", "collide_adjacent", "on_impact",
                                           "links"};

// A link takes a body's shape keys (and its material) plus its place in the chain. Mass and
// velocity do not apply: a link is kinematic.
constexpr std::string_view kLinkKeys[] = {"name",         "shape", "radius",      "half_height",
                                          "half_extents", "file",  "scale",       "offset",
                                          "parent",       "joint", "restitution", "friction"};

// Joint values and times beyond these are typing mistakes; they also keep every product of the
// forward kinematics finite.
constexpr Real kMaxJointValue = Real(1e6);      // deg, m, deg/s, m/s
constexpr Real kMaxJointTime = Real(1e9);       // s
constexpr Real kMaxJointFrequency = Real(1e3);  // Hz, as `deform.frequency`
// An axis shorter than this (as written; it is normalised) has no direction.
constexpr Real kMinAxisLength = Real(1e-9);

}  // namespace

Pose SceneParser::readPlacement(const YAML::Node& n, const std::string& path) const {
    const std::vector<Entry> es = entries(n, path, {"position", "euler_deg"});
    Pose pose;
    for (const Entry& e : es) {
        const std::string p = childPath(path, e.key);
        const Vec3 v = readVec3(e.value, p);
        for (int k = 0; k < 3; ++k) {
            if (!(std::abs(v[k]) <= kMaxWorldCoordinate)) {
                fail(e.value[static_cast<std::size_t>(k)], indexPath(p, std::size_t(k)),
                     "must be within +-" + formatLimit(kMaxWorldCoordinate));
            }
        }
        if (e.key == "position") pose.position = v;
        if (e.key == "euler_deg") pose.orientation = eulerDegrees(v);
    }
    return pose;
}

// One joint trajectory; `unit` converts the file's values (degrees or metres) to the joint's
// (radians or metres). Every value is checked at its key.
collision::JointTrajectory SceneParser::readMotion(const YAML::Node& n, const std::string& path,
                                                   Real unit) const {
    using Kind = collision::JointTrajectory::Kind;
    const std::vector<Entry> es = entries(n, path, {"constant", "ramp", "sine", "keyframes"});
    if (es.size() != 1) {
        fail(n, path, "expected exactly one of: constant, ramp, sine, keyframes");
    }
    const Entry& e = es.front();
    const std::string p = childPath(path, e.key);
    auto value = [&](const YAML::Node& v, const std::string& vp) {
        const Real x = readReal(v, vp);
        if (!(std::abs(x) <= kMaxJointValue)) {
            fail(v, vp, "must be within +-" + formatLimit(kMaxJointValue));
        }
        return x * unit;
    };
    collision::JointTrajectory t;
    if (e.key == "constant") {
        t.kind = Kind::Constant;
        t.value = value(e.value, p);
    } else if (e.key == "ramp") {
        t.kind = Kind::Ramp;
        const std::vector<Entry> re = entries(e.value, p, {"start", "rate"});
        if (const Entry* s = find(re, "start")) t.value = value(s->value, childPath(p, "start"));
        t.rate = value(require(re, "rate", e.value, p).value, childPath(p, "rate"));
    } else if (e.key == "sine") {
        t.kind = Kind::Sine;
        const std::vector<Entry> se =
            entries(e.value, p, {"amplitude", "frequency", "phase_deg", "offset"});
        t.amplitude = value(require(se, "amplitude", e.value, p).value, childPath(p, "amplitude"));
        const Entry& f = require(se, "frequency", e.value, p);
        t.frequency = readReal(f.value, childPath(p, "frequency"));
        if (!(t.frequency > 0 && t.frequency <= kMaxJointFrequency)) {
            fail(f.value, childPath(p, "frequency"),
                 "must be in (0, " + formatLimit(kMaxJointFrequency) + "] (Hz)");
        }
        if (const Entry* ph = find(se, "phase_deg")) {
            const Real deg = readReal(ph->value, childPath(p, "phase_deg"));
            if (!(std::abs(deg) <= kMaxJointValue)) {
                fail(ph->value, childPath(p, "phase_deg"),
                     "must be within +-" + formatLimit(kMaxJointValue));
            }
            t.phase = deg * (std::numbers::pi_v<Real> / 180);
        }
        if (const Entry* o = find(se, "offset")) t.value = value(o->value, childPath(p, "offset"));
    } else {
        t.kind = Kind::Keyframes;
        if (!e.value.IsSequence() || e.value.size() == 0) {
            fail(e.value, p, "expected a list of [time s, value] pairs");
        }
        for (std::size_t i = 0; i < e.value.size(); ++i) {
            const YAML::Node k = e.value[i];
            const std::string kp = indexPath(p, i);
            if (!k.IsSequence() || k.size() != 2) fail(k, kp, "expected [time s, value]");
            const Real time = readReal(k[0], indexPath(kp, 0));
            if (!(std::abs(time) <= kMaxJointTime)) {
                fail(k[0], indexPath(kp, 0), "must be within +-" + formatLimit(kMaxJointTime));
            }
            if (!t.keys.empty() && !(time > t.keys.back().first)) {
                fail(k[0], indexPath(kp, 0),
                     "key times must increase strictly (the previous key is at " +
                         formatLimit(t.keys.back().first) + " s)");
            }
            t.keys.emplace_back(time, value(k[1], indexPath(kp, 1)));
        }
    }
    return t;
}

collision::ChainJoint SceneParser::readJoint(const YAML::Node& n, const std::string& path) const {
    const std::vector<Entry> es = entries(n, path, {"type", "axis", "origin", "motion"});
    collision::ChainJoint j;
    const Entry& type = require(es, "type", n, path);
    const std::string name = readString(type.value, childPath(path, "type"));
    Real unit = 1;
    if (name == "revolute") {
        j.type = collision::JointType::Revolute;
        unit = std::numbers::pi_v<Real> / 180;  // the file's angles are degrees
    } else if (name == "prismatic") {
        j.type = collision::JointType::Prismatic;
    } else if (name == "fixed") {
        j.type = collision::JointType::Fixed;
    } else {
        fail(type.value, childPath(path, "type"),
             "unknown joint type '" + name + "' (expected one of: revolute, prismatic, fixed)");
    }
    if (const Entry* axis = find(es, "axis")) {
        const std::string p = childPath(path, "axis");
        if (j.type == collision::JointType::Fixed) {
            fail(axis->key_node, p, "does not apply to a fixed joint");
        }
        const Vec3 a = readVec3(axis->value, p);
        const Real len = a.stableNorm();
        if (!(len > kMinAxisLength) || !std::isfinite(len)) {
            fail(axis->value, p, "must be a non-zero direction (it is normalised)");
        }
        j.axis = a / len;
    } else if (j.type != collision::JointType::Fixed) {
        require(es, "axis", n, path);
    }
    if (const Entry* origin = find(es, "origin")) {
        j.origin = readPlacement(origin->value, childPath(path, "origin"));
    }
    if (const Entry* motion = find(es, "motion")) {
        const std::string p = childPath(path, "motion");
        if (j.type == collision::JointType::Fixed) {
            fail(motion->key_node, p, "does not apply to a fixed joint");
        }
        j.trajectory = readMotion(motion->value, p, unit);
    } else if (j.type != collision::JointType::Fixed) {
        require(es, "motion", n, path);
    }
    return j;
}

void SceneParser::parseLink(const YAML::Node& n, const std::string& path,
                            const std::string& chain_name, std::size_t index, Scene& scene,
                            ChainSpec& chain, std::map<std::string, std::string>& names,
                            std::map<std::string, int>& link_index) {
    const std::vector<Entry> es =
        entries(n, path, std::vector<std::string_view>(std::begin(kLinkKeys), std::end(kLinkKeys)));
    std::string shape_name;
    std::vector<std::string_view> shape_keys;
    const ShapeType type = bodyShape(es, n, path, shape_name, shape_keys);
    BodyValues values = readBodyValues(es, n, path, chain_name + "_" + std::to_string(index),
                                       shape_keys, scene, /*needs_position=*/false);
    Shape shape;
    const MassProperties props =
        bodyMassProperties(es, path, type, shape_keys, values, scene, shape);
    const YAML::Node name_node = find(es, "name") != nullptr ? find(es, "name")->value : n;
    const std::string name_path = find(es, "name") != nullptr ? childPath(path, "name") : path;
    if (const auto it = names.find(values.name); it != names.end()) {
        fail(name_node, name_path,
             "the name '" + values.name + "' is already taken by " + it->second +
                 "; body and link names must be unique");
    }
    if (values.name == "base") fail(name_node, name_path, "'base' names the chain's base frame");
    names.emplace(values.name, path);

    collision::ChainJoint joint;
    const Entry& joint_entry = require(es, "joint", n, path);
    joint = readJoint(joint_entry.value, childPath(path, "joint"));
    // The parent: the previous link by default (the base for the first).
    joint.parent = static_cast<int>(index) - 1;
    if (const Entry* parent = find(es, "parent")) {
        const std::string p = childPath(path, "parent");
        const std::string pname = readString(parent->value, p);
        if (pname == "base") {
            joint.parent = -1;
        } else if (const auto it = link_index.find(pname); it != link_index.end()) {
            joint.parent = it->second;
        } else {
            fail(parent->value, p,
                 "no earlier link of chain '" + chain_name + "' is named '" + pname +
                     "' (a parent is 'base' or a link listed before this one)");
        }
    }
    link_index.emplace(values.name, static_cast<int>(index));

    Pose offset;
    if (const Entry* o = find(es, "offset"))
        offset = readPlacement(o->value, childPath(path, "offset"));
    // The body frame is the shape re-centred at its centre of mass (mesh and hull shapes).
    const Pose shape_in_link = offset * Pose{props.center_of_mass, Quat::Identity()};

    Body body = makeBody(values.name, std::move(shape), props);
    body.restitution = values.restitution;
    body.friction = values.friction;
    setStatic(body);
    body.kinematic = true;
    const Real radius = shape_in_link.position.norm() + body.local_bounds.sphere.center.norm() +
                        body.local_bounds.sphere.radius;

    chain.chain.joints.push_back(std::move(joint));
    chain.chain.link_radius.push_back(radius);
    chain.shape_in_link.push_back(shape_in_link);
    chain.links.push_back(static_cast<BodyId>(scene.bodies.size()));
    scene.bodies.push_back(std::move(body));
}

void SceneParser::parseChain(const YAML::Node& n, std::size_t index, Scene& scene,
                             std::map<std::string, std::string>& names) {
    const std::string path = indexPath("chains", index);
    const std::vector<Entry> es = entries(
        n, path, std::vector<std::string_view>(std::begin(kChainKeys), std::end(kChainKeys)));
    ChainSpec chain;
    chain.name = "chain" + std::to_string(index);
    if (const Entry* name = find(es, "name")) {
        chain.name = readString(name->value, childPath(path, "name"));
        if (chain.name.empty()) fail(name->value, childPath(path, "name"), "must not be empty");
    }
    for (const ChainSpec& other : scene.chains) {
        if (other.name == chain.name) {
            const Entry* name = find(es, "name");
            fail(
                name != nullptr ? name->value : n, childPath(path, "name"),
                "the chain name '" + chain.name + "' is already taken; chain names must be unique");
        }
    }
    if (const Entry* base = find(es, "base")) {
        const std::string p = childPath(path, "base");
        chain.chain.base = readPlacement(base->value, p);
        if (!scene.world.bounds.contains(chain.chain.base.position)) {
            fail(base->value, p, "the base position is outside the world bounds");
        }
    }
    if (const Entry* adjacent = find(es, "collide_adjacent")) {
        chain.collide_adjacent = readBool(adjacent->value, childPath(path, "collide_adjacent"));
    }
    if (const Entry* impact = find(es, "on_impact")) {
        const std::string p = childPath(path, "on_impact");
        const std::string v = readString(impact->value, p);
        if (v == "stop") {
            chain.on_impact = ChainImpact::Stop;
        } else if (v == "continue") {
            chain.on_impact = ChainImpact::Continue;
        } else {
            fail(impact->value, p, "unknown value '" + v + "' (expected one of: stop, continue)");
        }
    }
    const Entry& links = require(es, "links", n, path);
    const std::string lp = childPath(path, "links");
    if (!links.value.IsSequence() || links.value.size() == 0) {
        fail(links.value, lp, "expected a non-empty list of links");
    }
    std::map<std::string, int> link_index;
    for (std::size_t i = 0; i < links.value.size(); ++i) {
        if (scene.bodies.size() >= kMaxBodies) {
            fail(links.value[i], indexPath(lp, i),
                 "more than " + std::to_string(kMaxBodies) + " bodies in a scene");
        }
        parseLink(links.value[i], indexPath(lp, i), chain.name, i, scene, chain, names, link_index);
    }
    scene.chains.push_back(std::move(chain));
}

void SceneParser::parseChains(const Entry& entry, Scene& scene) {
    if (entry.value.IsNull()) return;
    if (!entry.value.IsSequence()) fail(entry.value, "chains", "expected a list of chains");
    if (scene.world.response != Response::None) {
        fail(entry.key_node, "chains",
             "chains need world.response: none (the contact solver has no kinematic bodies; "
             "links are moved by their trajectories, not by contacts)");
    }
    std::map<std::string, std::string> names;
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
        names.emplace(scene.bodies[i].name, "a body of 'bodies'");
    }
    for (std::size_t i = 0; i < entry.value.size(); ++i) {
        parseChain(entry.value[i], i, scene, names);
    }
}

}  // namespace engine::scene_parsing
