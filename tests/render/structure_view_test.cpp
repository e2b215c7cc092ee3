// tests/render/structure_view_test.cpp -- --draw-structure: each broad phase's own structure in
// colours no overlay state uses, named in a legend; SAP's sorted intervals as 1-D diagrams along
// the edges of the world bounds.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "collision/debug_draw.h"
#include "engine/world.h"
#include "engine/world_draw.h"
#include "pixel_checks.h"
#include "render/renderer.h"

namespace {

using namespace cdlab_test;

const std::vector<std::string> kDrawing = {"grid", "hash",   "hgrid",  "hgrid-levels", "sap",
                                           "sap1", "tree",   "octree", "sphere",       "obb"};

// Bounds that frame the three spheres closely, so diagrams along their edges are in view of
// structureCamera().
const collision::Aabb kFramedBounds{Vec3(-4.5, -2, -1.5), Vec3(4.5, 2, 1.5)};

engine::CameraSettings structureCamera() {
    engine::CameraSettings camera = headOnCamera();
    camera.position = Vec3(0, 0, 14);
    return camera;
}

// Records what a broad phase draws: its segments with their colours, and its legend.
class RecordingDraw final : public collision::DebugDraw {
public:
    struct Segment {
        Vec3 a, b;
        Rgb color;
    };
    void drawLine(const Vec3& a, const Vec3& b, const collision::Color& color) override {
        const Rgb c = toRgb(color);
        segments.push_back({a, b, c});
        if (std::find(colors.begin(), colors.end(), c) == colors.end()) colors.push_back(c);
    }
    void legend(std::string_view label, const collision::Color& color) override {
        labels.emplace_back(label);
        legend_colors.push_back(toRgb(color));
    }
    std::vector<Segment> segments;
    std::vector<Rgb> colors;
    std::vector<std::string> labels;
    std::vector<Rgb> legend_colors;
};

engine::World worldWith(const std::string& broad_phase) {
    engine::World world = makeThreeSphereWorld(kFramedBounds);
    world.setBroadPhase(broad_phase);
    world.detect();  // inserts the proxies into the new broad phase
    return world;
}

// The colours an overlay already gives a meaning to.
std::vector<Rgb> meaningfulColors() {
    return {toRgb(engine::stateColor(engine::BodyState::Apart)),
            toRgb(engine::stateColor(engine::BodyState::Flagged)),
            toRgb(engine::stateColor(engine::BodyState::Colliding)), toRgb(engine::kToiColor),
            toRgb(engine::kContactColor)};
}

// True when `seen` is `line` laid over `under` with a coverage of at least 30 %, within 10 per
// channel: a 1-pixel line falls across two pixels after the supersampling box filter, each then
// a partial blend, so comparing with the line's colour alone would miss it.
bool blendedOver(const Rgb& seen, const Rgb& under, const Rgb& line) {
    double de = 0;
    double ee = 0;
    for (int k = 0; k < 3; ++k) {
        de += double(seen[k] - under[k]) * double(line[k] - under[k]);
        ee += double(line[k] - under[k]) * double(line[k] - under[k]);
    }
    if (ee < 30 * 30) return false;   // the line's colour is (nearly) what was there already
    const double coverage = de / ee;  // least squares: seen - under = coverage (line - under)
    if (coverage < 0.3 || coverage > 1.05) return false;
    for (int k = 0; k < 3; ++k) {
        const double residual = double(seen[k] - under[k]) - coverage * double(line[k] - under[k]);
        if (std::abs(residual) > 10) return false;
    }
    return true;
}

// True when some size x size square of the image is all `color`.
bool hasSolidSquare(const render::Image& image, const Rgb& color, int size) {
    for (int y = 0; y + size <= image.height; ++y) {
        for (int x = 0; x + size <= image.width; ++x) {
            bool solid = true;
            for (int dy = 0; dy < size && solid; ++dy) {
                for (int dx = 0; dx < size && solid; ++dx) {
                    solid = pixelAt(image, x + dx, y + dy) == color;
                }
            }
            if (solid) return true;
        }
    }
    return false;
}

}  // namespace

// --draw-structure: every broad phase that has a structure to show draws it, so the picture
// changes, and the change is in the structure's own colours (not, say, a state colour).
TEST(StructureView, EachBroadPhaseDrawsItsStructureInItsOwnColours) {
    render::Renderer renderer(kWidth, kHeight);
    for (const std::string& name : kDrawing) {
        SCOPED_TRACE(name);
        const engine::World world = worldWith(name);
        ASSERT_EQ(world.broadPhase().name(), name);
        RecordingDraw recorded;
        world.broadPhase().draw(recorded, world.settings().bounds);
        ASSERT_FALSE(recorded.segments.empty()) << "draws nothing";

        render::FrameOptions options = plainOptions();
        const render::Image without = renderer.render(world, structureCamera(), options);
        options.draw_structure = true;
        const render::Image with = renderer.render(world, structureCamera(), options);
        int differing = 0;
        int structure_coloured = 0;  // pixels that show a blend of one of the structure's colours
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                const Rgb a = pixelAt(without, x, y);
                const Rgb b = pixelAt(with, x, y);
                if (a == b) continue;
                ++differing;
                for (const Rgb& c : recorded.colors) {
                    if (blendedOver(b, a, c)) {
                        ++structure_coloured;
                        break;
                    }
                }
            }
        }
        EXPECT_GE(differing, 20) << "structure barely visible";
        EXPECT_GE(structure_coloured, 10)
            << "of " << differing << " changed pixels, too few in the structure's "
            << recorded.colors.size() << " colours";
    }
}

// A broad phase without a structure of its own says so in the legend rather than drawing
// nothing silently: the references, how many pairs they test.
TEST(StructureView, BroadPhasesWithoutAStructureSaySoInTheLegend) {
    for (const std::string name : {"brute", "sphere-brute", "obb-brute"}) {
        SCOPED_TRACE(name);
        const engine::World world = worldWith(name);
        RecordingDraw recorded;
        world.broadPhase().draw(recorded, world.settings().bounds);
        EXPECT_TRUE(recorded.segments.empty());
        ASSERT_EQ(recorded.labels.size(), 1u);
        EXPECT_EQ(recorded.labels[0], name +
                                          ": no structure: every pair of its 3 proxies is tested "
                                          "(3 pairs)");
    }
}

// SAP once drew its x intervals in red and its y intervals in
// green, the colours of a colliding and of an apart volume. No structure colour may be a state
// colour, the time-of-impact blue or the contact magenta, nor blend over the background into one.
TEST(StructureView, PaletteNeverLooksLikeAStateToiOrContactColour) {
    const Rgb background = toRgb(render::kBackgroundColor);
    for (const collision::Color& c : collision::kStructurePalette) {
        const Rgb line = toRgb(c);
        for (const Rgb& meaningful : meaningfulColors()) {
            for (int percent = 30; percent <= 100; percent += 5) {
                Rgb seen;
                for (int k = 0; k < 3; ++k) {
                    seen[k] = background[k] + (line[k] - background[k]) * percent / 100;
                }
                EXPECT_FALSE(close(seen, meaningful, 40))
                    << "palette colour " << line[0] << "," << line[1] << "," << line[2] << " at "
                    << percent << " % looks like " << meaningful[0] << "," << meaningful[1] << ","
                    << meaningful[2];
            }
        }
    }
}

TEST(StructureView, NoPixelTheStructureChangesTakesAStateToiOrContactColour) {
    render::Renderer renderer(kWidth, kHeight);
    for (const std::string& name : kDrawing) {
        SCOPED_TRACE(name);
        const engine::World world = worldWith(name);
        RecordingDraw recorded;
        world.broadPhase().draw(recorded, world.settings().bounds);
        for (const Rgb& c : recorded.colors) {
            for (const Rgb& meaningful : meaningfulColors()) EXPECT_FALSE(close(c, meaningful, 40));
        }
        render::FrameOptions options = plainOptions();
        options.draw.sphere = false;  // no state colour anywhere but where the structure is
        const render::Image without = renderer.render(world, structureCamera(), options);
        options.draw_structure = true;
        const render::Image with = renderer.render(world, structureCamera(), options);
        int changed = 0;
        int meaningful_pixels = 0;
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                const Rgb b = pixelAt(with, x, y);
                if (pixelAt(without, x, y) == b) continue;
                ++changed;
                for (const Rgb& meaningful : meaningfulColors()) {
                    meaningful_pixels += close(b, meaningful, 40);
                }
            }
        }
        EXPECT_GE(changed, 20);
        EXPECT_EQ(meaningful_pixels, 0) << "of " << changed << " pixels the structure changed";
    }
}

// Every colour a structure draws in is named in its legend, and the legend shows when the HUD
// is on.
TEST(StructureView, EveryStructureColourIsNamedInALegend) {
    constexpr int kW = 480;
    constexpr int kH = 270;
    render::Renderer renderer(kW, kH);
    for (const std::string& name : kDrawing) {
        SCOPED_TRACE(name);
        const engine::World world = worldWith(name);
        RecordingDraw recorded;
        world.broadPhase().draw(recorded, world.settings().bounds);
        ASSERT_FALSE(recorded.labels.empty()) << "no legend";
        for (const Rgb& c : recorded.colors) {
            EXPECT_NE(std::find(recorded.legend_colors.begin(), recorded.legend_colors.end(), c),
                      recorded.legend_colors.end())
                << "colour " << c[0] << "," << c[1] << "," << c[2] << " is not in the legend";
        }
        for (const std::string& label : recorded.labels) EXPECT_FALSE(label.empty());

        render::FrameOptions options = plainOptions();
        options.draw.bodies = false;
        options.draw.sphere = false;
        options.draw_structure = true;
        const render::Image without_hud = renderer.render(world, structureCamera(), options);
        options.draw.hud = true;
        const render::Image with_hud = renderer.render(world, structureCamera(), options);
        // The HUD adds the legend: a 7 x 7 swatch of each of its colours, a solid square no
        // line (at most 2 pixels wide) makes.
        for (const Rgb& c : recorded.legend_colors) {
            EXPECT_TRUE(hasSolidSquare(with_hud, c, 5)) << c[0] << "," << c[1] << "," << c[2];
            EXPECT_FALSE(hasSolidSquare(without_hud, c, 5));
        }
    }
}

// SAP draws each axis's sorted intervals as a 1-D diagram outside the world bounds: x below the
// front bottom edge, y left of the front left edge, z right of the bottom right edge; every
// proxy's interval at its true coordinates, overlapping intervals in different rows, and the
// intervals of proxies in an active pair (here A and B, overlapping on x, y and z) marked.
//
//          y left of           A B          C
//          this edge -> |  (  )(  )       (  )  | <- z right of this edge, into the screen
//                       +-----------------------+
//                        x intervals below: [A ]  [C ]
//                                             [B ]
TEST(StructureView, SapLaysItsSortedIntervalsAlongTheBoundsEdges) {
    for (const std::string& name : {std::string("sap"), std::string("sap1")}) {
        SCOPED_TRACE(name);
        const engine::World world = worldWith(name);
        const collision::Aabb& bounds = world.settings().bounds;
        RecordingDraw recorded;
        world.broadPhase().draw(recorded, bounds);
        const auto volumes = world.volumes();
        std::vector<bool> in_pair(volumes.size(), false);
        for (const collision::ProxyPair& p : world.flaggedPairs())
            in_pair[p.a] = in_pair[p.b] = true;
        ASSERT_TRUE(in_pair[0] && in_pair[1] && !in_pair[2]);
        const int axes = name == "sap" ? 3 : 1;  // sap1 sorts on x, the axis of greatest spread
        Rgb marked{-1, -1, -1};
        for (int axis = 0; axis < axes; ++axis) {
            Rgb unmarked{-1, -1, -1};  // each axis has its own colour
            std::vector<Real> row_of(volumes.size(), 0);
            for (std::size_t i = 0; i < volumes.size(); ++i) {
                const Real lo = volumes[i].aabb.min[axis];
                const Real hi = volumes[i].aabb.max[axis];
                const RecordingDraw::Segment* found = nullptr;
                for (const RecordingDraw::Segment& s : recorded.segments) {
                    if (s.a[axis] == lo && s.b[axis] == hi) found = &s;
                }
                ASSERT_NE(found, nullptr) << "no interval of body " << i << " on axis " << axis;
                // Outside the box, beside the edge the diagram belongs to.
                const Vec3& a = found->a;
                if (axis == 0) {
                    EXPECT_LT(a.y(), bounds.min.y());
                    EXPECT_EQ(a.z(), bounds.max.z());
                    row_of[i] = a.y();
                } else if (axis == 1) {
                    EXPECT_LT(a.x(), bounds.min.x());
                    EXPECT_EQ(a.z(), bounds.max.z());
                    row_of[i] = a.x();
                } else {
                    EXPECT_GT(a.x(), bounds.max.x());
                    EXPECT_EQ(a.y(), bounds.min.y());
                    row_of[i] = a.x();
                }
                Rgb& expected = in_pair[i] ? marked : unmarked;
                if (expected[0] < 0) expected = found->color;
                EXPECT_EQ(found->color, expected) << "body " << i;
            }
            // A and B overlap on every axis: never in the same row.
            EXPECT_NE(row_of[0], row_of[1]) << "axis " << axis;
            EXPECT_NE(marked, unmarked) << "active intervals are not marked";
        }
        EXPECT_GE(recorded.labels.size(), std::size_t(axes + 1));
    }
}
