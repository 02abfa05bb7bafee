// The HUD's bitmap font: glyph placement, scale, clipping and the backdrop.
#include "viewer/hud_text.h"

#include <gtest/gtest.h>

#include <vector>

namespace pl {
namespace {

struct Buffer {
  int width, height;
  std::vector<uint32_t> pixels;
  Buffer(int w, int h, uint32_t fill = 0xFF000000u) : width(w), height(h), pixels(size_t(w) * size_t(h), fill) {}
  uint32_t at(int x, int y) const { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
  int count(uint32_t colour) const {
    int n = 0;
    for (uint32_t p : pixels) n += p == colour;
    return n;
  }
};

TEST(HudText, DrawsGlyphsAtScale) {
  Buffer b(40, 20);
  drawHudText(b.pixels.data(), b.width * 4, b.width, b.height, 0, 0, "1", 1, 0xFFFFFFFFu);
  // '1' has 1 + 2 + 1 + 1 + 1 + 1 + 3 = 10 lit dots (rows 0x04,0x0C,0x04,0x04,0x04,0x04,0x0E).
  EXPECT_EQ(b.count(0xFFFFFFFFu), 10);
  EXPECT_EQ(b.at(2, 0), 0xFFFFFFFFu);  // top of the stem, column 2
  Buffer big(40, 20);
  drawHudText(big.pixels.data(), big.width * 4, big.width, big.height, 0, 0, "1", 2, 0xFFFFFFFFu);
  EXPECT_EQ(big.count(0xFFFFFFFFu), 10 * 4);  // each dot a 2×2 square
  EXPECT_EQ(hudTextWidth("12", 1), 11);        // 2 glyphs × 6 − 1 spacing column
  EXPECT_EQ(hudTextWidth("12", 3), 33);
  // Lower case is drawn as upper case; unknown characters as '?'.
  Buffer lower(10, 10), upper(10, 10), unknown(10, 10), question(10, 10);
  drawHudText(lower.pixels.data(), 40, 10, 10, 0, 0, "f", 1, 0xFFFFFFFFu);
  drawHudText(upper.pixels.data(), 40, 10, 10, 0, 0, "F", 1, 0xFFFFFFFFu);
  drawHudText(unknown.pixels.data(), 40, 10, 10, 0, 0, "@", 1, 0xFFFFFFFFu);
  drawHudText(question.pixels.data(), 40, 10, 10, 0, 0, "?", 1, 0xFFFFFFFFu);
  EXPECT_EQ(lower.pixels, upper.pixels);
  EXPECT_EQ(unknown.pixels, question.pixels);
}

TEST(HudText, ClipsAtTheBufferEdges) {
  Buffer b(8, 4);  // smaller than one scaled glyph
  drawHudText(b.pixels.data(), b.width * 4, b.width, b.height, -3, -2, "88888", 3, 0xFFFFFFFFu);
  EXPECT_GT(b.count(0xFFFFFFFFu), 0);  // drew what fits, no out-of-bounds writes (ASan/valgrind clean)
}

}  // namespace
}  // namespace pl
