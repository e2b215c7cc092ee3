// render/renderer.h -- software rendering of a World through OSMesa (no display needed):
// shaded bodies, bounding-volume wireframes coloured by overlap state, world bounds, HUD text.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "collision/debug_draw.h"
#include "engine/scene.h"
#include "engine/world.h"
#include "render/image.h"

namespace render {

/// The clear colour behind everything, a dark blue-grey: exactly RGB8 (26, 28, 36).
inline constexpr collision::Color kBackgroundColor{26 / 255.0f, 28 / 255.0f, 36 / 255.0f, 1.0f};
/// The shaded bodies' base colour (a neutral grey-blue) before lighting.
inline constexpr collision::Color kBodyColor{0.56f, 0.63f, 0.74f, 1.0f};

/// A rectangle of a picture in pixels: x to the right and y down from the top-left corner.
struct ScreenRect {
    double x0 = 0, y0 = 0;  ///< top-left
    double x1 = 0, y1 = 0;  ///< bottom-right
};

/// Where the world-frame box [min, max] shows in a width x height picture that render() takes
/// with `camera` (gluLookAt and gluPerspective): the bounding rectangle of its eight corners'
/// images, clipped to the picture. Nothing when a corner lies at or behind the eye's plane, or
/// when the rectangle misses the picture.
std::optional<ScreenRect> screenRect(const engine::CameraSettings& camera, int width, int height,
                                     const collision::Vec3& min, const collision::Vec3& max);

/// What one frame shows: the overlays as engine::drawWorld draws them for (draw, draw_structure),
/// and the HUD. With draw.hud and any volume (or hierarchy level) drawn, a colour legend (apart /
/// flagged / colliding) goes bottom-left.
struct FrameOptions {
    engine::DrawSettings draw;
    bool draw_structure = false;  ///< the broad phase's own structure (BroadPhase::draw)
    /// One body highlighted (engine::DrawOptions::selected) and named beside it.
    std::optional<engine::BodyId> selected;
    std::string hud_text;         ///< the HUD line, top-left; empty = none
    /// Leave out bodies and volumes wholly outside the view's side planes. Changes no pixel;
    /// false draws everything (the reference the tests compare against).
    bool cull = true;
    /// Bodies are drawn in batches once this many triangle vertices are buffered, so memory
    /// stays bounded whatever the number of bodies; batches change no pixel (same draw order).
    std::int64_t triangle_batch_vertices = std::int64_t(1) << 20;
};

/// What the last frame drew, for tests and the curious.
struct FrameStats {
    std::int64_t bodies_drawn = 0;
    std::int64_t bodies_culled = 0;      ///< outside the view (FrameOptions::cull)
    std::int64_t volumes_culled = 0;     ///< bounding-volume wireframes outside the view
    std::int64_t triangle_vertices = 0;  ///< all batches
    std::int64_t batches = 0;
    std::int64_t largest_batch_vertices = 0;
    double draw_s = 0;      ///< wall seconds: GL calls until the picture is finished (glFinish)
    double readback_s = 0;  ///< wall seconds: supersampled buffer -> RGB image, overlays
};

class Renderer {
public:
    /// Creates an off-screen OSMesa context of that size (pixels, > 0); throws RenderError.
    /// Frames are rendered 2x2 supersampled when OSMesa allows the size, then box-filtered.
    Renderer(int width, int height);
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    /// Renders the world's current state. Deterministic: the same world state, camera and
    /// options give a bit-identical image. `world` must have run detect() or step() so that its
    /// volumes and states match its bodies (volumes it lacks are not drawn).
    Image render(const engine::World& world, const engine::CameraSettings& camera,
                 const FrameOptions& options);
    /// The same picture written into `image`, whose storage is reused when large enough (a
    /// video's frames then cost no fresh pages, which the kernel would have to zero).
    void render(const engine::World& world, const engine::CameraSettings& camera,
                const FrameOptions& options, Image& image);

    int width() const;
    int height() const;
    /// Supersampling factor per axis actually used (1 or 2).
    int supersample() const;
    /// Counts of the last render().
    const FrameStats& lastFrameStats() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The default HUD line: "frame F  t=1.23 s  sap  flagged N  colliding M  step 0.12 ms".
/// `include_timing` false leaves the step time out so that frames are bit-identical run to run.
std::string hudLine(const engine::World& world, int frame, bool include_timing);

}  // namespace render
