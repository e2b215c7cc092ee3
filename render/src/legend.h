// render/src/legend.h -- legend blocks drawn into a frame after readback: rows of colour swatches
// and labels on a translucent plate (the state colours, the structure's colours). Private to
// render.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "collision/debug_draw.h"
#include "render/image.h"

namespace render {

/// One item of a legend row: a swatch (when `swatch`) and its label.
struct LegendItem {
    std::optional<collision::Color> swatch;
    std::string label;
};
/// Items side by side.
using LegendRow = std::vector<LegendItem>;

/// Width and height in pixels of a legend block's rows (without the plate's padding).
struct BlockSize {
    int width = 0;
    int height = 0;
};

/// The size `rows` take at text scale `scale` (>= 1).
BlockSize legendBlockSize(const std::vector<LegendRow>& rows, int scale);

/// Draws `rows` top to bottom from (left, top) on one translucent plate, clipped to the image.
void drawLegendBlock(Image& image, int left, int top, const std::vector<LegendRow>& rows,
                     int scale);

}  // namespace render
