// render/chart.h -- horizontal bar charts as pictures, for the reports of `cdlab sweep`.
// Software only (no GL): bars, labels and values drawn with the built-in bitmap font.
#pragma once

#include <string>
#include <vector>

#include "render/image.h"

namespace render {

/// One bar: its label (left of the bar) and value (>= 0 drawn as a bar; printed beside it).
struct ChartBar {
    std::string label;
    double value = 0;
    bool highlight = false;  ///< drawn in the accent colour (e.g. the reference run)
};

/// A horizontal bar chart; bars keep their order, top to bottom.
struct BarChart {
    std::string title;           ///< printed above the bars, with the unit
    std::vector<ChartBar> bars;
    int width = 900;             ///< pixels, at least; widened to fit the labels
    /// Bars are proportional to value / (largest value); with log_scale, to
    /// log10(value / smallest positive value) + 1 (every positive value gets a visible bar).
    bool log_scale = false;
};

/// Draws `chart`: white background, one bar per entry, each value printed at its bar's end
/// ("n/a" for NaN, negative values drawn as zero-length bars and printed as they are).
/// Height follows from the bar count. Deterministic: the same chart gives the same pixels.
Image drawBarChart(const BarChart& chart);

}  // namespace render
