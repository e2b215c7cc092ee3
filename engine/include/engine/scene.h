// engine/scene.h -- scene files (YAML): world, output, camera, what to draw, and the bodies.
// Every error names the place: "scene.yaml:12:7: bodies[3].radius: must be > 0".
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "collision/volumes/volume_kind.h"
#include "engine/body.h"
#include "engine/demo_commands.h"
#include "engine/chain.h"
#include "engine/world.h"

namespace engine {

struct CameraSettings {
    Vec3 position{0, 8, 24};
    Vec3 look_at = Vec3::Zero();
    Vec3 up = Vec3::UnitY();
    Real fov_deg = 45;
};

struct OutputSettings {
    int width = 960;
    int height = 540;
    int fps = 30;
};

/// The k of each entry of DrawSettings::kdop.
inline constexpr std::array<int, 4> kDrawnKdops{6, 14, 18, 26};

struct DrawSettings;
/// Draws exactly the volume named as in `draw.volumes` (sphere, aabb, obb, kdop6, kdop14, kdop18,
/// kdop26), every other volume flag cleared. False, `draw` unchanged, for any other name.
bool drawOnlyVolume(DrawSettings& draw, std::string_view name);

/// What the renderer draws. Volume flags select which bounding volumes get wireframes.
struct DrawSettings {
    bool bodies = true;
    bool sphere = true;
    bool aabb = false;
    bool obb = false;
    /// k-DOPs drawn as their polytopes, for k = kDrawnKdops[i] (`kdop6`, `kdop14`, `kdop18`,
    /// `kdop26` in `draw.volumes`).
    std::array<bool, 4> kdop{};
    /// The scene chose its volumes with `draw.volumes`. Otherwise `cdlab run` draws the
    /// volume its broad phase tests (engine::drawSettingsFor) instead of the defaults above.
    bool volumes_given = false;
    bool bounds = true;
    bool hud = true;
    bool structure = false;  ///< the broad phase's own structure (cells, intervals, nodes)
    /// Each mesh body's hierarchy cut at this depth (root 0), nodes coloured by contact state;
    /// -1 = off. Scene key `draw.bvh_depth` (an integer >= 0, or -1: off).
    int bvh_depth = -1;
    /// Witness points and normals of the confirmed contacts. Scene key `draw.contacts`.
    bool contacts = false;
    /// Each body's name beside its centre. Scene key `draw.labels`.
    bool labels = false;

    /// The flag of one proxy volume kind: sphere, aabb or obb.
    bool& shows(collision::VolumeKind kind) {
        return kind == collision::VolumeKind::Sphere ? sphere
               : kind == collision::VolumeKind::Aabb ? aabb
                                                     : obb;
    }
    bool shows(collision::VolumeKind kind) const {
        return kind == collision::VolumeKind::Sphere ? sphere
               : kind == collision::VolumeKind::Aabb ? aabb
                                                     : obb;
    }
};

/// A frame or an inclusive frame range [first, last] of a run (frame 0 is the initial state).
struct FrameRange {
    int first = 0;
    int last = 0;
};

/// `expect.pairs[i]`: what must hold for one named pair of bodies over a frame range.
struct PairExpectation {
    BodyId a = 0;  ///< body index; a != b
    BodyId b = 0;
    std::string a_name;  ///< as written in the scene, for reports
    std::string b_name;
    FrameRange frames;
    bool every = true;              ///< true: at every frame of the range; false: at some frame
    std::optional<bool> colliding;  ///< confirmed by the narrow phase (or must not be)
    std::optional<bool> flagged;    ///< flagged by the broad phase (or must not be)
    int line = 0;                   ///< 1-based position of the entry in the scene file
    int column = 0;
};

/// `expect.colors[i]`: a frame rendered without HUD, counting pixels of the state colours.
struct ColorExpectation {
    int frame = 0;
    std::vector<BodyState> present;  ///< each needs at least min_pixels pixels of its colour
    std::vector<BodyState> absent;   ///< each must have fewer than min_pixels pixels
    int min_pixels = 20;
    /// "": the frame draws the volumes the scene draws; else only this one (a name of
    /// `draw.volumes`: sphere, aabb, obb, kdop6, kdop14, kdop18, kdop26), so the colours are
    /// that volume's own test alone.
    std::string volume;
    int line = 0;
    int column = 0;
};

/// `expect.tunnelling[i]`: whether body `a` passes through body `b`. a's centre starts outside
/// b's oriented box on one side of one of its axes (the axis along which it is farthest out,
/// relative to b's half extent); `a` has passed when, at some step, its centre is beyond b's box
/// on the opposite side of that axis. Checked after every step, so a pass within one step (the
/// tunnelling this expectation exists for) is seen.
struct TunnelExpectation {
    BodyId a = 0;
    BodyId b = 0;
    std::string a_name;
    std::string b_name;
    bool passes = false;  ///< true: it must pass (a scene showing tunnelling); false: it never may
};

/// `expect.toi[i]`: the first time of impact the CCD stage reports for the pair, in seconds of
/// simulated time, must lie in [time - tolerance, time] (CCD never reports a time later than
/// the true contact, and may stop short by its target gap).
struct ToiExpectation {
    BodyId a = 0;
    BodyId b = 0;
    std::string a_name;
    std::string b_name;
    Real time = 0;       ///< s, the exact first contact
    Real tolerance = 0;  ///< s, > 0
};

/// `expect.rest[i]`: over a frame range, the body stays within `max_displacement` of where it
/// was at the range's first frame, and its speed never exceeds `max_speed` (resting contact:
/// no drift, no jitter).
struct RestExpectation {
    BodyId body = 0;
    std::string name;
    FrameRange frames;
    std::optional<Real> max_displacement;  ///< m
    std::optional<Real> max_speed;         ///< m/s, of the centre of mass
};

/// `expect.self_collision[i]`: on every frame of a range, the number of the body's own
/// intersecting triangle pairs (World::selfPairs; the body must have `self_collision: true`)
/// is at least `min_pairs` and at most `max_pairs` (`max_pairs: 0`: none).
struct SelfCollisionExpectation {
    BodyId body = 0;
    std::string name;
    FrameRange frames;
    std::optional<int> min_pairs;
    std::optional<int> max_pairs;
};

/// The optional top-level `expect:` section: outcomes `cdlab check` verifies. Frames are
/// validated against `frames` (or the scene's frame count); body names must exist (unique).
struct Expectations {
    bool present = false;       ///< the scene has an `expect:` section
    std::optional<int> frames;  ///< frames to run for the check (default: scene.frames)
    std::optional<int> min_bodies;
    std::optional<int> min_moving_rotating;  ///< bodies displaced and rotated by the last frame
    std::vector<std::string> broad_phases;   ///< each must equal its brute reference every step
    /// The broad phases the run itself uses (the scene's, then each an events track switches
    /// to): each must be in use at some point and equal its brute reference on every state it
    /// detects (every step while it is in use, and the state it re-detects when switched to);
    /// one the run uses that is not listed fails a row of its own. `expect.broadphases_in_use`.
    std::vector<std::string> broad_phases_in_use;
    std::optional<Real> energy_drift_max;    ///< max |E(t) - E(0)| / |E(0)|, E kinetic+potential
    std::optional<Real> energy_rise_max;     ///< max (E(t) - E(0)) / |E(0)|: energy never grows
    std::vector<int> pause_dumps;            ///< frames whose pause PNG + JSON must be written
    std::vector<PairExpectation> pairs;
    std::vector<ColorExpectation> colors;
    std::vector<TunnelExpectation> tunnelling;
    std::vector<ToiExpectation> toi;
    std::vector<RestExpectation> rest;
    std::vector<SelfCollisionExpectation> self_collision;
};

struct Scene {
    std::string name;  ///< file stem
    WorldSettings world;
    int frames = 120;         ///< frames to write (frame 0 is the initial state)
    /// Integrator steps between two frames. A loaded scene that leaves out time_step or
    /// steps_per_frame (or both) gets values for which one frame is 1/fps s of simulated time:
    /// neither key, ceil(60 / fps) steps of 1 / (fps * steps) s; one key, the other from it.
    int steps_per_frame = 1;
    OutputSettings output;
    CameraSettings camera;
    DrawSettings draw;
    /// Bodies of `bodies:`, then the links of `chains:` (kinematic bodies), chain by chain.
    std::vector<Body> bodies;
    /// `chains:` (links in `bodies`, see ChainSpec::links).
    std::vector<ChainSpec> chains;
    Expectations expect;  ///< `expect:` (self-grading), empty when absent
    /// `events:`: a scripted demo (demo_commands.h), applied by `cdlab run` as the frames come.
    std::vector<DemoEvent> events;
    /// What loading assumed or changed that the user should know, one line each,
    /// "FILE:LINE:COL: path: what" (an open mesh's mass properties from its hull, triangles an
    /// import dropped): the commands print them on stderr. Not errors: the scene loaded.
    std::vector<std::string> notes;
};

/// An events file as `cdlab check --events` reads it: the track and, when the file has one, its
/// own `expect:` section, read against the scene the track plays on (its bodies and frames) with
/// the scene loader's care. A file's `expect:` states what the run through the track must show.
struct EventTrack {
    std::vector<DemoEvent> events;
    Expectations expect;  ///< `present` false when the file has no `expect:`
};

/// Reads an events file (keys `events:` and, optionally, `expect:`) against `scene`, as
/// loadEvents does, and its `expect:` as a scene's (graded through the track, so it may not
/// hold `colors`: requireGradableThroughEvents). Throws SceneError "FILE:LINE:COL: key: what".
EventTrack loadEventTrack(const std::filesystem::path& file, const Scene& scene);
/// The same from text.
EventTrack parseEventTrack(const std::string& yaml_text, const std::string& display_name,
                           const Scene& scene);

/// Throws SceneError "FILE:LINE:COL: expect.colors[i]: ..." when `expect` states something that
/// a run through an events track cannot grade: `colors` count the state colours of a picture,
/// and a track's picture is the view its commands set (volumes shown and hidden, the camera, a
/// selected body drawn white), so the count would grade the walkthrough's camera work and not
/// the bodies' states. `display_name` is the file the expectations came from.
void requireGradableThroughEvents(const Expectations& expect, const std::string& display_name);

/// Simulated seconds per second of the scene's video: time_step * steps_per_frame * fps
/// (1 = real time; below 1, slow motion).
inline Real videoTimeScale(const Scene& scene) {
    return scene.world.time_step * Real(scene.steps_per_frame) * Real(scene.output.fps);
}

/// A bad scene file. what() is "FILE:LINE:COL: key.path: what is wrong" (1-based line and column).
class SceneError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Reads and validates a scene file; mesh paths are relative to the scene file's folder.
/// Throws SceneError on any problem: unreadable file, malformed YAML, unknown key, wrong type,
/// out-of-range value, NaN/Inf, missing or broken mesh.
Scene loadScene(const std::filesystem::path& file);

/// Same, from text; `display_name` prefixes the messages, `base_dir` resolves mesh paths.
Scene parseScene(const std::string& yaml_text, const std::string& display_name,
                 const std::filesystem::path& base_dir);

/// A value put at a dotted key path of the scene document before it is validated, as
/// `cdlab sweep --vary` does: `{"world.time_step", "0.01"}`, `{"bodies.3.radius", "0.5"}`
/// (numbers index lists). The value is YAML text, so it is checked exactly like the file's own
/// values; missing maps on the path are created; a path through a scalar is an error.
struct SceneOverride {
    std::string key;
    std::string value;
    std::string option = "--set";  ///< the command-line option that gave it, for messages
};

/// loadScene with `overrides` applied, in order, to the document before validation. An error
/// about an overridden value, or about an override's key path, names the option instead of a
/// line of the file: "FILE: --set world.frames=abc: world.frames: expected an integer ...".
Scene loadScene(const std::filesystem::path& file, const std::vector<SceneOverride>& overrides);
/// parseScene with overrides, as loadScene.
Scene parseScene(const std::string& yaml_text, const std::string& display_name,
                 const std::filesystem::path& base_dir,
                 const std::vector<SceneOverride>& overrides);

/// Builds a World holding the scene's bodies and chains, with volumes and pairs already detected.
World makeWorld(const Scene& scene);

}  // namespace engine
