// render/src/renderer_impl.h -- the renderer's state between frames and its drawing steps,
// shared by the files that implement them: renderer.cpp (GL set-up, bodies, triangles, lines,
// pixels), frame_lines.cpp (what the frame draws as lines) and overlay.cpp (legends and HUD).
#pragma once

#include <map>
#include <optional>
#include <vector>

#include "camera.h"
#include "gl_debug_draw.h"
#include "legend.h"
#include "osmesa_context.h"
#include "render/renderer.h"
#include "render/volume_states.h"
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
    LineBuffer frame_lines;                     ///< world bounds and floor grid
    LineBuffer structure_lines;                 ///< the broad phase's own drawing
    LineBuffer volume_lines;                    ///< bounding volumes
    LineBuffer outline_lines;                   ///< bounding spheres' silhouettes
    LineBuffer bvh_lines;                       ///< mesh hierarchy levels (draw.bvh_depth)
    LineBuffer contact_lines;                   ///< contact witnesses and normals (draw.contacts)
    std::vector<LegendEntry> structure_legend;  ///< what the broad phase's colours show
    /// Some volume drawn is not the kind the broad phase tests: the legend says that each
    /// volume is coloured by its own test.
    bool own_tests = false;
    std::optional<VolumeKind> tested_volume;  ///< the kind the broad phase tests
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
    void buildLines(const engine::World& world, const CameraFrame& cam,
                    const FrameOptions& options);
    /// The bounding-volume wireframes, each kind in the colours of its own overlap test.
    void drawVolumes(const engine::World& world, const CameraFrame& cam,
                     const FrameOptions& options, GlDebugDraw& debug);
    void drawKdops(const engine::World& world, const FrameOptions& options, GlDebugDraw& debug);
    /// Draws the triangle buffer and empties it.
    void drawTriangles(const collision::Color& color = kBodyColor);
    void drawSelfPairs(const engine::World& world, const CameraFrame& cam);
    void drawLines(const LineBuffer& lines, float width_px);
    void readPixels(Image& image);
    void drawOverlays(Image& image, const FrameOptions& options) const;
};

}  // namespace render
