// render/src/renderer_impl.h -- the renderer's state between frames and its drawing steps,
// shared by the files that implement them: renderer.cpp (GL set-up, bodies, triangles, lines,
// pixels), gl_debug_draw.cpp (the overlays' lines) and overlay.cpp (legends and HUD).
#pragma once

#include <map>
#include <optional>
#include <vector>

#include "camera.h"
#include "gl_debug_draw.h"
#include "legend.h"
#include "osmesa_context.h"
#include "render/renderer.h"
#include "tessellation.h"

namespace render {

struct Renderer::Impl {
    Impl(int w, int h) : width(w), height(h), ss(supersampleFor(w, h)), context(w * ss, h * ss) {}

    int width;
    int height;
    int ss;
    OsMesaContext context;
    std::map<int, UnitSphereGrid> sphere_grids;  ///< by slice count
    TriangleBuffer triangles;
    FrameLines lines;
    engine::WorldDrawn drawn;  ///< what the last frame's overlays showed, for its legend
    FrameStats stats;

    const UnitSphereGrid& sphereGrid(int slices) {
        auto it = sphere_grids.find(slices);
        if (it == sphere_grids.end()) {
            it = sphere_grids.emplace(slices, makeUnitSphereGrid(slices)).first;
        }
        return it->second;
    }

    CameraFrame setUpCamera(const engine::World& world, const engine::CameraSettings& camera,
                            const FrameOptions& options);
    void setUpGl(const CameraFrame& cam);
    /// Tessellates and draws every body that may show, in batches.
    void drawBodies(const engine::World& world, const CameraFrame& cam,
                    const FrameOptions& options);
    /// Every overlay's lines, as engine::drawWorld decides them.
    void buildLines(const engine::World& world, const CameraFrame& cam,
                    const FrameOptions& options);
    /// Draws the triangle buffer and empties it.
    void drawTriangles(const collision::Color& color = kBodyColor);
    void drawSelfPairs(const engine::World& world, const CameraFrame& cam);
    void drawLines(const LineBuffer& buffer, float width_px);
    void readPixels(Image& image);
    void drawOverlays(Image& image, const FrameOptions& options) const;
    /// Body names above their boxes' pictures (draw.labels), the selected body's always.
    void drawLabels(Image& image, const engine::World& world, const engine::CameraSettings& camera,
                    const FrameOptions& options) const;
};

}  // namespace render
