// render/src/camera.cpp -- see camera.h.
#include "camera.h"

#include "render/renderer.h"

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

std::optional<ScreenRect> screenRect(const engine::CameraSettings& camera, int width, int height,
                                     const Vec3& min, const Vec3& max) {
    if (width <= 0 || height <= 0) return std::nullopt;
    const CameraFrame cam = makeCameraFrame(camera, width, height);
    // A corner this close to the eye's plane projects to "infinity": no rectangle to show.
    const Real min_depth = Real(1e-9) * std::max({cam.eye.norm(), min.norm(), max.norm(), Real(1)});
    ScreenRect rect{
        std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3 p((corner & 1) ? max.x() : min.x(), (corner & 2) ? max.y() : min.y(),
                     (corner & 4) ? max.z() : min.z());
        const Vec3 rel = cam.toEye(p);
        const Real z = cam.forward.dot(rel);
        if (!(z > min_depth)) return std::nullopt;
        // gluPerspective: normalised device x = x / (z tan(fov/2) aspect), y = y / (z tan(fov/2)).
        const double ndc_x = double(cam.right.dot(rel) / (z * cam.tan_half_fov * cam.aspect));
        const double ndc_y = double(cam.up.dot(rel) / (z * cam.tan_half_fov));
        const double x = (ndc_x + 1) * 0.5 * width;
        const double y = (1 - ndc_y) * 0.5 * height;
        rect.x0 = std::min(rect.x0, x);
        rect.y0 = std::min(rect.y0, y);
        rect.x1 = std::max(rect.x1, x);
        rect.y1 = std::max(rect.y1, y);
    }
    rect.x0 = std::max(rect.x0, 0.0);
    rect.y0 = std::max(rect.y0, 0.0);
    rect.x1 = std::min(rect.x1, double(width));
    rect.y1 = std::min(rect.y1, double(height));
    if (!(rect.x0 < rect.x1 && rect.y0 < rect.y1)) return std::nullopt;
    return rect;
}

}  // namespace render
