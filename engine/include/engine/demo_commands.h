// engine/demo_commands.h -- the vocabulary a demo is driven with: play, pause, step, seek,
// show/hide a layer, switch the broad phase, select a body, move the camera, dump the frame,
// change the speed, wait. One vocabulary for a scene's `events:` track, `cdlab run --events
// FILE` and a live session's commands, read by the scene loader with its care (every value
// checked where it is read, errors "FILE:LINE:COL: path: what") and applied by the app.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/body.h"

namespace engine {

struct Scene;

/// What `show:` and `hide:` switch on and off. The volumes are the names of `draw.volumes`;
/// hierarchy is each mesh body's hierarchy cut (draw.bvh_depth, shown at depth 2 unless the
/// scene gave one); labels are the bodies' names beside them.
enum class DemoLayer {
    Sphere,
    Aabb,
    Obb,
    Kdop6,
    Kdop14,
    Kdop18,
    Kdop26,
    Hierarchy,
    Structure,
    Contacts,
    Labels,
    Bounds,
    Bodies,
    Hud,
};

/// The layers' names in the order of DemoLayer ("sphere", "aabb", ..., "hud").
std::string_view demoLayerName(DemoLayer layer);
/// "sphere, aabb, ...": the list a message gives.
std::string demoLayerNames();
std::optional<DemoLayer> findDemoLayer(std::string_view name);

/// `camera:` of a command; every part optional, applied in this order: reset, orbit, zoom, pan,
/// follow.
struct CameraCommand {
    bool reset = false;  ///< back to the scene's camera, following nothing
    /// Degrees about the up axis (to the right: positive), then about the view's right axis
    /// (up: positive), around the point looked at. The elevation stays within 1 degree of the
    /// poles, so the view never flips.
    std::optional<std::array<Real, 2>> orbit;
    /// The distance to the point looked at divided by this (> 1 nearer, < 1 farther).
    std::optional<Real> zoom;
    /// Metres along the view's right and up axes; eye and point looked at move together.
    std::optional<std::array<Real, 2>> pan;
    /// Look at this body's centre every frame, keeping the eye's offset (`follow: none` stops).
    std::optional<std::optional<BodyId>> follow;
};

/// One set of commands: what an `events:` entry, a line of a session log or one request of a
/// live session carries. Every part is optional; they are applied in this fixed order, whatever
/// the order written: broadphase, show, hide, select, camera, speed, pause/play, step, seek,
/// dump, wait. So `{pause: true, show: [obb], dump: true}` dumps the paused frame with OBBs.
struct DemoCommands {
    std::optional<std::string> broad_phase;  ///< a registry name: switch on the current state
    std::vector<DemoLayer> show;
    std::vector<DemoLayer> hide;
    /// Highlight and label one body, listing its state and pairs (`select: none` clears).
    std::optional<std::optional<BodyId>> select;
    std::optional<CameraCommand> camera;
    std::optional<Real> speed;    ///< simulated frames per video frame, 1/16..16
    std::optional<bool> playing;  ///< `play: true` -> true, `pause: true` -> false
    std::optional<int> step;      ///< frames, non-zero; negative steps back
    std::optional<int> seek;      ///< the frame to go to (`seek: {frame: F}` or `{time: T}`)
    bool dump = false;            ///< write pause_F.png and pause_F.json of the current frame
    Real wait_s = 0;              ///< then hold the picture this long in the video (events only)

    /// Nothing is asked.
    bool empty() const;
};

/// An entry of an `events:` track: its commands, applied when the run reaches `frame` (`frame:
/// F`, or `at: T` seconds of simulated time: the first frame at or after T).
struct DemoEvent {
    int frame = 0;
    DemoCommands commands;
    int line = 0;  ///< 1-based position of the entry in its file
    int column = 0;
};

/// The longest `wait:` and the most entries of a track: an hour of one picture, or a script of
/// more than ten thousand entries, is a mistake, not a demo.
inline constexpr double kMaxDemoWaitSeconds = 3600;
inline constexpr std::size_t kMaxDemoEvents = 10000;
inline constexpr double kMinDemoSpeed = 1.0 / 16, kMaxDemoSpeed = 16;

/// Reads an events file (a mapping with the key `events:`, as a scene's own track, and an
/// optional `expect:` that `cdlab check --events` grades: engine::loadEventTrack) against
/// `scene` (its frames, bodies and timing) and checks the track as a whole (checkEventTrack).
/// The `expect:` section is validated too, and then left out of the answer.
/// Throws SceneError "FILE:LINE:COL: events[i].key: what".
std::vector<DemoEvent> loadEvents(const std::filesystem::path& file, const Scene& scene);
/// The same from text.
std::vector<DemoEvent> parseEvents(const std::string& yaml_text, const std::string& display_name,
                                   const Scene& scene);

/// One set of commands as YAML or JSON text (`{"pause": true, "show": ["obb"]}`) against
/// `scene`; `wait` is refused (a live session waits by itself). Throws SceneError
/// "NAME:LINE:COL: command.key: what".
DemoCommands parseDemoCommands(const std::string& text, const std::string& display_name,
                               const Scene& scene);

/// `events` as the text of an events file (`events:` and one flow mapping per entry, `frame: F`
/// first, bodies by name, every digit of each number), which parseEvents reads back to the same
/// commands. An empty list gives `events: []`, which is no track (parseEvents refuses it).
std::string eventsYaml(const std::vector<DemoEvent>& events, const Scene& scene);

/// Walks a track's frames as a run plays it (play moves one frame at a time, step and seek jump,
/// each entry applied once, in order) and throws SceneError at the first entry the run never
/// reaches (its frame left behind by a jump, or ahead of a pause nothing ends) or whose step
/// leaves the run's frames 0..frames-1.
void checkEventTrack(const std::vector<DemoEvent>& events, int frames,
                     const std::string& display_name);

}  // namespace engine
