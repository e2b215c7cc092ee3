// render/src/gl_debug_draw.h -- the vertex buffers a frame fills (eye-relative floats, in a fixed
// order every frame) and the engine::WorldDraw that records lines into them, one buffer per
// layer: what engine::drawWorld (and through it the broad phases and the World) draws through.
// Private to render.
#pragma once

#include <GL/gl.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "camera.h"
#include "collision/debug_draw.h"
#include "collision/volumes/bounding_volumes.h"
#include "engine/world_draw.h"

namespace render {

/// Lines behind a body show through this faintly.
inline constexpr float kHiddenLineAlpha = 0.3f;


struct TriangleBuffer {
    std::vector<float> positions;
    std::vector<float> normals;

    void clear() {
        positions.clear();
        normals.clear();
    }
    void add(const Vec3& p_eye, const Vec3& n_world) {
        positions.insert(positions.end(), {float(p_eye.x()), float(p_eye.y()), float(p_eye.z())});
        normals.insert(normals.end(), {float(n_world.x()), float(n_world.y()), float(n_world.z())});
    }
    GLsizei count() const { return GLsizei(positions.size() / 3); }
};

struct LineBuffer {
    std::vector<float> positions;
    std::vector<float> colors;
    std::vector<float> faint_colors;  ///< same colours at kHiddenLineAlpha

    void clear() {
        positions.clear();
        colors.clear();
        faint_colors.clear();
    }
    void add(const Vec3& a_eye, const Vec3& b_eye, const Color& c) {
        positions.insert(positions.end(), {float(a_eye.x()), float(a_eye.y()), float(a_eye.z()),
                                           float(b_eye.x()), float(b_eye.y()), float(b_eye.z())});
        colors.insert(colors.end(), {c.r, c.g, c.b, c.a, c.r, c.g, c.b, c.a});
        const float fa = c.a * kHiddenLineAlpha;
        faint_colors.insert(faint_colors.end(), {c.r, c.g, c.b, fa, c.r, c.g, c.b, fa});
    }
    GLsizei count() const { return GLsizei(positions.size() / 3); }
};

/// One line of a legend: a colour swatch and what lines of that colour show.
struct LegendEntry {
    std::string label;
    Color color;
};

/// Segments around a circle of `radius` centred at `center` so that each spans about
/// `px_per_segment` framebuffer pixels, a multiple of 4 in [lo, hi].
int segmentsFor(const CameraFrame& cam, const Vec3& center, Real radius, Real px_per_segment,
                int lo, int hi);

/// The lines of one frame, a buffer per engine::DrawLayer (the volumes' sphere silhouettes in
/// their own, drawn thinner), and the legend entries the broad phase's structure gave.
struct FrameLines {
    LineBuffer frame;      ///< world bounds and floor grid
    LineBuffer structure;  ///< the broad phase's own drawing
    LineBuffer volumes;    ///< bounding volumes, poses at impact, skeletons
    LineBuffer outlines;   ///< bounding spheres' silhouettes
    LineBuffer hierarchy;  ///< mesh hierarchy levels (draw.bvh_depth)
    LineBuffer contacts;   ///< contact witnesses and normals (draw.contacts)
    LineBuffer selection;  ///< the selected body's volumes, drawn last and widest
    std::vector<LegendEntry> structure_legend;

    void clear();
};

// Records what engine::drawWorld draws into a frame's buffers, eye-relative.
class GlDebugDraw final : public engine::WorldDraw {
public:
    /// With `cull`, volumes wholly outside the view's side planes are refused (mayShow) and
    /// counted in `culled`.
    GlDebugDraw(const CameraFrame& cam, FrameLines& lines, bool cull, std::int64_t& culled)
        : cam_(cam), lines_(lines), target_(&lines.frame), cull_(cull), culled_(culled) {}

    void setLayer(engine::DrawLayer layer) override;
    bool mayShow(const Vec3& center, Real radius) override;

    void drawLine(const Vec3& a, const Vec3& b, const Color& color) override {
        target_->add(cam_.toEye(a), cam_.toEye(b), color);
    }

    /// Three great circles and the silhouette (gl_debug_draw.cpp).
    void drawSphere(const collision::BoundingSphere& sphere, const Color& color) override;

    /// Appends the entry to the structure's legend unless the same (label, colour) is already
    /// listed; dropped outside the Structure layer.
    void legend(std::string_view label, const Color& color) override;

private:
    /// center + cos(t) u + sin(t) v over a full turn in n segments.
    void circle(const Vec3& center, const Vec3& u, const Vec3& v, int n, const Color& color);

    const CameraFrame& cam_;
    FrameLines& lines_;
    LineBuffer* target_;
    LineBuffer* outlines_ = nullptr;
    std::vector<LegendEntry>* legend_ = nullptr;
    bool cull_;
    std::int64_t& culled_;
};

}  // namespace render
