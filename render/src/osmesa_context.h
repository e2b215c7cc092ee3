// render/src/osmesa_context.h -- the off-screen OSMesa context (RAII) and the supersampling
// factor a frame size allows. Private to render.
#pragma once

#include <GL/gl.h>
#include <GL/osmesa.h>

#include <string>
#include <vector>

#include "render/image.h"

namespace render {


class OsMesaContext {
public:
    OsMesaContext(int width, int height) : width_(width), height_(height) {
        context_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
        if (!context_) throw RenderError("OSMesa: cannot create an RGBA context with 24-bit depth");
        buffer_.resize(std::size_t(width) * std::size_t(height) * 4);
        makeCurrent();
        if (!glGetString(GL_VERSION)) {
            OSMesaDestroyContext(context_);
            throw RenderError("OSMesa: GL_VERSION is NULL (is libGL linked beside libOSMesa?)");
        }
    }
    ~OsMesaContext() { OSMesaDestroyContext(context_); }
    OsMesaContext(const OsMesaContext&) = delete;
    OsMesaContext& operator=(const OsMesaContext&) = delete;

    /// The colour buffer OSMesa renders into: RGBA8, width x height, row 0 at the bottom
    /// (OSMESA_Y_UP). Complete once glFinish() has returned.
    const GLubyte* pixels() const { return buffer_.data(); }

    /// Contexts are current per thread: every frame binds its own before drawing.
    void makeCurrent() {
        if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width_, height_)) {
            throw RenderError("OSMesa: cannot make a " + std::to_string(width_) + "x" +
                              std::to_string(height_) + " context current");
        }
    }

private:
    OSMesaContext context_ = nullptr;
    int width_;
    int height_;
    std::vector<GLubyte> buffer_;
};

/// Supersampling per axis (2, else 1) that OSMesa's maximum size allows for width x height;
/// throws RenderError for a non-positive size or one past that maximum.
int supersampleFor(int width, int height);

}  // namespace render
