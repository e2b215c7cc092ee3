// render/src/gl_debug_draw.cpp -- see gl_debug_draw.h.
#include "gl_debug_draw.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace render {

int segmentsFor(const CameraFrame& cam, const Vec3& center, Real radius, Real px_per_segment,
                int lo, int hi) {
    const Real depth = cam.depth(center);
    const Real px = depth > cam.near_plane ? radius * cam.focal_px / depth
                                           : std::numeric_limits<Real>::infinity();
    const Real wanted = 2 * kPi * px / px_per_segment;
    const int n = std::isfinite(wanted) ? int(std::min(wanted, Real(hi))) : hi;
    return std::clamp((n + 3) / 4 * 4, lo, hi);
}

void FrameLines::clear() {
    frame.clear();
    structure.clear();
    volumes.clear();
    outlines.clear();
    hierarchy.clear();
    contacts.clear();
    selection.clear();
    structure_legend.clear();
}

void GlDebugDraw::setLayer(engine::DrawLayer layer) {
    outlines_ = nullptr;
    legend_ = nullptr;
    switch (layer) {
        case engine::DrawLayer::Frame:
            target_ = &lines_.frame;
            break;
        case engine::DrawLayer::Structure:
            target_ = &lines_.structure;
            legend_ = &lines_.structure_legend;
            break;
        case engine::DrawLayer::Volumes:
            target_ = &lines_.volumes;
            outlines_ = &lines_.outlines;
            break;
        case engine::DrawLayer::Hierarchy:
            target_ = &lines_.hierarchy;
            break;
        case engine::DrawLayer::Contacts:
            target_ = &lines_.contacts;
            break;
        case engine::DrawLayer::Selection:
            target_ = &lines_.selection;
            break;
    }
}

bool GlDebugDraw::mayShow(const Vec3& center, Real radius) {
    if (!cull_ || cam_.mayShow(center, radius)) return true;
    ++culled_;
    return false;
}

// Three great circles, as the base does, but with as many segments as the on-screen size
// needs (round at 4K, cheap for a thousand small spheres), plus the silhouette: the circle
// where the view cone touches the sphere. The great circles lie a little behind the rim as
// seen in perspective, so without it a sphere's outline would only show faintly.
void GlDebugDraw::drawSphere(const collision::BoundingSphere& sphere, const Color& color) {
    if (!(sphere.radius > 0) || !sphere.center.allFinite()) return;
    const int n = segmentsFor(cam_, sphere.center, sphere.radius, 6, 24, 128);
    for (int axis = 0; axis < 3; ++axis) {
        circle(sphere.center, Vec3::Unit((axis + 1) % 3) * sphere.radius,
               Vec3::Unit((axis + 2) % 3) * sphere.radius, n, color);
    }
    // The tangent cone from the eye touches the sphere on a circle: with d the distance to
    // the centre, its plane lies r^2/d in front of the centre and its radius is
    // r sqrt(1 - r^2/d^2) (right triangle eye-centre-tangent point).
    const Vec3 to_center = sphere.center - cam_.eye;
    const Real d = to_center.norm();
    if (!(d > sphere.radius)) return;  // the eye is inside: no silhouette
    const Vec3 w = to_center / d;
    const Real k = sphere.radius / d;
    const Vec3 center = sphere.center - w * (sphere.radius * k);
    const Real radius = sphere.radius * std::sqrt(1 - k * k);
    const Vec3 helper = std::abs(w.x()) < Real(0.6) ? Vec3::UnitX() : Vec3::UnitY();
    const Vec3 u = w.cross(helper).normalized();
    const Vec3 v = w.cross(u);
    LineBuffer* great_circles = target_;
    if (outlines_) target_ = outlines_;
    circle(center, u * radius, v * radius, n, color);
    target_ = great_circles;
}

void GlDebugDraw::legend(std::string_view label, const Color& color) {
    if (legend_ == nullptr) return;
    for (const LegendEntry& e : *legend_) {
        if (e.label == label && e.color == color) return;
    }
    legend_->push_back(LegendEntry{std::string(label), color});
}

/// center + cos(t) u + sin(t) v over a full turn in n segments.
void GlDebugDraw::circle(const Vec3& center, const Vec3& u, const Vec3& v, int n,
                     const Color& color) {
    Vec3 prev = center + u;
    for (int i = 1; i <= n; ++i) {
        const Real t = 2 * kPi * Real(i) / Real(n);
        const Vec3 p =
            i == n ? Vec3(center + u) : Vec3(center + std::cos(t) * u + std::sin(t) * v);
        drawLine(prev, p, color);
        prev = p;
    }
}

}  // namespace render
