// render/src/legend.cpp -- see legend.h.
#include "legend.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "font.h"

namespace render {

namespace {

font::Rgb toRgb8(const collision::Color& c) {
    auto channel = [](float v) {
        return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
    };
    return {channel(c.r), channel(c.g), channel(c.b)};
}

}  // namespace

BlockSize legendBlockSize(const std::vector<LegendRow>& rows, int scale) {
    const int swatch = font::kCapHeight * scale;
    const int gap = 4 * scale;
    BlockSize size;
    for (const LegendRow& row : rows) {
        int w = 0;
        for (const LegendItem& item : row) {
            w += (item.swatch ? swatch + gap : 0) + font::textWidth(item.label, scale) + 3 * gap;
        }
        size.width = std::max(size.width, w - 3 * gap);
    }
    const int row_height = font::kLineHeight * scale;
    size.height = rows.empty() ? 0 : int(rows.size()) * row_height - (row_height - swatch);
    return size;
}

void drawLegendBlock(Image& image, int left, int top, const std::vector<LegendRow>& rows,
                     int scale) {
    const font::Rgb text_color{236, 238, 242};
    const int swatch = font::kCapHeight * scale;
    const int gap = 4 * scale;
    const int pad = 3 * scale;
    const BlockSize size = legendBlockSize(rows, scale);
    font::blendRect(image, left - pad, top - pad, size.width + 2 * pad + scale,
                    size.height + 2 * pad + scale, {0, 0, 0}, 0.45f);
    int y = top;
    for (const LegendRow& row : rows) {
        int x = left;
        for (const LegendItem& item : row) {
            if (item.swatch) {
                font::fillRect(image, x + scale, y + scale, swatch, swatch, {12, 12, 16});
                font::fillRect(image, x, y, swatch, swatch, toRgb8(*item.swatch));
                x += swatch + gap;
            }
            font::drawText(image, x, y, item.label, scale, text_color);
            x += font::textWidth(item.label, scale) + 3 * gap;
        }
        y += font::kLineHeight * scale;
    }
}

}  // namespace render
