// tests/render/pixel_checks.h -- shared by the render checks: bodies and a head-on camera for
// small test worlds, an independent pinhole projection, and colour look-ups around a pixel.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "collision/debug_draw.h"
#include "collision/geometry/shape.h"
#include "engine/body.h"
#include "engine/scene.h"
#include "engine/world.h"
#include "render/image.h"
#include "render/renderer.h"

namespace cdlab_test {

using engine::Mat3;
using engine::Quat;
using engine::Real;
using engine::Vec3;
using Rgb = std::array<int, 3>;

inline constexpr int kWidth = 160;
inline constexpr int kHeight = 120;
inline constexpr double kPi = 3.14159265358979323846;

inline engine::Body makeShapeBody(const std::string& name, collision::Shape shape,
                                  const Vec3& position,
                                  const Quat& orientation = Quat::Identity()) {
    engine::MassProperties mass;
    mass.mass = 1;
    mass.inertia = Mat3::Identity() * Real(0.4);
    engine::Body body = engine::makeBody(name, std::move(shape), mass);
    body.position = position;
    body.orientation = orientation;
    return body;
}

inline engine::Body sphereBody(const std::string& name, Real radius, const Vec3& position) {
    return makeShapeBody(name, collision::Shape::sphere(radius), position);
}

inline engine::CameraSettings headOnCamera() {
    engine::CameraSettings camera;
    camera.position = Vec3(0, 0, 9);
    camera.look_at = Vec3::Zero();
    camera.up = Vec3::UnitY();
    camera.fov_deg = 45;
    return camera;
}

inline render::FrameOptions plainOptions() {
    render::FrameOptions options;
    options.draw.bodies = true;
    options.draw.sphere = true;
    options.draw.aabb = false;
    options.draw.obb = false;
    options.draw.bounds = false;
    options.draw.hud = false;
    return options;
}

// Two overlapping spheres on the left (colliding: red) and one alone on the right (apart: green),
// seen head-on from +z:
//
//        y
//        |   ( A )( B )        ( C )
//   -----+--------------------------- x      camera at (0, 0, 9) looking at the origin
//            x=-3  x=-1.6      x=2.6
//
// The default bounds are far outside the view, so every pixel that is not a body or a line is
// background.
inline engine::World makeThreeSphereWorld(const collision::Aabb& bounds = collision::Aabb{
                                              Vec3::Constant(-20), Vec3::Constant(20)}) {
    engine::WorldSettings settings;
    settings.bounds = bounds;
    engine::World world(settings);
    world.addBody(sphereBody("a", 1, Vec3(-3, 0, 0)));
    world.addBody(sphereBody("b", 1, Vec3(-1.6, 0.2, 0)));
    world.addBody(sphereBody("c", 1, Vec3(2.6, 0, 0)));
    world.detect();
    return world;
}

// Pinhole projection written out independently of the renderer (gluLookAt + gluPerspective):
// pixel x to the right, y down, (0, 0) the top-left corner of the image.
struct PixelPos {
    double x;
    double y;
};

inline PixelPos project(const engine::CameraSettings& camera, int width, int height,
                        const Vec3& p) {
    const Vec3 f = (camera.look_at - camera.position).normalized();
    const Vec3 r = f.cross(camera.up).normalized();
    const Vec3 u = r.cross(f);
    const Vec3 d = p - camera.position;
    const double t = std::tan(double(camera.fov_deg) * kPi / 360.0);
    const double aspect = double(width) / double(height);
    const double ndc_x = double(d.dot(r)) / (double(d.dot(f)) * t * aspect);
    const double ndc_y = double(d.dot(u)) / (double(d.dot(f)) * t);
    return {(ndc_x + 1) * 0.5 * width, (1 - ndc_y) * 0.5 * height};
}

inline Rgb pixelAt(const render::Image& image, int x, int y) {
    const std::uint8_t* p = image.pixel(x, y);
    return {p[0], p[1], p[2]};
}

inline Rgb toRgb(const collision::Color& c) {
    return {int(std::lround(c.r * 255)), int(std::lround(c.g * 255)), int(std::lround(c.b * 255))};
}

inline bool close(const Rgb& a, const Rgb& b, int tolerance) {
    for (int k = 0; k < 3; ++k) {
        if (std::abs(a[k] - b[k]) > tolerance) return false;
    }
    return true;
}

// True when some pixel within `radius` of `at` is within `tolerance` of `color` per channel.
inline bool colorNear(const render::Image& image, PixelPos at, const Rgb& color, int radius = 2,
                      int tolerance = 40) {
    const int cx = int(std::floor(at.x));
    const int cy = int(std::floor(at.y));
    for (int y = cy - radius; y <= cy + radius; ++y) {
        for (int x = cx - radius; x <= cx + radius; ++x) {
            if (x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
            if (close(pixelAt(image, x, y), color, tolerance)) return true;
        }
    }
    return false;
}

// Pixels within `tolerance` of `color` per channel.
inline int countColor(const render::Image& image, const Rgb& color, int tolerance = 40) {
    int n = 0;
    for (int y = 0; y < image.height; ++y) {
        for (int x = 0; x < image.width; ++x) n += close(pixelAt(image, x, y), color, tolerance);
    }
    return n;
}

}  // namespace cdlab_test
