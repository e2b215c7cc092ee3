// render/src/renderer.cpp -- OSMesa software rendering of a World: the GL set-up, shaded
// bodies, the overlays' line buffers (what they hold is engine::drawWorld's decision), the
// supersampled pixels read back and filtered, then the legends and HUD (overlay.cpp).
// Invariant: a frame is a pure function of (world state, camera, options, size). Nothing that
// shapes a pixel reads a clock (the clock only times the stages for FrameStats), geometry is
// generated in a fixed order, and all vertices are eye-relative, so the same state renders
// bit-identical pixels and large world coordinates do not lose float precision.
#include "render/renderer.h"

#include <GL/gl.h>
#include <GL/osmesa.h>
#if defined(__SSE2__) && defined(__x86_64__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "collision/geometry/shape.h"
#include "collision/volumes/bounding_volumes.h"
#include "renderer_impl.h"

namespace render {
namespace {

using collision::Color;
using collision::Mat3;
using collision::Pose;
using collision::Real;
using collision::Vec3;

// One output row of a 2x2 box filter: `width` RGB pixels, each the rounded mean
// ((a + b + c + d + 2) >> 2) of two adjacent RGBA pixels in `r0` and the two below them in `r1`.
void downsampleRow2x2(const std::uint8_t* r0, const std::uint8_t* r1, int width,
                      std::uint8_t* dst) {
    int x = 0;
#if defined(__SSE2__) && defined(__x86_64__)
    // Two output pixels per 16 bytes of each row, in 16-bit lanes (the sum of four bytes fits).
    // Each pixel is stored as 4 bytes at 3x, its alpha overwritten by the next pixel's red, so
    // the row's last pixel is left to the scalar loop (its 4th byte would leave the row).
    const __m128i zero = _mm_setzero_si128();
    const __m128i two = _mm_set1_epi16(2);
    for (; x + 2 < width; x += 2) {
        const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r0 + 8 * x));
        const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r1 + 8 * x));
        const __m128i lo = _mm_add_epi16(_mm_unpacklo_epi8(a, zero), _mm_unpacklo_epi8(b, zero));
        const __m128i hi = _mm_add_epi16(_mm_unpackhi_epi8(a, zero), _mm_unpackhi_epi8(b, zero));
        const __m128i sum = _mm_add_epi16(_mm_unpacklo_epi64(lo, hi), _mm_unpackhi_epi64(lo, hi));
        const __m128i mean = _mm_srli_epi16(_mm_add_epi16(sum, two), 2);
        const __m128i bytes = _mm_packus_epi16(mean, mean);
        const std::uint64_t two_pixels = std::uint64_t(_mm_cvtsi128_si64(bytes));
        const std::uint32_t p0 = std::uint32_t(two_pixels);
        const std::uint32_t p1 = std::uint32_t(two_pixels >> 32);
        std::memcpy(dst + 3 * x, &p0, 4);
        std::memcpy(dst + 3 * x + 3, &p1, 4);
    }
#endif
    for (; x < width; ++x) {
        const int o = 8 * x;
        for (int k = 0; k < 3; ++k) {
            const int sum = r0[o + k] + r0[o + 4 + k] + r1[o + k] + r1[o + 4 + k];
            dst[3 * x + k] = static_cast<std::uint8_t>((sum + 2) >> 2);
        }
    }
}

}  // namespace

// ---------------------------------------------------------------------------------------------

void Renderer::Impl::buildLines(const engine::World& world, const CameraFrame& cam,
                                const FrameOptions& options) {
    lines.clear();
    GlDebugDraw debug(cam, lines, options.cull, stats.volumes_culled);
    drawn = engine::drawWorld(world, debug, {options.draw, options.draw_structure, options.selected});
}

CameraFrame Renderer::Impl::setUpCamera(const engine::World& world,
                                        const engine::CameraSettings& camera,
                                        const FrameOptions& options) {
    CameraFrame cam = makeCameraFrame(camera, width * ss, height * ss);
    // Clip planes hug everything that may be drawn: the bounds and every body's volumes (the
    // AABB's and OBB's circumspheres enclose the body and its wireframes).
    DepthRange range;
    const collision::Aabb& bounds = world.settings().bounds;
    // Structure diagrams laid out along the bounds' edges reach 17 % of its size beyond them.
    const Real structure_margin =
        options.draw_structure ? Real(0.17) * bounds.extents().maxCoeff() : Real(0);
    range.add(cam, bounds.center(), Real(0.5) * bounds.extents().norm() + structure_margin);
    const auto bodies = world.bodies();
    const auto volumes = world.volumes();
    for (std::size_t i = 0; i < bodies.size(); ++i) {
        const engine::Body& body = bodies[i];
        const Pose pose = body.pose();
        range.add(cam, pose.apply(body.local_bounds.sphere.center),
                  body.local_bounds.sphere.radius);
        if (i < volumes.size()) {
            const collision::ProxyVolumes& v = volumes[i];
            range.add(cam, v.sphere.center, v.sphere.radius);
            range.add(cam, v.aabb.center(), Real(0.5) * v.aabb.extents().norm());
            range.add(cam, v.obb.center, v.obb.half_extents.norm());
        }
    }
    setClipPlanes(cam, range);
    return cam;
}

void Renderer::Impl::setUpGl(const CameraFrame& cam) {
    glViewport(0, 0, width * ss, height * ss);
    glClearColor(kBackgroundColor.r, kBackgroundColor.g, kBackgroundColor.b, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

    // gluPerspective. GL matrices are column-major: each line below is one column.
    const double f = 1.0 / double(cam.tan_half_fov);
    const double n = double(cam.near_plane);
    const double fa = double(cam.far_plane);
    // clang-format off
    const GLdouble projection[16] = {f / double(cam.aspect), 0, 0,                     0,
                                     0,                      f, 0,                     0,
                                     0,                      0, (fa + n) / (n - fa),  -1,
                                     0,                      0, 2 * fa * n / (n - fa), 0};
    // clang-format on
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixd(projection);

    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    // Lights in eye space (set under the identity): a key light from the upper left behind the
    // viewer and a dim fill from the lower right, so shapes read the same from any camera.
    const GLfloat key_dir[4] = {-0.38f, 0.62f, 0.69f, 0.0f};
    const GLfloat key_diffuse[4] = {0.78f, 0.78f, 0.76f, 1.0f};
    const GLfloat key_specular[4] = {0.35f, 0.35f, 0.35f, 1.0f};
    const GLfloat fill_dir[4] = {0.62f, -0.30f, 0.72f, 0.0f};
    const GLfloat fill_diffuse[4] = {0.26f, 0.28f, 0.32f, 1.0f};
    const GLfloat black[4] = {0, 0, 0, 1};
    const GLfloat ambient[4] = {0.20f, 0.20f, 0.22f, 1.0f};
    glLightfv(GL_LIGHT0, GL_POSITION, key_dir);
    glLightfv(GL_LIGHT0, GL_DIFFUSE, key_diffuse);
    glLightfv(GL_LIGHT0, GL_SPECULAR, key_specular);
    glLightfv(GL_LIGHT0, GL_AMBIENT, black);
    glLightfv(GL_LIGHT1, GL_POSITION, fill_dir);
    glLightfv(GL_LIGHT1, GL_DIFFUSE, fill_diffuse);
    glLightfv(GL_LIGHT1, GL_SPECULAR, black);
    glLightfv(GL_LIGHT1, GL_AMBIENT, black);
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, ambient);
    glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_FALSE);
    glLightModeli(GL_LIGHT_MODEL_LOCAL_VIEWER, GL_FALSE);
    glEnable(GL_LIGHT0);
    glEnable(GL_LIGHT1);

    // World to eye: rotation only, because vertices are already eye-relative (gluLookAt rows
    // right, up, -forward).
    // clang-format off
    const GLdouble view[16] = {cam.right.x(), cam.up.x(), -cam.forward.x(), 0,
                               cam.right.y(), cam.up.y(), -cam.forward.y(), 0,
                               cam.right.z(), cam.up.z(), -cam.forward.z(), 0,
                               0,             0,          0,                1};
    // clang-format on
    glLoadMatrixd(view);

    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDisable(GL_CULL_FACE);
    glDisable(GL_DITHER);
    glShadeModel(GL_SMOOTH);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
}

void Renderer::Impl::drawBodies(const engine::World& world, const CameraFrame& cam,
                                const FrameOptions& options) {
    triangles.clear();
    for (const engine::Body& body : world.bodies()) {
        const collision::Shape& shape = body.shape;
        const Pose pose = body.pose();
        if (!pose.position.allFinite() || !pose.orientation.coeffs().allFinite()) continue;
        if (options.cull && !cam.mayShow(pose.apply(body.local_bounds.sphere.center),
                                         body.local_bounds.sphere.radius)) {
            ++stats.bodies_culled;
            continue;
        }
        ++stats.bodies_drawn;
        // Drawn in batches, in body order: the depth test sees the same fragments in the same
        // order as one draw of everything, and memory stays bounded for 10^5 bodies.
        if (triangles.count() >= options.triangle_batch_vertices) drawTriangles();
        switch (shape.type) {
            case collision::ShapeType::Sphere:
            case collision::ShapeType::Capsule: {
                const Real h = shape.type == collision::ShapeType::Capsule ? shape.half_height : 0;
                const int slices = segmentsFor(cam, pose.position, shape.radius + h, 10, 12, 64);
                tessellateCapsule(sphereGrid(slices), shape.radius, h, pose, cam, triangles);
                break;
            }
            case collision::ShapeType::Box:
                tessellateBox(shape.half_extents, pose, cam, triangles);
                break;
            case collision::ShapeType::ConvexHull:
                if (shape.hull) {
                    tessellateTriangles(shape.hull->vertices, shape.hull->faces, pose, cam,
                                        triangles);
                }
                break;
            case collision::ShapeType::Mesh:
                if (shape.mesh) {
                    tessellateTriangles(shape.mesh->vertices, shape.mesh->triangles, pose, cam,
                                        triangles);
                }
                break;
        }
    }
    drawTriangles();
    drawSelfPairs(world, cam);
}

// The triangles of each self_collision mesh body that cross another of its triangles, drawn
// again in the colliding colour over the body's own (the same vertices give the same depths,
// and GL_LEQUAL lets the second draw win).
void Renderer::Impl::drawSelfPairs(const engine::World& world, const CameraFrame& cam) {
    std::vector<std::array<std::int32_t, 3>> hit;
    for (std::size_t i = 0; i < world.bodies().size(); ++i) {
        const std::span<const collision::TrianglePair> pairs =
            world.selfPairs(static_cast<engine::BodyId>(i));
        const engine::Body& body = world.bodies()[i];
        if (pairs.empty() || !body.shape.mesh) continue;
        std::vector<std::int32_t> ids;
        for (const collision::TrianglePair& p : pairs) {
            ids.push_back(p.a);
            ids.push_back(p.b);
        }
        std::sort(ids.begin(), ids.end());
        ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
        hit.clear();
        for (const std::int32_t t : ids) {
            hit.push_back(body.shape.mesh->triangles[static_cast<std::size_t>(t)]);
        }
        tessellateTriangles(body.shape.mesh->vertices, hit, body.pose(), cam, triangles);
    }
    drawTriangles(engine::stateColor(engine::BodyState::Colliding));
}


void Renderer::Impl::drawTriangles(const collision::Color& color) {
    if (triangles.count() == 0) return;
    struct Clear {
        TriangleBuffer& buffer;
        ~Clear() { buffer.clear(); }
    } clear_after{triangles};
    ++stats.batches;
    stats.triangle_vertices += triangles.count();
    stats.largest_batch_vertices =
        std::max<std::int64_t>(stats.largest_batch_vertices, triangles.count());
    glEnable(GL_LIGHTING);
    glEnable(GL_COLOR_MATERIAL);
    glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
    const GLfloat specular[4] = {0.30f, 0.30f, 0.30f, 1.0f};
    glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, specular);
    glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, 40.0f);
    glColor4f(color.r, color.g, color.b, 1.0f);
    // Pushed back a little so wireframes lying on the surface (a sphere's bounding sphere, a
    // box's OBB) win the depth test instead of z-fighting; the slope term covers the rim.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 2.0f);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);

    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_NORMAL_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, triangles.positions.data());
    glNormalPointer(GL_FLOAT, 0, triangles.normals.data());
    glDrawArrays(GL_TRIANGLES, 0, triangles.count());
    glDisableClientState(GL_NORMAL_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);

    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_COLOR_MATERIAL);
    glDisable(GL_LIGHTING);
}

void Renderer::Impl::drawLines(const LineBuffer& buffer, float width_px) {
    if (buffer.count() == 0) return;
    glDisable(GL_LIGHTING);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glDepthMask(GL_FALSE);  // wireframes never hide each other
    glLineWidth(width_px * float(ss));
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, buffer.positions.data());
    // Pass 1: the parts behind a body, faint (x-ray). Pass 2: the visible parts, full colour.
    glDepthFunc(GL_GREATER);
    glColorPointer(4, GL_FLOAT, 0, buffer.faint_colors.data());
    glDrawArrays(GL_LINES, 0, buffer.count());
    glDepthFunc(GL_LEQUAL);
    glColorPointer(4, GL_FLOAT, 0, buffer.colors.data());
    glDrawArrays(GL_LINES, 0, buffer.count());
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
}

void Renderer::Impl::readPixels(Image& image) {
    // glFinish() leaves the frame in the context's own RGBA buffer (OSMesa copies its render
    // target there): read it in place rather than through glReadPixels, which converts RGBA to
    // RGB in a second full pass over the supersampled frame. Same bytes, no conversion.
    const int gw = width * ss;
    const int gh = height * ss;
    const GLubyte* rgba = context.pixels();

    image.width = width;
    image.height = height;
    image.rgb.resize(std::size_t(width) * std::size_t(height) * 3);
    // GL rows run bottom-up: flip so row 0 is the top, and box-filter each ss x ss block,
    // rounding the mean to nearest ((sum + n/2) / n).
    if (ss == 2) {
        for (int y = 0; y < height; ++y) {
            const GLubyte* r0 = rgba + std::size_t(gh - 1 - 2 * y) * std::size_t(gw) * 4;
            const GLubyte* r1 = rgba + std::size_t(gh - 2 - 2 * y) * std::size_t(gw) * 4;
            downsampleRow2x2(r0, r1, width, &image.rgb[std::size_t(y) * std::size_t(width) * 3]);
        }
        return;
    }
    const int n = ss * ss;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            int sum[3] = {0, 0, 0};
            for (int dy = 0; dy < ss; ++dy) {
                const int gl_row = gh - 1 - (y * ss + dy);
                const GLubyte* src = &rgba[(std::size_t(gl_row) * gw + std::size_t(x) * ss) * 4];
                for (int dx = 0; dx < ss; ++dx) {
                    sum[0] += src[dx * 4 + 0];
                    sum[1] += src[dx * 4 + 1];
                    sum[2] += src[dx * 4 + 2];
                }
            }
            std::uint8_t* dst = &image.rgb[(std::size_t(y) * width + x) * 3];
            for (int k = 0; k < 3; ++k) dst[k] = static_cast<std::uint8_t>((sum[k] + n / 2) / n);
        }
    }
}


Renderer::Renderer(int width, int height) : impl_(std::make_unique<Impl>(width, height)) {}

Renderer::~Renderer() = default;

int Renderer::width() const { return impl_->width; }
int Renderer::height() const { return impl_->height; }
int Renderer::supersample() const { return impl_->ss; }
const FrameStats& Renderer::lastFrameStats() const { return impl_->stats; }

Image Renderer::render(const engine::World& world, const engine::CameraSettings& camera,
                       const FrameOptions& options) {
    Image image;
    render(world, camera, options, image);
    return image;
}

void Renderer::render(const engine::World& world, const engine::CameraSettings& camera,
                      const FrameOptions& options, Image& image) {
    const auto start = std::chrono::steady_clock::now();
    Impl& im = *impl_;
    im.context.makeCurrent();
    const CameraFrame cam = im.setUpCamera(world, camera, options);
    im.setUpGl(cam);
    im.stats = FrameStats{};
    if (options.draw.bodies) im.drawBodies(world, cam, options);
    im.buildLines(world, cam, options);
    im.drawLines(im.lines.frame, 1.0f);
    im.drawLines(im.lines.structure, 1.0f);
    im.drawLines(im.lines.outlines, 1.0f);
    im.drawLines(im.lines.volumes, 2.0f);
    im.drawLines(im.lines.hierarchy, 1.0f);
    im.drawLines(im.lines.contacts, 2.0f);
    im.drawLines(im.lines.selection, 3.0f);
    const GLenum error = glGetError();
    if (error != GL_NO_ERROR) {
        throw RenderError("OpenGL error " + std::to_string(error) + " while rendering a frame");
    }
    glFinish();
    const auto drawn = std::chrono::steady_clock::now();
    im.readPixels(image);
    if (options.draw.labels || options.selected) im.drawLabels(image, world, camera, options);
    im.drawOverlays(image, options);
    const auto read = std::chrono::steady_clock::now();
    im.stats.draw_s = std::chrono::duration<double>(drawn - start).count();
    im.stats.readback_s = std::chrono::duration<double>(read - drawn).count();
}


}  // namespace render
