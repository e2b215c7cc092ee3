// Bar charts for sweep reports: bars proportional to their values, reference highlighted,
// log scale keeps small values visible, deterministic pixels.
#include <gtest/gtest.h>

#include <cmath>

#include "render/chart.h"

namespace {

// Length in pixels of the longest horizontal run of the colour (r, g, b): the bar drawn in it.
int barLength(const render::Image& image, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    int best = 0;
    for (int y = 0; y < image.height; ++y) {
        int run = 0;
        for (int x = 0; x < image.width; ++x) {
            const std::uint8_t* p = image.pixel(x, y);
            run = (p[0] == r && p[1] == g && p[2] == b) ? run + 1 : 0;
            best = std::max(best, run);
        }
    }
    return best;
}

TEST(BarChart, BarsAreProportionalAndTheHighlightUsesTheAccent) {
    render::BarChart one;
    one.title = "t";
    one.bars = {{"a", 10.0, false}};
    render::BarChart half = one;
    half.bars = {{"a", 10.0, true}, {"b", 5.0, false}};
    const render::Image full = render::drawBarChart(one);
    const render::Image two = render::drawBarChart(half);
    EXPECT_EQ(full.width, two.width);
    EXPECT_GT(two.height, full.height);
    const int blue_full = barLength(full, 70, 120, 190);
    const int orange = barLength(two, 220, 120, 30);
    const int blue_half = barLength(two, 70, 120, 190);
    EXPECT_GT(blue_full, 300);
    EXPECT_EQ(orange, blue_full);                      // the largest value spans the axis
    EXPECT_NEAR(blue_half, blue_full / 2.0, 1.0);      // half the value, half the length
    EXPECT_EQ(render::drawBarChart(half).rgb, two.rgb);  // deterministic
}

TEST(BarChart, LogScaleKeepsTinyValuesVisibleAndNanIsNoBar) {
    render::BarChart c;
    c.title = "drift";
    c.log_scale = true;
    c.bars = {{"tiny", 1e-12, false}};
    const int alone = barLength(render::drawBarChart(c), 70, 120, 190);
    c.bars = {{"tiny", 1e-12, false}, {"big", 1e-2, true}};
    const render::Image img = render::drawBarChart(c);
    const int big = barLength(img, 220, 120, 30);
    const int tiny = barLength(img, 70, 120, 190);
    EXPECT_GT(tiny, 0);
    // log10(1e10) + 1 = 11 units for the big bar, 1 for the tiny one.
    EXPECT_NEAR(double(tiny) / big, 1.0 / 11.0, 0.01);
    EXPECT_EQ(alone, big);
    c.bars = {{"nan", std::nan(""), false}};
    EXPECT_EQ(barLength(render::drawBarChart(c), 70, 120, 190), 0);
}

}  // namespace
