// app/lab/pause_dump.h -- the data file written at a pause: every body's bounding volumes and state.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/scene.h"
#include "engine/world.h"
#include "render/renderer.h"

namespace app {

/// The pause dump as JSON text: frame, time, broad phase and the volume it tests
/// ("broadphase_volume"), bodies (pose, sphere, AABB, OBB, state, and "volume_states": each
/// volume's state by its own overlap test, "apart" / "overlapping" / "colliding", as the pause
/// picture colours it), flagged and colliding pairs, and "overlapping_pairs" per volume kind
/// (all pair lists sorted, i < j). For every k-DOP `draw` draws (draw.kdop), each body also has
/// "kdopK": {"k", "min", "max"} (its k / 2 slab intervals, slab i along
/// "kdop_slab_directions"["kdopK"][i], unnormalised), and "kdopK" joins "volume_states" and
/// "overlapping_pairs". A mesh body has "mesh_bvh": the volume name of its hierarchy
/// (collision::bvhVolumeNames()). Numbers are printed to round-trip. Indented one space a level
/// with a final newline (the file's form), or `compact`: one object on one line, no newline.
std::string pauseDumpJson(const engine::World& world, int frame, const engine::DrawSettings& draw,
                          bool compact = false);

/// What a `--pause-at` picture draws over the frame's view `frame_draw`: the volumes the frames
/// draw when they were chosen (`volumes_chosen`: the scene's draw.volumes, or a show/hide), else
/// the three proxy volumes (sphere, AABB and OBB) side by side, each coloured by its own test.
engine::DrawSettings pauseDrawSettings(engine::DrawSettings frame_draw, bool volumes_chosen);

/// Where each body's AABB shows in a width x height picture taken with `camera` (the rectangle
/// a page outlines, and picks the body by); none for a body behind the eye.
std::vector<std::optional<render::ScreenRect>> bodyRects(const engine::World& world,
                                                         const engine::CameraSettings& camera,
                                                         int width, int height);

}  // namespace app
