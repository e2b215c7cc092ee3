// engine/src/scene_settings.cpp -- the scene's `world`, `output`, `camera` and `draw` sections.
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

void SceneParser::parseWorld(const YAML::Node& n, Scene& scene) const {
    const std::string path = "world";
    const std::vector<Entry> es =
        entries(n, path,
                {"bounds", "gravity", "time_step", "steps_per_frame", "frames", "mesh_bvh",
                 "integrator", "ccd", "ccd_spheres", "ccd_tolerance", "ccd_target_gap", "response",
                 "restitution", "friction", "rebuild_ratio"});
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
        } else if (e.key == "ccd_spheres") {
            const std::string name = readString(e.value, p);
            if (!findCcdSpheres(name, scene.world.ccd_spheres)) {
                fail(e.value, p,
                     "unknown ccd_spheres '" + name + "' (expected one of: advancement, exact)");
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
        } else if (e.key == "rebuild_ratio") {
            // Multiple of a deforming mesh's volume ratio at its last build (WorldSettings); at
            // or below 1 a tree would be rebuilt on every step that loosens it at all.
            const Real v = readReal(e.value, p);
            if (!(v > 1)) {
                fail(e.value, p, "must be > 1 (multiple of the volume ratio at the last build)");
            }
            scene.world.rebuild_ratio = v;
        } else if (e.key == "integrator") {
            const std::string name = readString(e.value, p);
            if (!findIntegrator(name, scene.world.integrator)) {
                fail(e.value, p,
                     "unknown integrator '" + name + "' (expected one of: " + integratorNames() +
                         ")");
            }
        }
    }
    defaultTiming(find(es, "time_step") != nullptr, find(es, "steps_per_frame") != nullptr, scene);
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

void SceneParser::defaultTiming(bool has_time_step, bool has_steps_per_frame, Scene& scene) {
    // A frame shows 1/fps s of simulated time unless the scene says otherwise, so a video plays
    // at the speed things happen. With neither key the step is at most 1/60 s:
    // ceil(60 / fps) steps per frame of 1 / (fps * steps) s each (30 fps: two steps of 1/60 s).
    const int fps = scene.output.fps;
    if (!has_time_step && !has_steps_per_frame) {
        scene.steps_per_frame = (kDefaultMaxStepRate + fps - 1) / fps;
        scene.world.time_step = Real(1) / (Real(fps) * Real(scene.steps_per_frame));
    } else if (!has_time_step) {
        scene.world.time_step = Real(1) / (Real(fps) * Real(scene.steps_per_frame));
    } else if (!has_steps_per_frame) {
        const double steps = std::round(1.0 / (double(fps) * double(scene.world.time_step)));
        scene.steps_per_frame = static_cast<int>(std::clamp(steps, 1.0, double(kMaxStepsPerFrame)));
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

namespace {

/// Index into DrawSettings::kdop of a volume name "kdopK", or -1.
int kdopIndex(const std::string& name) {
    for (std::size_t i = 0; i < engine::kDrawnKdops.size(); ++i) {
        if (name == "kdop" + std::to_string(engine::kDrawnKdops[i])) return int(i);
    }
    return -1;
}

}  // namespace

void SceneParser::parseDraw(const YAML::Node& n, Scene& scene) const {
    const std::string path = "draw";
    DrawSettings& d = scene.draw;
    for (const Entry& e :
         entries(n, path,
                 {"bodies", "volumes", "bounds", "hud", "structure", "bvh_depth", "contacts",
                  "labels"})) {
        const std::string p = childPath(path, e.key);
        if (e.key == "bodies") d.bodies = readBool(e.value, p);
        if (e.key == "bounds") d.bounds = readBool(e.value, p);
        if (e.key == "hud") d.hud = readBool(e.value, p);
        if (e.key == "structure") d.structure = readBool(e.value, p);
        if (e.key == "contacts") d.contacts = readBool(e.value, p);
        if (e.key == "labels") d.labels = readBool(e.value, p);
        if (e.key == "bvh_depth") {
            d.bvh_depth = readInt(e.value, p);
            if (d.bvh_depth < -1) fail(e.value, p, "must be >= 0, or -1 for off");
        }
        if (e.key == "volumes") {
            const std::string kinds = "sphere, aabb, obb, kdop6, kdop14, kdop18, kdop26";
            if (!e.value.IsSequence()) fail(e.value, p, "expected a list of: " + kinds);
            d.sphere = d.aabb = d.obb = false;
            d.kdop = {};
            d.volumes_given = true;
            for (std::size_t i = 0; i < e.value.size(); ++i) {
                const std::string ip = indexPath(p, i);
                const std::string v = readString(e.value[i], ip);
                if (const auto kind = collision::volumeKindNamed(v)) {
                    d.shows(*kind) = true;
                } else if (const int k = kdopIndex(v); k >= 0) {
                    d.kdop[std::size_t(k)] = true;
                } else {
                    std::string what = "unknown volume '";
                    what += v;
                    what += "' (expected one of: ";
                    what += kinds;
                    what += ")";
                    fail(e.value[i], ip, what);
                }
            }
        }
    }
}

}  // namespace engine::scene_parsing

namespace engine {

bool drawOnlyVolume(DrawSettings& draw, std::string_view name) {
    const int k = scene_parsing::kdopIndex(std::string(name));
    const std::optional<collision::VolumeKind> kind = collision::volumeKindNamed(name);
    if (!kind && k < 0) return false;
    draw.sphere = draw.aabb = draw.obb = false;
    if (kind) draw.shows(*kind) = true;
    draw.kdop = {};
    if (k >= 0) draw.kdop[std::size_t(k)] = true;
    return true;
}

}  // namespace engine
