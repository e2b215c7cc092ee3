// render/src/font.h -- a built-in 5x7 bitmap font (ASCII 32..126) drawn straight into an Image
// after readback: the HUD and the legend. Private to render/.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "render/image.h"

namespace render::font {

using Rgb = std::array<std::uint8_t, 3>;

inline constexpr int kGlyphWidth = 5;   ///< pixels at scale 1
inline constexpr int kCapHeight = 7;    ///< pixels at scale 1 above the baseline
inline constexpr int kGlyphHeight = 8;  ///< cap height + 1 row for descenders (g j p q y ,)
inline constexpr int kAdvance = 6;      ///< glyph width + 1 column of spacing
inline constexpr int kLineHeight = 10;  ///< glyph height + 2 rows of spacing

/// The 8 rows of a glyph, top first; bit 4 is the leftmost column. Characters outside 32..126
/// map to '?'.
const std::array<std::uint8_t, kGlyphHeight>& glyph(char c);

/// Width in pixels of the longest line of `text` at `scale` (>= 1); '\n' starts a new line.
int textWidth(std::string_view text, int scale);
/// Height in pixels of `text` at `scale`.
int textHeight(std::string_view text, int scale);

/// Draws `text` with its top-left corner at (x, y) (pixels, row 0 at the top), each font pixel
/// a scale x scale square, clipped to the image. With `shadow`, a dark copy offset by `scale`
/// pixels right and down goes underneath so the text reads on any background.
void drawText(Image& image, int x, int y, std::string_view text, int scale, const Rgb& color,
              bool shadow = true);

/// Fills the rectangle [x, x+w) x [y, y+h), clipped to the image.
void fillRect(Image& image, int x, int y, int w, int h, const Rgb& color);
/// Blends `color` over the rectangle with opacity `alpha` in [0, 1], clipped to the image.
void blendRect(Image& image, int x, int y, int w, int h, const Rgb& color, float alpha);

}  // namespace render::font
