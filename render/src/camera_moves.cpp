// render/src/camera_moves.cpp -- see camera_moves.h. The view's axes are the renderer's own
// (makeCameraFrame), so "right" and "up" are the picture's right and up.
#include "render/camera_moves.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "camera.h"

namespace render {

namespace {

constexpr Real kDegree = kPi / 180;

}  // namespace

engine::CameraSettings orbitCamera(const engine::CameraSettings& camera, Real yaw_deg,
                                   Real pitch_deg) {
    const Vec3 offset = camera.position - camera.look_at;
    const Real distance = offset.norm();
    if (!(distance > 0) || !(camera.up.norm() > 0)) return camera;
    const Vec3 up = camera.up.normalized();
    const CameraFrame frame = makeCameraFrame(camera, 1, 1);
    // The eye's direction from the point looked at: its angle from `up`, and the horizontal
    // direction (right x up) it leans towards.
    const Real from_up = std::acos(std::clamp(offset.dot(up) / distance, Real(-1), Real(1)));
    const Real turned = std::clamp(from_up - pitch_deg * kDegree, kDegree, 179 * kDegree);
    const Vec3 horizontal =
        Eigen::AngleAxis<Real>(yaw_deg * kDegree, up) * frame.right.cross(up).normalized();
    engine::CameraSettings out = camera;
    out.position =
        camera.look_at + distance * (std::cos(turned) * up + std::sin(turned) * horizontal);
    return out;
}

engine::CameraSettings zoomCamera(const engine::CameraSettings& camera, Real factor) {
    engine::CameraSettings out = camera;
    out.position = camera.look_at + (camera.position - camera.look_at) / factor;
    return out;
}

engine::CameraSettings panCamera(const engine::CameraSettings& camera, Real right, Real up) {
    const CameraFrame frame = makeCameraFrame(camera, 1, 1);
    const Vec3 shift = right * frame.right + up * frame.up;
    engine::CameraSettings out = camera;
    out.position += shift;
    out.look_at += shift;
    return out;
}

engine::CameraSettings lookAtPoint(const engine::CameraSettings& camera, const Vec3& target) {
    engine::CameraSettings out = camera;
    out.position += target - camera.look_at;
    out.look_at = target;
    return out;
}

}  // namespace render
