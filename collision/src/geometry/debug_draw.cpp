// collision/src/geometry/debug_draw.cpp -- default DebugDraw shapes, built from drawLine.
#include "collision/debug_draw.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace collision {

void DebugDraw::drawAabb(const Aabb& box, const Color& color) {
    Obb o;
    o.center = box.center();
    o.half_extents = box.extents() * Real(0.5);
    drawObb(o, color);
}

void DebugDraw::drawObb(const Obb& box, const Color& color) {
    Vec3 c[8];
    box.corners(c);
    // Corner k has bit 0 = +x, bit 1 = +y, bit 2 = +z: edges join corners one bit apart.
    for (int k = 0; k < 8; ++k) {
        for (int bit = 1; bit < 8; bit <<= 1) {
            if (!(k & bit)) drawLine(c[k], c[k | bit], color);
        }
    }
}

void DebugDraw::drawKdop(const WorldKdop& kdop, const Color& color) {
    const KdopPolytope p = kdopPolytope(kdop);
    for (const auto& [a, b] : p.edges) {
        drawLine(p.vertices[std::size_t(a)], p.vertices[std::size_t(b)], color);
    }
}

void DebugDraw::drawSphere(const BoundingSphere& sphere, const Color& color) {
    constexpr int kSegments = 48;
    const Real step = Real(2) * std::numbers::pi_v<Real> / kSegments;
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3;
        const int v = (axis + 2) % 3;
        Vec3 prev = sphere.center;
        prev[u] += sphere.radius;
        for (int s = 1; s <= kSegments; ++s) {
            Vec3 p = sphere.center;
            p[u] += sphere.radius * std::cos(step * s);
            p[v] += sphere.radius * std::sin(step * s);
            drawLine(prev, p, color);
            prev = p;
        }
    }
}

void legendByNumber(DebugDraw& draw, std::string_view prefix, int count, std::string_view suffix) {
    for (int first = 0; first < std::min(count, kStructurePaletteSize); ++first) {
        std::string label(prefix);
        for (int k = first; k < count; k += kStructurePaletteSize) {
            label += k == first ? " " : ", ";
            label += std::to_string(k);
        }
        label += suffix;
        draw.legend(label, structureColor(first));
    }
}

}  // namespace collision
