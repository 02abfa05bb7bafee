#pragma once
// A tiny built-in bitmap font for the viewer's HUD (no font files, no extra library):
// 5×7-pixel glyphs for digits, upper-case letters (lower case is drawn upper case) and
// " .,:;-+/=()%[]_<>*#'", drawn into a 32-bit 0xAARRGGBB frame buffer. Unknown characters
// are drawn as '?'.
#include <cstdint>
#include <string>

namespace pl {

inline constexpr int kGlyphWidth = 5, kGlyphHeight = 7, kGlyphAdvance = 6, kLineAdvance = 9;

/// Width in pixels of `text` drawn at `scale` (one line).
int hudTextWidth(const std::string& text, int scale);

/// Draws one line of text with its top-left at (x, y), each font pixel a scale×scale
/// square, clipped to the buffer.
void drawHudText(uint32_t* pixels, int pitchBytes, int width, int height, int x, int y, const std::string& text,
                 int scale, uint32_t color);

}  // namespace pl
