// render/src/overlay.cpp -- what is written over the read-back pixels: the state legend, the
// broad phase's structure legend and the HUD text (hudLine).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "font.h"
#include "renderer_impl.h"

namespace render {

using collision::Color;

void Renderer::Impl::drawLabels(Image& image, const engine::World& world,
                                const engine::CameraSettings& camera,
                                const FrameOptions& options) const {
    const int scale = height >= 1440 ? 2 : 1;
    const font::Rgb label_color{236, 238, 242};
    const font::Rgb selected_color{255, 255, 255};
    const auto volumes = world.volumes();
    const auto bodies = world.bodies();
    for (std::size_t i = 0; i < volumes.size() && i < bodies.size(); ++i) {
        const bool selected = options.selected && std::size_t(*options.selected) == i;
        if (!options.draw.labels && !selected) continue;
        const std::optional<ScreenRect> rect =
            screenRect(camera, width, height, volumes[i].aabb.min, volumes[i].aabb.max);
        if (!rect) continue;
        const int s = selected ? scale + 1 : scale;
        const std::string& name = bodies[i].name;
        const int w = font::textWidth(name, s);
        const int x = int(std::lround(0.5 * (rect->x0 + rect->x1))) - w / 2;
        const int y = std::max(0, int(std::lround(rect->y0)) - font::textHeight(name, s) - 2 * s);
        font::drawText(image, x, y, name, s, selected ? selected_color : label_color);
    }
}

void Renderer::Impl::drawOverlays(Image& image, const FrameOptions& options) const {
    // Text is pixel art: integer scale, 2x from 720p, 3x from 1440p.
    const int scale = height >= 1440 ? 3 : height >= 720 ? 2 : 1;
    const int margin = 6 * scale;
    const font::Rgb text_color{236, 238, 242};
    const font::Rgb plate{0, 0, 0};
    const int pad = 3 * scale;
    if (!options.hud_text.empty()) {
        const int w = font::textWidth(options.hud_text, scale);
        const int h = font::textHeight(options.hud_text, scale);
        font::blendRect(image, margin - pad, margin - pad, w + 2 * pad + scale, h + 2 * pad + scale,
                        plate, 0.45f);
        font::drawText(image, margin, margin, options.hud_text, scale, text_color);
    }
    if (!options.draw.hud) return;
    // Legends: the state colours bottom-left, what the structure's colours show top-right.
    const bool any_volume = options.draw.sphere || options.draw.aabb || options.draw.obb ||
                            std::find(options.draw.kdop.begin(), options.draw.kdop.end(), true) !=
                                options.draw.kdop.end();
    if (any_volume || options.draw.bvh_depth >= 0) {
        const Color apart = engine::stateColor(engine::BodyState::Apart);
        const Color flagged = engine::stateColor(engine::BodyState::Flagged);
        const Color colliding = engine::stateColor(engine::BodyState::Colliding);
        std::vector<LegendRow> rows;
        if (any_volume && drawn.own_tests) {
            rows.push_back({{std::nullopt, "each volume coloured by its own overlap test"}});
            std::string names;
            for (const std::string& name : engine::drawnVolumeNames(options.draw)) {
                names += (names.empty() ? "drawn: " : ", ") + name;
            }
            rows.push_back({{std::nullopt, names}});
            rows.push_back({{apart, "apart"},
                            {flagged, "overlaps a volume of its kind"},
                            {colliding, "colliding"}});
        } else {
            std::string flagged_label = "flagged";
            if (any_volume && drawn.tested_volume) {
                const char* const names[3] = {"sphere", "AABB", "OBB"};
                flagged_label += " (" + std::string(names[int(*drawn.tested_volume)]) + " test)";
            }
            rows.push_back({{apart, "apart"}, {flagged, flagged_label}, {colliding, "colliding"}});
        }
        drawLegendBlock(image, margin, height - margin - legendBlockSize(rows, scale).height, rows,
                        scale);
    }
    if (!lines.structure_legend.empty()) {
        std::vector<LegendRow> rows;
        for (const LegendEntry& e : lines.structure_legend) rows.push_back({{e.color, e.label}});
        // Right-aligned; a block wider than the frame starts at the left margin instead, so its
        // swatches stay on screen and only the ends of its longest lines are cut.
        const int left = std::max(margin, width - margin - legendBlockSize(rows, scale).width);
        drawLegendBlock(image, left, margin, rows, scale);
    }
}

std::string hudLine(const engine::World& world, int frame, bool include_timing) {
    // Line 1: where we are and what the phases found. Line 2: the cost model's counters
    // (F = Nv Cv + Np Cp + Nu Cu) and, with timing, the time per stage.
    const engine::StepStats& st = world.lastStats();
    const std::string_view bp = world.broadPhase().name();
    char buffer[512];
    int n = std::snprintf(
        buffer, sizeof buffer,
        "frame %d  t=%.3f s  %.*s  flagged %zu  colliding %zu\n"
        "BV tests %lld  updated %lld  narrow tests %lld  triangle tests %lld",
        frame, double(world.time()), int(bp.size()), bp.data(), world.flaggedPairs().size(),
        world.collidingPairs().size(), static_cast<long long>(st.broad.volume_tests),
        static_cast<long long>(st.broad.volumes_updated), static_cast<long long>(st.narrow_tests),
        static_cast<long long>(st.triangle_tests));
    std::string line(buffer, std::size_t(std::clamp(n, 0, int(sizeof buffer) - 1)));
    // Only in scenes that have them: self-collision and deforming mesh bodies.
    bool self = false;
    for (const engine::Body& b : world.bodies()) self = self || b.self_collision;
    if (self) line += "  self pairs " + std::to_string(st.self_pairs);
    if (st.refit_nodes > 0) line += "  refit nodes " + std::to_string(st.refit_nodes);
    // Scenes with chains: the continuous stage's queries and events, and where a chain halted.
    if (!world.chains().empty()) {
        line += "\ntoi queries " + std::to_string(st.toi_queries) + "  iterations " +
                std::to_string(st.toi_iterations) + "  events " + std::to_string(st.toi_events);
        for (std::size_t c = 0; c < world.chains().size(); ++c) {
            if (!world.chainHalted(c)) continue;
            n = std::snprintf(buffer, sizeof buffer, "  %s halted at %.5f s",
                              world.chains()[c].name.c_str(), double(world.chainTime(c)));
            line.append(buffer, std::size_t(std::clamp(n, 0, int(sizeof buffer) - 1)));
        }
    }
    if (include_timing) {
        n = std::snprintf(
            buffer, sizeof buffer, "\nstep %.3f ms  volumes %.3f  broad %.3f  narrow %.3f ms",
            1e3 * st.total_s, 1e3 * st.volumes_s, 1e3 * st.broad_phase_s, 1e3 * st.narrow_phase_s);
        line.append(buffer, std::size_t(std::clamp(n, 0, int(sizeof buffer) - 1)));
    }
    return line;
}

}  // namespace render
