// render/src/camera.cpp -- see camera.h.
#include "camera.h"

namespace render {

CameraFrame makeCameraFrame(const engine::CameraSettings& camera, int gl_width, int gl_height) {
    CameraFrame frame;
    frame.eye = camera.position;
    const Vec3 view = camera.look_at - camera.position;
    const Real scale = std::max({camera.position.norm(), camera.look_at.norm(), Real(1)});
    if (view.norm() > 64 * collision::kEpsilon * scale) frame.forward = view.normalized();
    Vec3 up = camera.up;
    Vec3 right = frame.forward.cross(up);
    if (!(right.norm() > kParallelSine * up.norm())) {
        // `up` is zero or parallel to the view: pick the world axis least aligned with it.
        up = std::abs(frame.forward.y()) < Real(0.9) ? Vec3::UnitY() : Vec3::UnitZ();
        right = frame.forward.cross(up);
    }
    frame.right = right.normalized();
    frame.up = frame.right.cross(frame.forward);
    const Real fov = std::clamp(camera.fov_deg, Real(1), Real(179));
    frame.tan_half_fov = std::tan(fov * kPi / 360);
    frame.aspect = Real(gl_width) / Real(gl_height);
    frame.focal_px = Real(gl_height) / (2 * frame.tan_half_fov);
    return frame;
}

void setClipPlanes(CameraFrame& cam, const DepthRange& range) {
    if (!(range.hi > 0)) {
        cam.far_plane = 1;
        cam.near_plane = kNearFarRatio;
        return;
    }
    const Real margin = Real(0.01) * (range.hi - std::max(range.lo, Real(0))) + 1e-6 * range.hi;
    cam.far_plane = range.hi + margin;
    cam.near_plane = std::max(range.lo - margin, kNearFarRatio * cam.far_plane);
}

}  // namespace render
