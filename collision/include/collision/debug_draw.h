// collision/debug_draw.h -- what the collision library can draw, without knowing who draws.
// render/ implements it; app connects the two (Box2D b2DebugDraw, Jolt DebugRenderer).
#pragma once

#include <string_view>

#include "collision/math.h"
#include "collision/volumes/bounding_volumes.h"

namespace collision {

struct Color {
    float r = 1, g = 1, b = 1, a = 1;
};

class DebugDraw {
public:
    virtual ~DebugDraw() = default;
    /// A line segment in world coordinates.
    virtual void drawLine(const Vec3& a, const Vec3& b, const Color& color) = 0;
    virtual void drawAabb(const Aabb& box, const Color& color);
    virtual void drawObb(const Obb& box, const Color& color);
    /// A wire sphere (three great circles).
    virtual void drawSphere(const BoundingSphere& sphere, const Color& color);
};

}  // namespace collision
