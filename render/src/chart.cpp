// render/src/chart.cpp -- horizontal bar charts drawn with the bitmap font (see chart.h).
#include "render/chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "font.h"

namespace render {

namespace {

constexpr font::Rgb kBackground{255, 255, 255};
constexpr font::Rgb kText{20, 20, 20};
constexpr font::Rgb kBar{70, 120, 190};
constexpr font::Rgb kAccent{220, 120, 30};
constexpr font::Rgb kAxis{150, 150, 150};
constexpr int kScale = 2;
constexpr int kMargin = 12;
constexpr int kBarHeight = 22;
constexpr int kBarGap = 8;

std::string formatValue(double v) {
    if (std::isnan(v)) return "n/a";
    char text[32];
    const double a = std::abs(v);
    if (a != 0 && (a >= 1e6 || a < 1e-3)) {
        std::snprintf(text, sizeof text, "%.3g", v);
    } else if (a >= 100 || v == std::floor(v)) {
        std::snprintf(text, sizeof text, "%.0f", v);
    } else {
        std::snprintf(text, sizeof text, "%.3g", v);
    }
    return text;
}

}  // namespace

Image drawBarChart(const BarChart& chart) {
    const int n = static_cast<int>(chart.bars.size());
    const int title_h = font::textHeight(chart.title, kScale);
    int label_w = 0;
    for (const ChartBar& b : chart.bars) {
        label_w = std::max(label_w, font::textWidth(b.label, kScale));
    }
    Image image;
    // Wide enough for the labels, the title and a 400-pixel bar span.
    image.width = std::max({chart.width, label_w + 560,
                            font::textWidth(chart.title, kScale) + 2 * kMargin});
    image.height = kMargin + title_h + kMargin + std::max(n, 1) * (kBarHeight + kBarGap) + kMargin;
    image.rgb.assign(std::size_t(image.width) * image.height * 3, 0);
    font::fillRect(image, 0, 0, image.width, image.height, kBackground);
    font::drawText(image, kMargin, kMargin, chart.title, kScale, kText, false);

    double largest = 0;
    double smallest = 0;  // smallest positive
    for (const ChartBar& b : chart.bars) {
        if (std::isfinite(b.value) && b.value > 0) {
            largest = std::max(largest, b.value);
            smallest = smallest == 0 ? b.value : std::min(smallest, b.value);
        }
    }
    const int value_w = font::textWidth("-0.000e+00", kScale);
    const int x0 = kMargin + label_w + kMargin;
    const int span = std::max(image.width - x0 - kMargin - value_w - kMargin, 10);
    const int top = kMargin + title_h + kMargin;
    font::fillRect(image, x0 - 1, top - kBarGap / 2, 1, n * (kBarHeight + kBarGap), kAxis);
    for (int i = 0; i < n; ++i) {
        const ChartBar& b = chart.bars[static_cast<std::size_t>(i)];
        const int y = top + i * (kBarHeight + kBarGap);
        double fraction = 0;
        if (std::isfinite(b.value) && b.value > 0 && largest > 0) {
            fraction = chart.log_scale
                           ? (std::log10(b.value / smallest) + 1) /
                                 (std::log10(largest / smallest) + 1)
                           : b.value / largest;
        }
        const int w = static_cast<int>(std::lround(fraction * span));
        font::fillRect(image, x0, y, w, kBarHeight, b.highlight ? kAccent : kBar);
        const int text_y = y + (kBarHeight - font::textHeight("0", kScale)) / 2;
        font::drawText(image, kMargin, text_y, b.label, kScale, kText, false);
        font::drawText(image, x0 + w + kMargin / 2, text_y, formatValue(b.value), kScale, kText,
                       false);
    }
    return image;
}

}  // namespace render
