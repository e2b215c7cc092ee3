// render/src/osmesa_context.cpp -- see osmesa_context.h.
#include "osmesa_context.h"

#include <algorithm>

namespace render {

namespace {

constexpr int kMaxSupersample = 2;

int maxOsMesaSize() {
    GLint max_width = 0;
    GLint max_height = 0;
    OSMesaGetIntegerv(OSMESA_MAX_WIDTH, &max_width);
    OSMesaGetIntegerv(OSMESA_MAX_HEIGHT, &max_height);
    const int m = std::min(max_width, max_height);
    return m > 0 ? m : 4096;
}

}  // namespace

int supersampleFor(int width, int height) {
    if (width <= 0 || height <= 0) {
        throw RenderError("render size " + std::to_string(width) + "x" + std::to_string(height) +
                          " must be positive");
    }
    const int max_size = maxOsMesaSize();
    for (int ss = kMaxSupersample; ss > 1; --ss) {
        if (std::max(width, height) * ss <= max_size) return ss;
    }
    if (std::max(width, height) > max_size) {
        throw RenderError("render size " + std::to_string(width) + "x" + std::to_string(height) +
                          " exceeds OSMesa's maximum " + std::to_string(max_size));
    }
    return 1;
}

}  // namespace render
