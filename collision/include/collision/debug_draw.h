// collision/debug_draw.h -- what the collision library can draw, without knowing who draws.
// render/ implements it; app connects the two (Box2D b2DebugDraw, Jolt DebugRenderer).
#pragma once

#include <string_view>

#include "collision/math.h"
#include "collision/volumes/bounding_volumes.h"
#include "collision/volumes/kdop_volume.h"

namespace collision {

struct Color {
    float r = 1, g = 1, b = 1, a = 1;
    friend bool operator==(const Color&, const Color&) = default;
};

/// The colours a broad phase draws its own structure in (cells, intervals, nodes), in the order
/// they are handed out: cyan, orange, violet, pink, tan, teal. None is, or blends over a dark
/// background into, a colour the overlays already give a meaning: the overlap states (green
/// apart, yellow flagged, red colliding), the time-of-impact blue or the contact magenta.
inline constexpr Color kStructurePalette[] = {
    {0.00f, 0.80f, 0.85f, 1.0f},  // cyan
    {1.00f, 0.50f, 0.00f, 1.0f},  // orange
    {0.62f, 0.42f, 1.00f, 1.0f},  // violet
    {1.00f, 0.60f, 0.75f, 1.0f},  // pink
    {0.80f, 0.65f, 0.45f, 1.0f},  // tan
    {0.00f, 0.55f, 0.55f, 1.0f},  // teal
};
inline constexpr int kStructurePaletteSize =
    int(sizeof kStructurePalette / sizeof kStructurePalette[0]);

/// kStructurePalette[index mod its size], for numbered things (levels, depths); index >= 0.
inline constexpr Color structureColor(int index) {
    return kStructurePalette[index % kStructurePaletteSize];
}

class DebugDraw {
public:
    virtual ~DebugDraw() = default;
    /// A line segment in world coordinates.
    virtual void drawLine(const Vec3& a, const Vec3& b, const Color& color) = 0;
    virtual void drawAabb(const Aabb& box, const Color& color);
    virtual void drawObb(const Obb& box, const Color& color);
    /// The edges of the k-DOP's polytope (kdopPolytope).
    virtual void drawKdop(const WorldKdop& kdop, const Color& color);
    /// A wire sphere (three great circles).
    virtual void drawSphere(const BoundingSphere& sphere, const Color& color);
    /// One line of the picture's legend: what the lines of `color` show. Entries are listed in
    /// the order given; a repeated (label, colour) is listed once. Default: ignored.
    virtual void legend(std::string_view /*label*/, const Color& /*color*/) {}
};

/// The lines in `color` of numbered things 0..count-1 drawn in structureColor(number), as
/// legend entries "PREFIX 0, 6, 12" (every number sharing a palette colour in one entry), so
/// a legend stays short however deep a tree is. `suffix` follows the numbers.
void legendByNumber(DebugDraw& draw, std::string_view prefix, int count,
                    std::string_view suffix = {});

}  // namespace collision
