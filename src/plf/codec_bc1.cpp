// libsquish behind one file (see codec_backends.h).
#include <squish.h>

#include "plf/codec_backends.h"

namespace pl::detail {

namespace {
// A null metric is libsquish's uniform weight {1, 1, 1}.
constexpr int kFlags = squish::kDxt1 | squish::kColourIterativeClusterFit;
}

void bc1EncodeBlock(const unsigned char (&rgb)[16][3], int validMask, unsigned char* block) {
  squish::u8 rgba[16 * 4];
  for (int i = 0; i < 16; ++i) {
    rgba[4 * i + 0] = rgb[i][0];
    rgba[4 * i + 1] = rgb[i][1];
    rgba[4 * i + 2] = rgb[i][2];
    rgba[4 * i + 3] = 255;  // opaque: BC1's 3-colour mode may still be chosen, never transparency
  }
  squish::CompressMasked(rgba, validMask, block, kFlags, nullptr);
}

void bc1DecodeBlock(const unsigned char* block, unsigned char (&rgb)[16][3]) {
  squish::u8 rgba[16 * 4];
  squish::Decompress(rgba, block, kFlags);
  for (int i = 0; i < 16; ++i)
    for (int c = 0; c < 3; ++c) rgb[i][c] = rgba[4 * i + c];
}

}  // namespace pl::detail
