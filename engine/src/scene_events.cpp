// engine/src/scene_events.cpp -- the demo command vocabulary (demo_commands.h) read with the
// scene loader's care: a scene's `events:` track, an events file, and one set of commands of a
// live session. Every value is checked where it is read against the scene (its frames, timing,
// bodies, the broad-phase registry), so a bad command is refused by name before anything runs.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>

#include "collision/broadphase/broad_phase.h"
#include "engine/demo_commands.h"
#include "engine/scene.h"
#include "scene_parser.h"

namespace engine {

namespace {

constexpr std::string_view kLayerNames[] = {
    "sphere", "aabb",      "obb",      "kdop6",  "kdop14", "kdop18", "kdop26",
    "hierarchy", "structure", "contacts", "labels", "bounds", "bodies", "hud"};

}  // namespace

std::string_view demoLayerName(DemoLayer layer) { return kLayerNames[int(layer)]; }

std::string demoLayerNames() {
    std::string list;
    for (const std::string_view n : kLayerNames) list += (list.empty() ? "" : ", ") + std::string(n);
    return list;
}

std::optional<DemoLayer> findDemoLayer(std::string_view name) {
    for (int i = 0; i < int(std::size(kLayerNames)); ++i) {
        if (kLayerNames[i] == name) return DemoLayer(i);
    }
    return std::nullopt;
}

bool DemoCommands::empty() const {
    return !broad_phase && show.empty() && hide.empty() && !select && !camera && !speed &&
           !playing && !step && !seek && !dump && wait_s == 0;
}

namespace scene_parsing {

// Reads commands against one scene: frames within the run, times on its frame clock, bodies by
// name. Every failure goes through SceneParser::fail, naming the key's position.
class EventReader {
public:
    EventReader(const SceneParser& parser, const Scene& scene) : p_(parser), scene_(scene) {
        for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
            by_name_.emplace(scene.bodies[i].name, static_cast<BodyId>(i));
        }
    }

    std::vector<DemoEvent> readTrack(const YAML::Node& n, const std::string& path) const {
        if (!n.IsSequence()) p_.fail(n, path, "expected a list of events ({frame: F, ...})");
        if (n.size() == 0) p_.fail(n, path, "empty list: a track needs at least one event");
        if (n.size() > kMaxDemoEvents) {
            p_.fail(n, path,
                    std::to_string(n.size()) + " events, more than the limit of " +
                        std::to_string(kMaxDemoEvents));
        }
        std::vector<DemoEvent> events;
        for (std::size_t i = 0; i < n.size(); ++i) {
            events.push_back(readEvent(n[i], indexPath(path, i)));
        }
        return events;
    }

    DemoEvent readEvent(const YAML::Node& n, const std::string& path) const {
        std::vector<std::string_view> keys = commandKeys(true);
        keys.insert(keys.begin(), {"frame", "at"});
        const std::vector<Entry> es = p_.entries(n, path, keys);
        DemoEvent event;
        event.line = n.Mark().line + 1;
        event.column = n.Mark().column + 1;
        const Entry* frame = p_.find(es, "frame");
        const Entry* at = p_.find(es, "at");
        if ((frame == nullptr) == (at == nullptr)) {
            p_.fail(n, path, "needs exactly one of 'frame' (a frame) or 'at' (seconds)");
        }
        event.frame = frame != nullptr ? readFrame(frame->value, childPath(path, "frame"))
                                       : readTime(at->value, childPath(path, "at"));
        event.commands = readCommands(es, n, path, true);
        return event;
    }

    DemoCommands readCommands(const YAML::Node& n, const std::string& path, bool allow_wait) const {
        return readCommands(p_.entries(n, path, commandKeys(allow_wait)), n, path, allow_wait);
    }

private:
    static std::vector<std::string_view> commandKeys(bool allow_wait) {
        std::vector<std::string_view> keys = {"play",   "pause",  "step", "seek",   "show",
                                              "hide",   "broadphase", "select", "camera",
                                              "dump",   "speed"};
        if (allow_wait) keys.push_back("wait");
        return keys;
    }

    DemoCommands readCommands(const std::vector<Entry>& es, const YAML::Node& n,
                              const std::string& path, bool allow_wait) const {
        DemoCommands c;
        for (const Entry& e : es) {
            const std::string p = childPath(path, e.key);
            if (e.key == "play" || e.key == "pause") {
                if (!p_.readBool(e.value, p)) {
                    p_.fail(e.value, p,
                            "write '" + e.key + ": true' (the opposite is '" +
                                (e.key == "play" ? "pause" : "play") + ": true')");
                }
                if (c.playing) p_.fail(e.key_node, p, "play and pause in one command");
                c.playing = e.key == "play";
            } else if (e.key == "step") {
                const int s = p_.readInt(e.value, p);
                if (s == 0) p_.fail(e.value, p, "must not be 0 (frames forward, or back if < 0)");
                if (std::abs(s) >= scene_.frames) {
                    p_.fail(e.value, p,
                            "must stay within the run's " + std::to_string(scene_.frames) +
                                " frames");
                }
                c.step = s;
            } else if (e.key == "seek") {
                const std::vector<Entry> se = p_.entries(e.value, p, {"frame", "time"});
                if (se.size() != 1) p_.fail(e.value, p, "needs exactly one of 'frame' or 'time'");
                const std::string sp = childPath(p, se[0].key);
                c.seek = se[0].key == "frame" ? readFrame(se[0].value, sp)
                                              : readTime(se[0].value, sp);
            } else if (e.key == "show" || e.key == "hide") {
                (e.key == "show" ? c.show : c.hide) = readLayers(e.value, p);
            } else if (e.key == "broadphase") {
                const std::string name = p_.readString(e.value, p);
                if (collision::findBroadPhase(name) == nullptr) {
                    p_.fail(e.value, p,
                            "unknown broad phase '" + name +
                                "' (expected one of: " + collision::broadPhaseNames() + ")");
                }
                c.broad_phase = name;
            } else if (e.key == "select") {
                c.select = readBodyOrNone(e.value, p);
            } else if (e.key == "camera") {
                c.camera = readCamera(e.value, p);
            } else if (e.key == "dump") {
                if (!p_.readBool(e.value, p)) p_.fail(e.value, p, "write 'dump: true' or leave it out");
                c.dump = true;
            } else if (e.key == "speed") {
                const Real s = p_.readReal(e.value, p);
                if (!(s >= Real(kMinDemoSpeed) && s <= Real(kMaxDemoSpeed))) {
                    p_.fail(e.value, p,
                            "must be from 1/16 to 16 (simulated frames per video frame)");
                }
                c.speed = s;
            } else if (e.key == "wait" && allow_wait) {
                const Real w = p_.readReal(e.value, p);
                if (!(w > 0 && w <= Real(kMaxDemoWaitSeconds))) {
                    p_.fail(e.value, p,
                            "must be > 0 and <= " + formatLimit(Real(kMaxDemoWaitSeconds)) +
                                " (seconds the picture is held)");
                }
                c.wait_s = w;
            }
        }
        for (const DemoLayer l : c.show) {
            if (std::find(c.hide.begin(), c.hide.end(), l) != c.hide.end()) {
                p_.fail(n, path,
                        "'" + std::string(demoLayerName(l)) + "' is both shown and hidden");
            }
        }
        if (c.empty()) p_.fail(n, path, "no command (expected one of: " + keyList(allow_wait) + ")");
        return c;
    }

    static std::string keyList(bool allow_wait) {
        std::string list;
        for (const std::string_view k : commandKeys(allow_wait)) {
            list += (list.empty() ? "" : ", ") + std::string(k);
        }
        return list;
    }

    int readFrame(const YAML::Node& v, const std::string& p) const {
        const int f = p_.readInt(v, p);
        if (f < 0 || f >= scene_.frames) {
            p_.fail(v, p,
                    "frame out of range (the run has frames 0.." +
                        std::to_string(scene_.frames - 1) + ")");
        }
        return f;
    }

    // Seconds of simulated time -> the first frame at or after them (frame f shows time f dt n,
    // dt the time step and n the steps per frame); a time within 1e-9 of a frame's is that frame.
    int readTime(const YAML::Node& v, const std::string& p) const {
        const Real t = p_.readReal(v, p);
        const double frame_s = double(scene_.world.time_step) * scene_.steps_per_frame;
        const double last_s = frame_s * (scene_.frames - 1);
        if (!(t >= 0 && double(t) <= last_s * (1 + 1e-12))) {
            p_.fail(v, p,
                    "time out of range (the run's frames span 0.." + formatLimit(Real(last_s)) +
                        " s)");
        }
        const double f = std::ceil(double(t) / frame_s - 1e-9);
        return std::clamp(int(f), 0, scene_.frames - 1);
    }

    std::vector<DemoLayer> readLayers(const YAML::Node& v, const std::string& p) const {
        // `show: obb` for `show: [obb]`.
        std::vector<std::pair<YAML::Node, std::string>> items;
        if (v.IsScalar()) {
            items.emplace_back(v, p);
        } else if (v.IsSequence() && v.size() > 0) {
            for (std::size_t i = 0; i < v.size(); ++i) items.emplace_back(v[i], indexPath(p, i));
        } else {
            p_.fail(v, p, "expected a list of layers (" + demoLayerNames() + ")");
        }
        std::vector<DemoLayer> layers;
        for (const auto& [item, ip] : items) {
            const std::string name = p_.readString(item, ip);
            const std::optional<DemoLayer> layer = findDemoLayer(name);
            if (!layer) {
                p_.fail(item, ip,
                        "unknown layer '" + name + "' (expected one of: " + demoLayerNames() + ")");
            }
            if (std::find(layers.begin(), layers.end(), *layer) != layers.end()) {
                p_.fail(item, ip, "'" + name + "' is listed twice");
            }
            layers.push_back(*layer);
        }
        return layers;
    }

    std::optional<BodyId> readBodyOrNone(const YAML::Node& v, const std::string& p) const {
        if (v.IsNull()) return std::nullopt;
        const std::string name = p_.readString(v, p);
        const auto it = by_name_.find(name);
        if (it != by_name_.end()) return it->second;
        if (name == "none") return std::nullopt;
        p_.fail(v, p, "no body is named '" + name + "' (write 'none' to clear)");
    }

    std::array<Real, 2> readPair(const YAML::Node& v, const std::string& p, Real limit,
                                 const std::string& unit) const {
        if (!v.IsSequence() || v.size() != 2) p_.fail(v, p, "expected a list of 2 numbers");
        std::array<Real, 2> out{};
        for (std::size_t i = 0; i < 2; ++i) {
            out[i] = p_.readReal(v[i], indexPath(p, i));
            if (!(std::abs(out[i]) <= limit)) {
                p_.fail(v[i], indexPath(p, i), "must be within +-" + formatLimit(limit) + unit);
            }
        }
        return out;
    }

    CameraCommand readCamera(const YAML::Node& v, const std::string& p) const {
        const std::vector<Entry> es = p_.entries(v, p, {"orbit", "zoom", "pan", "follow", "reset"});
        if (es.empty()) p_.fail(v, p, "no camera move (expected one of: orbit, zoom, pan, follow, reset)");
        CameraCommand c;
        // Pans stay within the world's scale: a metre count beyond the coordinate limit would
        // put the eye where squared distances overflow.
        const Real extent = (scene_.world.bounds.max - scene_.world.bounds.min).norm();
        for (const Entry& e : es) {
            const std::string cp = childPath(p, e.key);
            if (e.key == "orbit") {
                c.orbit = readPair(e.value, cp, Real(3600), " degrees");
            } else if (e.key == "zoom") {
                const Real z = p_.readReal(e.value, cp);
                if (!(z >= Real(0.01) && z <= Real(100))) {
                    p_.fail(e.value, cp, "must be from 0.01 to 100 (distance divided by it)");
                }
                c.zoom = z;
            } else if (e.key == "pan") {
                c.pan = readPair(e.value, cp, Real(100) * extent, " m (100 world diagonals)");
            } else if (e.key == "follow") {
                c.follow = readBodyOrNone(e.value, cp);
            } else if (e.key == "reset") {
                if (!p_.readBool(e.value, cp)) p_.fail(e.value, cp, "write 'reset: true' or leave it out");
                c.reset = true;
            }
        }
        return c;
    }

    const SceneParser& p_;
    const Scene& scene_;
    std::map<std::string, BodyId> by_name_;
};

void SceneParser::parseEvents(const Entry& entry, Scene& scene) const {
    scene.events = EventReader(*this, scene).readTrack(entry.value, "events");
    checkEventTrack(scene.events, scene.frames, file_);
}

EventTrack SceneParser::parseEventsDocument(const std::string& text, const Scene& scene) const {
    const YAML::Node root = loadDocument(text);
    if (!root.IsMap()) fail(root, "events", "expected a mapping with the key: events");
    const std::vector<Entry> es = entries(root, "", {"events", "expect"});
    const Entry& track = require(es, "events", root, "");
    EventTrack out;
    out.events = EventReader(*this, scene).readTrack(track.value, "events");
    checkEventTrack(out.events, scene.frames, file_);
    // What the run through this track must show, read as a scene's own section is.
    if (const Entry* e = find(es, "expect")) parseExpect(*e, scene, out.expect, true);
    return out;
}

DemoCommands SceneParser::parseCommandsDocument(const std::string& text, const Scene& scene) const {
    const YAML::Node root = loadDocument(text);
    return EventReader(*this, scene).readCommands(root, "command", false);
}

}  // namespace scene_parsing

namespace {

template <typename Parse>
auto runEventParser(const std::string& display_name, Parse&& parse) {
    try {
        return parse();
    } catch (const SceneError&) {
        throw;
    } catch (const YAML::Exception& e) {
        throw SceneError(scene_parsing::formatMessage(display_name, e.mark, "events", e.msg));
    } catch (const std::exception& e) {
        throw SceneError(scene_parsing::formatMessage(display_name, YAML::Mark::null_mark(),
                                                      "events", e.what()));
    }
}

}  // namespace

EventTrack parseEventTrack(const std::string& yaml_text, const std::string& display_name,
                           const Scene& scene) {
    const scene_parsing::SceneParser parser(display_name, ".");
    return runEventParser(display_name,
                          [&] { return parser.parseEventsDocument(yaml_text, scene); });
}

std::vector<DemoEvent> parseEvents(const std::string& yaml_text, const std::string& display_name,
                                   const Scene& scene) {
    return parseEventTrack(yaml_text, display_name, scene).events;
}

std::vector<DemoEvent> loadEvents(const std::filesystem::path& file, const Scene& scene) {
    return loadEventTrack(file, scene).events;
}

EventTrack loadEventTrack(const std::filesystem::path& file, const Scene& scene) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) {
        throw SceneError(file.string() + ":1:1: events: cannot open the file (" +
                         (std::filesystem::exists(file, ec) ? "not a regular file"
                                                            : "no such file") +
                         ")");
    }
    // An events file is a script of commands; ten thousand entries fit in well under 1 MiB.
    constexpr std::uintmax_t kMaxEventsBytes = std::uintmax_t(4) << 20;
    if (std::filesystem::file_size(file, ec) > kMaxEventsBytes && !ec) {
        throw SceneError(file.string() + ":1:1: events: the file is larger than 4 MiB");
    }
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in.good() && !in.eof()) throw SceneError(file.string() + ":1:1: events: cannot read the file");
    return parseEventTrack(text.str(), file.string(), scene);
}

DemoCommands parseDemoCommands(const std::string& text, const std::string& display_name,
                               const Scene& scene) {
    const scene_parsing::SceneParser parser(display_name, ".");
    return runEventParser(display_name,
                          [&] { return parser.parseCommandsDocument(text, scene); });
}

void checkEventTrack(const std::vector<DemoEvent>& events, int frames,
                     const std::string& display_name) {
    auto fail = [&](const DemoEvent& e, std::size_t i, const std::string& what) {
        throw SceneError(display_name + ":" + std::to_string(e.line) + ":" +
                         std::to_string(e.column) + ": events[" + std::to_string(i) + "]: " + what);
    };
    int frame = 0;
    bool playing = true;
    std::size_t next = 0;
    for (;;) {
        while (next < events.size() && events[next].frame == frame) {
            const DemoEvent& e = events[next];
            const DemoCommands& c = e.commands;
            if (c.playing) playing = *c.playing;
            if (c.step) {
                const int to = frame + *c.step;
                if (to < 0 || to >= frames) {
                    fail(e, next,
                         "step " + std::to_string(*c.step) + " from frame " +
                             std::to_string(frame) + " leaves the run's frames 0.." +
                             std::to_string(frames - 1));
                }
                frame = to;
            }
            if (c.seek) {
                if (*c.seek >= frames) {
                    fail(e, next,
                         "seek to frame " + std::to_string(*c.seek) + " leaves the run's frames 0.." +
                             std::to_string(frames - 1));
                }
                frame = *c.seek;
            }
            ++next;
        }
        if (next == events.size()) return;
        const DemoEvent& e = events[next];
        if (e.frame < frame) {
            fail(e, next,
                 "frame " + std::to_string(e.frame) + " is never reached: the entry before it " +
                     "left the run at frame " + std::to_string(frame) +
                     " (entries apply in order; seek back to reach an earlier frame)");
        }
        if (!playing) {
            fail(e, next,
                 "frame " + std::to_string(e.frame) + " is never reached: the run is paused at " +
                     "frame " + std::to_string(frame) +
                     " (an entry at that frame with 'play: true', 'step' or 'seek' moves on)");
        }
        if (e.frame >= frames) {
            fail(e, next,
                 "frame out of range (the run has frames 0.." + std::to_string(frames - 1) + ")");
        }
        frame = e.frame;  // playing reaches it
    }
}

namespace {

void emitReal(YAML::Emitter& out, Real v) { out << v; }

void emitCommands(YAML::Emitter& out, const DemoCommands& c, const Scene& scene) {
    auto name = [&](const std::optional<BodyId>& id) {
        return id ? scene.bodies[std::size_t(*id)].name : std::string("none");
    };
    auto layers = [&](const char* key, const std::vector<DemoLayer>& list) {
        if (list.empty()) return;
        out << YAML::Key << key << YAML::Value << YAML::BeginSeq;
        for (const DemoLayer l : list) out << std::string(demoLayerName(l));
        out << YAML::EndSeq;
    };
    auto pair = [&](const char* key, const std::array<Real, 2>& v) {
        out << YAML::Key << key << YAML::Value << YAML::BeginSeq;
        emitReal(out, v[0]);
        emitReal(out, v[1]);
        out << YAML::EndSeq;
    };
    if (c.broad_phase) out << YAML::Key << "broadphase" << YAML::Value << *c.broad_phase;
    layers("show", c.show);
    layers("hide", c.hide);
    if (c.select) out << YAML::Key << "select" << YAML::Value << name(*c.select);
    if (c.camera) {
        out << YAML::Key << "camera" << YAML::Value << YAML::BeginMap;
        if (c.camera->reset) out << YAML::Key << "reset" << YAML::Value << true;
        if (c.camera->orbit) pair("orbit", *c.camera->orbit);
        if (c.camera->zoom) {
            out << YAML::Key << "zoom" << YAML::Value;
            emitReal(out, *c.camera->zoom);
        }
        if (c.camera->pan) pair("pan", *c.camera->pan);
        if (c.camera->follow) out << YAML::Key << "follow" << YAML::Value << name(*c.camera->follow);
        out << YAML::EndMap;
    }
    if (c.speed) {
        out << YAML::Key << "speed" << YAML::Value;
        emitReal(out, *c.speed);
    }
    if (c.playing) out << YAML::Key << (*c.playing ? "play" : "pause") << YAML::Value << true;
    if (c.step) out << YAML::Key << "step" << YAML::Value << *c.step;
    if (c.seek) {
        out << YAML::Key << "seek" << YAML::Value << YAML::BeginMap << YAML::Key << "frame"
            << YAML::Value << *c.seek << YAML::EndMap;
    }
    if (c.dump) out << YAML::Key << "dump" << YAML::Value << true;
    if (c.wait_s > 0) {
        out << YAML::Key << "wait" << YAML::Value;
        emitReal(out, c.wait_s);
    }
}

}  // namespace

std::string eventsYaml(const std::vector<DemoEvent>& events, const Scene& scene) {
    YAML::Emitter out;
    // Every digit a Real needs, so a track read back gives the same values bit for bit.
    out.SetFloatPrecision(9);
    out.SetDoublePrecision(17);
    out << YAML::BeginMap << YAML::Key << "events" << YAML::Value << YAML::BeginSeq;
    for (const DemoEvent& e : events) {
        out << YAML::Flow << YAML::BeginMap << YAML::Key << "frame" << YAML::Value << e.frame;
        emitCommands(out, e.commands, scene);
        out << YAML::EndMap;
    }
    out << YAML::EndSeq << YAML::EndMap;
    return std::string(out.c_str()) + "\n";
}

}  // namespace engine
