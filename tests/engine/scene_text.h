// tests/engine/scene_text.h -- the scene texts the engine's scene tests build on: a minimal
// header, one valid body, a scene using every section, and parsing as "test.yaml" with mesh paths
// relative to scenes/ (as a file there).
#pragma once

#include <filesystem>
#include <string>

#include "engine/scene.h"

namespace engine::scene_text {

// Mesh paths in the test scenes are relative to this folder, like a file in scenes/.
inline const std::filesystem::path kScenesDir = std::filesystem::path(CDLAB_SOURCE_DIR) / "scenes";

inline Scene parse(const std::string& text) { return parseScene(text, "test.yaml", kScenesDir); }

// A minimal valid scene; the error tests append one body or replace a line.
inline const std::string kHeader =
    "world:\n"                                             // 1
    "  bounds: {min: [-10, -6, -10], max: [10, 6, 10]}\n"  // 2
    "bodies:\n";                                           // 3

inline std::string withBody(const std::string& body_lines) { return kHeader + body_lines; }

// kHeader with one body: the smallest scene that loads.
inline const std::string kValid =
    kHeader + "  - {shape: sphere, radius: 0.25, position: [0.5, 0.5, 0.5]}\n";

inline constexpr const char* kFullScene = R"(world:
  bounds: {min: [-10, -6, -10], max: [10, 6, 10]}
  gravity: [0, -9.81, 0]
  time_step: 0.01
  steps_per_frame: 2
  frames: 240
broadphase: brute
output: {width: 640, height: 360, fps: 25}
camera: {position: [1, 8, 24], look_at: [0, 1, 0], up: [0, 1, 0], fov_deg: 50}
draw:
  bodies: false
  volumes: [aabb, obb]
  bounds: false
  hud: false
  structure: true
bodies:
  - name: ball
    shape: sphere
    radius: 0.5
    position: [0, 1, 0]
    velocity: [1, 0, 0]
    angular_velocity: [0, 2, 0]
    mass: 2.0
  - name: crate
    shape: box
    half_extents: [0.5, 0.3, 0.2]
    position: [2, 0, 0]
    orientation_wxyz: [2, 0, 0, 0]
    density: 500
  - shape: capsule
    radius: 0.25
    half_height: 0.6
    position: [-2, 0, 0]
    euler_deg: [0, 30, 0]
  - name: gem
    shape: hull
    file: ../assets/crystal.obj
    scale: 2
    position: [0, 0, 3]
  - name: ring
    shape: mesh
    file: ../assets/torus.obj
    scale: 0.5
    position: [0, 0, -3]
    density: 800
)";

}  // namespace engine::scene_text
