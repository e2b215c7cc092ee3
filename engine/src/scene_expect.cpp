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

// Reads the lists of `expect:` for one scene: frames inside the run, bodies by unique name,
// colours. Every value is checked where it is read (SceneParser::fail names its position).
class ExpectReader {
public:
    ExpectReader(const SceneParser& parser, const Scene& scene, int run_frames)
        : p_(parser), run_frames_(run_frames) {
        // Body names -> index (the loader has made them unique).
        for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
            by_name_.emplace(scene.bodies[i].name, static_cast<BodyId>(i));
        }
    }

    int readFrame(const YAML::Node& v, const std::string& p) const {
        const int f = p_.readInt(v, p);
        if (f < 0 || f >= run_frames_) {
            p_.fail(v, p,
                    "frame out of range (the check runs frames 0.." +
                        std::to_string(run_frames_ - 1) + ")");
        }
        return f;
    }
    FrameRange readFrames(const YAML::Node& v, const std::string& p) const {
        FrameRange r;
        if (v.IsSequence()) {
            if (v.size() != 2) p_.fail(v, p, "expected a frame or a range [first, last]");
            r.first = readFrame(v[0], indexPath(p, 0));
            r.last = readFrame(v[1], indexPath(p, 1));
            if (r.last < r.first) p_.fail(v[1], indexPath(p, 1), "must be >= the first frame");
        } else {
            r.first = r.last = readFrame(v, p);
        }
        return r;
    }
    int readCount(const YAML::Node& v, const std::string& p) const {
        const int c = p_.readInt(v, p);
        if (c < 0) p_.fail(v, p, "must be >= 0");
        return c;
    }
    // A list of expectations that is empty states nothing, which is taken for a mistake; the
    // colour lists inside one expectation may be empty (`needs 'present' or 'absent'` guards).
    std::vector<YAML::Node> readList(const YAML::Node& v, const std::string& p,
                                     bool may_be_empty = false) const {
        if (!v.IsSequence()) p_.fail(v, p, "expected a list");
        if (v.size() == 0 && !may_be_empty) p_.fail(v, p, "empty list: states no expectation");
        std::vector<YAML::Node> out;
        for (std::size_t i = 0; i < v.size(); ++i) out.push_back(v[i]);
        return out;
    }
    BodyId readBody(const YAML::Node& v, const std::string& p) const {
        const std::string name = p_.readString(v, p);
        const auto it = by_name_.find(name);
        if (it == by_name_.end()) p_.fail(v, p, "no body is named '" + name + "'");
        return it->second;
    }
    BodyState readState(const YAML::Node& v, const std::string& p) const {
        const std::string c = p_.readString(v, p);
        if (c == "green") return BodyState::Apart;
        if (c == "yellow") return BodyState::Flagged;
        if (c == "red") return BodyState::Colliding;
        p_.fail(v, p, "unknown colour '" + c + "' (expected one of: green, yellow, red)");
    }

    /// `tunnelling` and `toi`: pairs of bodies, with what passes through or the time of impact.
    void tunnellingOrToi(const Entry& e, const std::string& p, Expectations& ex) const;
    void rest(const Entry& e, const std::string& p, Expectations& ex) const;
    void selfCollision(const Entry& e, const std::string& p, Expectations& ex,
                       const Scene& scene) const;
    /// `broadphases` and `broadphases_in_use`: registry names.
    void broadPhases(const Entry& e, const std::string& p, std::vector<std::string>& names) const;
    void pauseDumps(const Entry& e, const std::string& p, Expectations& ex) const;
    void pairs(const Entry& e, const std::string& p, Expectations& ex) const;
    void colors(const Entry& e, const std::string& p, Expectations& ex) const;

private:
    const SceneParser& p_;
    int run_frames_;
    std::map<std::string, BodyId> by_name_;
};

void ExpectReader::tunnellingOrToi(const Entry& e, const std::string& p, Expectations& ex) const {
        const std::vector<YAML::Node> list = readList(e.value, p);
        for (std::size_t i = 0; i < list.size(); ++i) {
            const std::string ip = indexPath(p, i);
            const bool tunnel = e.key == "tunnelling";
            const std::vector<Entry> te =
                tunnel ? p_.entries(list[i], ip, {"a", "b", "passes"})
                       : p_.entries(list[i], ip, {"a", "b", "time", "tolerance"});
            const Entry& a = p_.require(te, "a", list[i], ip);
            const Entry& b = p_.require(te, "b", list[i], ip);
            const BodyId ia = readBody(a.value, childPath(ip, "a"));
            const BodyId ib = readBody(b.value, childPath(ip, "b"));
            if (ia == ib) p_.fail(b.value, childPath(ip, "b"), "must differ from 'a'");
            if (tunnel) {
                TunnelExpectation t{ia, ib, a.value.Scalar(), b.value.Scalar()};
                const Entry& passes = p_.require(te, "passes", list[i], ip);
                t.passes = p_.readBool(passes.value, childPath(ip, "passes"));
                ex.tunnelling.push_back(std::move(t));
            } else {
                ToiExpectation t{ia, ib, a.value.Scalar(), b.value.Scalar()};
                const Entry& time = p_.require(te, "time", list[i], ip);
                t.time = p_.readReal(time.value, childPath(ip, "time"));
                if (!(t.time >= 0)) p_.fail(time.value, childPath(ip, "time"), "must be >= 0");
                const Entry& tol = p_.require(te, "tolerance", list[i], ip);
                t.tolerance = p_.readReal(tol.value, childPath(ip, "tolerance"));
                if (!(t.tolerance > 0)) {
                    p_.fail(tol.value, childPath(ip, "tolerance"), "must be > 0");
                }
                ex.toi.push_back(std::move(t));
            }
        }
}

void ExpectReader::rest(const Entry& e, const std::string& p, Expectations& ex) const {
        const std::vector<YAML::Node> list = readList(e.value, p);
        for (std::size_t i = 0; i < list.size(); ++i) {
            const std::string ip = indexPath(p, i);
            const std::vector<Entry> re =
                p_.entries(list[i], ip, {"body", "frames", "max_displacement", "max_speed"});
            const Entry& body = p_.require(re, "body", list[i], ip);
            RestExpectation r;
            r.body = readBody(body.value, childPath(ip, "body"));
            r.name = body.value.Scalar();
            r.frames =
                readFrames(p_.require(re, "frames", list[i], ip).value, childPath(ip, "frames"));
            for (const char* key : {"max_displacement", "max_speed"}) {
                const Entry* m = p_.find(re, key);
                if (m == nullptr) continue;
                const Real v = p_.readReal(m->value, childPath(ip, key));
                if (!(v >= 0)) p_.fail(m->value, childPath(ip, key), "must be >= 0");
                (std::string_view(key) == "max_speed" ? r.max_speed : r.max_displacement) = v;
            }
            if (!r.max_displacement && !r.max_speed) {
                p_.fail(list[i], ip, "needs 'max_displacement' or 'max_speed' (or both)");
            }
            ex.rest.push_back(std::move(r));
        }
}

void ExpectReader::selfCollision(const Entry& e, const std::string& p, Expectations& ex,
                                 const Scene& scene) const {
    const std::vector<YAML::Node> list = readList(e.value, p);
    for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string ip = indexPath(p, i);
        const std::vector<Entry> se =
            p_.entries(list[i], ip, {"body", "frames", "min_pairs", "max_pairs"});
        const Entry& body = p_.require(se, "body", list[i], ip);
        SelfCollisionExpectation s;
        s.body = readBody(body.value, childPath(ip, "body"));
        s.name = body.value.Scalar();
        if (!scene.bodies[static_cast<std::size_t>(s.body)].self_collision) {
            p_.fail(body.value, childPath(ip, "body"),
                    "'" + s.name + "' does not have 'self_collision: true'");
        }
        s.frames = readFrames(p_.require(se, "frames", list[i], ip).value, childPath(ip, "frames"));
        if (const Entry* m = p_.find(se, "min_pairs")) {
            s.min_pairs = readCount(m->value, childPath(ip, "min_pairs"));
        }
        if (const Entry* m = p_.find(se, "max_pairs")) {
            s.max_pairs = readCount(m->value, childPath(ip, "max_pairs"));
        }
        if (!s.min_pairs && !s.max_pairs) {
            p_.fail(list[i], ip, "needs 'min_pairs' or 'max_pairs' (or both)");
        }
        if (s.min_pairs && s.max_pairs && *s.max_pairs < *s.min_pairs) {
            p_.fail(p_.find(se, "max_pairs")->value, childPath(ip, "max_pairs"),
                    "must be >= 'min_pairs'");
        }
        ex.self_collision.push_back(std::move(s));
    }
}

void ExpectReader::broadPhases(const Entry& e, const std::string& p,
                               std::vector<std::string>& names) const {
        const std::vector<YAML::Node> list = readList(e.value, p);
        for (std::size_t i = 0; i < list.size(); ++i) {
            const std::string name = p_.readString(list[i], indexPath(p, i));
            if (collision::findBroadPhase(name) == nullptr) {
                p_.fail(list[i], indexPath(p, i),
                     "unknown broad phase '" + name +
                         "' (expected one of: " + collision::broadPhaseNames() + ")");
            }
            // `broadphases` always refused nothing here; a name listed twice in the list of
            // those in use would grade one broad phase under two rows.
            if (e.key == "broadphases_in_use" &&
                std::find(names.begin(), names.end(), name) != names.end()) {
                p_.fail(list[i], indexPath(p, i), "'" + name + "' is listed twice");
            }
            names.push_back(name);
        }
}

void ExpectReader::pauseDumps(const Entry& e, const std::string& p, Expectations& ex) const {
        const std::vector<YAML::Node> list = readList(e.value, p);
        for (std::size_t i = 0; i < list.size(); ++i) {
            ex.pause_dumps.push_back(readFrame(list[i], indexPath(p, i)));
        }
}

void ExpectReader::pairs(const Entry& e, const std::string& p, Expectations& ex) const {
        const std::vector<YAML::Node> list = readList(e.value, p);
        for (std::size_t i = 0; i < list.size(); ++i) {
            const std::string ip = indexPath(p, i);
            const std::vector<Entry> pe =
                p_.entries(list[i], ip, {"a", "b", "frames", "when", "colliding", "flagged"});
            PairExpectation pair;
            pair.line = list[i].Mark().line + 1;
            pair.column = list[i].Mark().column + 1;
            const Entry& a = p_.require(pe, "a", list[i], ip);
            const Entry& b = p_.require(pe, "b", list[i], ip);
            pair.a = readBody(a.value, childPath(ip, "a"));
            pair.b = readBody(b.value, childPath(ip, "b"));
            pair.a_name = a.value.Scalar();
            pair.b_name = b.value.Scalar();
            if (pair.a == pair.b) p_.fail(b.value, childPath(ip, "b"), "must differ from 'a'");
            pair.frames =
                readFrames(p_.require(pe, "frames", list[i], ip).value, childPath(ip, "frames"));
            if (const Entry* w = p_.find(pe, "when")) {
                const std::string when = p_.readString(w->value, childPath(ip, "when"));
                if (when != "every" && when != "any") {
                    p_.fail(w->value, childPath(ip, "when"),
                         "unknown '" + when + "' (expected one of: every, any)");
                }
                pair.every = when == "every";
            }
            if (const Entry* c = p_.find(pe, "colliding")) {
                pair.colliding = p_.readBool(c->value, childPath(ip, "colliding"));
            }
            if (const Entry* f = p_.find(pe, "flagged")) {
                pair.flagged = p_.readBool(f->value, childPath(ip, "flagged"));
            }
            if (!pair.colliding && !pair.flagged) {
                p_.fail(list[i], ip, "needs 'colliding' or 'flagged' (or both)");
            }
            // Confirmed pairs are a subset of flagged pairs.
            if (pair.colliding == true && pair.flagged == false) {
                p_.fail(p_.find(pe, "flagged")->value, childPath(ip, "flagged"),
                     "a colliding pair is always flagged: 'colliding: true' with "
                     "'flagged: false' can never hold");
            }
            ex.pairs.push_back(std::move(pair));
        }
}

void ExpectReader::colors(const Entry& e, const std::string& p, Expectations& ex) const {
        const std::vector<YAML::Node> list = readList(e.value, p);
        for (std::size_t i = 0; i < list.size(); ++i) {
            const std::string ip = indexPath(p, i);
            const std::vector<Entry> ce =
                p_.entries(list[i], ip, {"frame", "present", "absent", "min_pixels", "volume"});
            ColorExpectation color;
            color.line = list[i].Mark().line + 1;
            color.column = list[i].Mark().column + 1;
            color.frame =
                readFrame(p_.require(ce, "frame", list[i], ip).value, childPath(ip, "frame"));
            for (const Entry& c : ce) {
                const std::string cp = childPath(ip, c.key);
                if (c.key == "present" || c.key == "absent") {
                    const std::vector<YAML::Node> names = readList(c.value, cp, true);
                    for (std::size_t k = 0; k < names.size(); ++k) {
                        const BodyState st = readState(names[k], indexPath(cp, k));
                        (c.key == "present" ? color.present : color.absent).push_back(st);
                    }
                } else if (c.key == "min_pixels") {
                    color.min_pixels = p_.readInt(c.value, cp);
                    if (color.min_pixels < 1) p_.fail(c.value, cp, "must be >= 1");
                } else if (c.key == "volume") {
                    color.volume = p_.readString(c.value, cp);
                    DrawSettings probe;
                    if (!drawOnlyVolume(probe, color.volume)) {
                        std::string what = "unknown volume '";
                        what += color.volume;
                        what +=
                            "' (expected one of: sphere, aabb, obb, kdop6, kdop14, kdop18, "
                            "kdop26)";
                        p_.fail(c.value, cp, what);
                    }
                }
            }
            for (const BodyState st : color.present) {
                for (const BodyState other : color.absent) {
                    if (st == other) {
                        p_.fail(list[i], ip, "a colour cannot be both present and absent");
                    }
                }
            }
            if (color.present.empty() && color.absent.empty()) {
                p_.fail(list[i], ip, "needs 'present' or 'absent'");
            }
            ex.colors.push_back(std::move(color));
        }
}

// `expect:` states outcomes `cdlab check` verifies. Everything that can be checked without
// running is checked here: frames inside the run, body names that exist and are unique, broad
// phase names in the registry, colour names, contradictory pair states, and that the section
// states at least one expectation (an empty one would pass `cdlab check` having checked
// nothing).
void SceneParser::parseExpect(const Entry& entry, const Scene& scene, Expectations& ex,
                              bool through_events) const {
    const YAML::Node& n = entry.value;
    const std::string path = "expect";
    ex.present = true;
    const std::string kinds =
        "min_bodies, min_moving_rotating, broadphases, broadphases_in_use, energy_drift_max, "
        "energy_rise_max, pause_dumps, pairs, colors, tunnelling, toi, rest, self_collision";
    if (n.IsNull() || (n.IsMap() && n.size() == 0)) {
        fail(entry.key_node, path, "states no expectation (give at least one of: " + kinds + ")");
    }
    const std::vector<Entry> es =
        entries(n, path,
                {"frames", "min_bodies", "min_moving_rotating", "broadphases",
                 "broadphases_in_use", "energy_drift_max", "energy_rise_max", "pause_dumps",
                 "pairs", "colors", "tunnelling", "toi", "rest", "self_collision"});
    // The run length first: every frame below must lie inside it.
    if (const Entry* f = find(es, "frames")) {
        const int v = readInt(f->value, childPath(path, "frames"));
        if (v < 1) fail(f->value, childPath(path, "frames"), "must be >= 1");
        ex.frames = v;
    }
    const int run_frames = ex.frames.value_or(scene.frames);
    const ExpectReader reader(*this, scene, run_frames);
    for (const Entry& e : es) {
        const std::string p = childPath(path, e.key);
        if (e.key == "min_bodies") {
            ex.min_bodies = reader.readCount(e.value, p);
        } else if (e.key == "min_moving_rotating") {
            ex.min_moving_rotating = reader.readCount(e.value, p);
        } else if (e.key == "energy_drift_max") {
            const Real d = readReal(e.value, p);
            if (!(d >= 0)) fail(e.value, p, "must be >= 0 (relative drift)");
            ex.energy_drift_max = d;
        } else if (e.key == "energy_rise_max") {
            const Real d = readReal(e.value, p);
            if (!(d >= 0)) fail(e.value, p, "must be >= 0 (relative rise)");
            ex.energy_rise_max = d;
        } else if (e.key == "tunnelling" || e.key == "toi") {
            reader.tunnellingOrToi(e, p, ex);
        } else if (e.key == "rest") {
            reader.rest(e, p, ex);
        } else if (e.key == "self_collision") {
            reader.selfCollision(e, p, ex, scene);
        } else if (e.key == "broadphases") {
            reader.broadPhases(e, p, ex.broad_phases);
        } else if (e.key == "broadphases_in_use") {
            reader.broadPhases(e, p, ex.broad_phases_in_use);
        } else if (e.key == "pause_dumps") {
            reader.pauseDumps(e, p, ex);
        } else if (e.key == "pairs") {
            reader.pairs(e, p, ex);
        } else if (e.key == "colors") {
            reader.colors(e, p, ex);
        }
    }
    // `frames` alone sets the run length and checks nothing.
    const bool states_something =
        ex.min_bodies || ex.min_moving_rotating || !ex.broad_phases.empty() ||
        !ex.broad_phases_in_use.empty() || ex.energy_drift_max || ex.energy_rise_max || !ex.pause_dumps.empty() || !ex.pairs.empty() ||
        !ex.colors.empty() || !ex.tunnelling.empty() || !ex.toi.empty() || !ex.rest.empty() ||
        !ex.self_collision.empty();
    if (!states_something) {
        fail(entry.key_node, path, "states no expectation (give at least one of: " + kinds + ")");
    }
    if (through_events) requireGradableThroughEvents(ex, file_);
}

}  // namespace engine::scene_parsing

namespace engine {

void requireGradableThroughEvents(const Expectations& expect, const std::string& display_name) {
    if (expect.colors.empty()) return;
    const ColorExpectation& c = expect.colors.front();
    throw SceneError(display_name + ":" + std::to_string(c.line) + ":" +
                     std::to_string(c.column) +
                     ": expect.colors[0]: not graded in a run through an events track (its "
                     "picture is the view the track sets: volumes shown, camera, selection); "
                     "grade colours in a scene's expect: without events");
}

}  // namespace engine
