// render/src/camera.h -- the view of a frame: gluLookAt / gluPerspective conventions, computed
// here (no GLU) so tests can mirror them, the view-pyramid test that culls what cannot show, and
// the clip planes fitted to what is drawn. Private to render.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "collision/math.h"
#include "engine/scene.h"

namespace render {

using collision::Color;
using collision::kPi;
using collision::Mat3;
using collision::Pose;
using collision::Real;
using collision::Vec3;

/// sin of the smallest angle between view direction and `up` that still defines a camera roll.
inline constexpr Real kParallelSine = Real(1e-6);
/// Near plane never closer than this fraction of the far plane (24-bit depth stays useful).
inline constexpr Real kNearFarRatio = Real(1e-4);


struct CameraFrame {
    Vec3 eye = Vec3::Zero();
    Vec3 forward = -Vec3::UnitZ();
    Vec3 right = Vec3::UnitX();
    Vec3 up = Vec3::UnitY();
    Real tan_half_fov = 1;
    Real aspect = 1;
    Real focal_px = 1;  ///< pixels (of the GL framebuffer) per unit of x/z in eye space
    Real near_plane = 0.1;
    Real far_plane = 100;

    Vec3 toEye(const Vec3& world) const { return world - eye; }
    Real depth(const Vec3& world) const { return forward.dot(world - eye); }

    /// False only when the sphere lies wholly outside one of the four side planes of the view
    /// pyramid (the clip planes enclose every body by construction, see setUpCamera). Geometry
    /// there would be clipped away entirely, so leaving it out changes no pixel; the test is
    /// padded (1 % of the radius plus a relative 1e-9 of the distance) so rounding never culls
    /// a sphere that reaches into the view.
    bool mayShow(const Vec3& center, Real radius) const {
        if (!center.allFinite() || !std::isfinite(radius)) return true;
        const Vec3 rel = center - eye;
        const Real x = right.dot(rel);
        const Real y = up.dot(rel);
        const Real z = forward.dot(rel);
        const Real pad = Real(1.01) * radius + Real(1e-9) * rel.norm();
        const Real tx = tan_half_fov * aspect;
        const Real ty = tan_half_fov;
        // Distance outside the plane |x| = z tx is (|x| - z tx) / sqrt(1 + tx^2).
        return (std::abs(x) - z * tx) <= pad * std::sqrt(1 + tx * tx) &&
               (std::abs(y) - z * ty) <= pad * std::sqrt(1 + ty * ty);
    }
};

/// The camera's frame for a framebuffer of gl_width x gl_height pixels (clip planes unset).
CameraFrame makeCameraFrame(const engine::CameraSettings& camera, int gl_width, int gl_height);

// Grows [near, far] to hold a sphere (centre, radius).
struct DepthRange {
    Real lo = std::numeric_limits<Real>::infinity();
    Real hi = -std::numeric_limits<Real>::infinity();
    void add(const CameraFrame& cam, const Vec3& center, Real radius) {
        if (!std::isfinite(radius) || !center.allFinite()) return;
        const Real d = cam.depth(center);
        lo = std::min(lo, d - radius);
        hi = std::max(hi, d + radius);
    }
};

/// Near and far planes around `range` (a 1 % margin), never nearer than kNearFarRatio of far.
void setClipPlanes(CameraFrame& cam, const DepthRange& range);

}  // namespace render
