// engine/src/scene_expect.cpp -- the scene's `expect:` section: what `cdlab check` grades
// (after the bodies, whose names it refers to).
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

}  // namespace engine::scene_parsing
