#pragma once
// Test support (header-only; include as "support/random_texture.h"): textures of random
// texels for scenes built in code (the renderers' texture tests).
#include <string>

#include "core/rng.h"
#include "scene/texture.h"

namespace pl::test_support {

/// A width × height colour texture of random texels: 8-bit values (k/255, so finish() packs
/// it) when eightBit, else any floats in [0, 1) (its levels stay float rows).
inline Texture randomTexture(int width, int height, bool eightBit, uint64_t seed) {
  Texture texture;
  texture.path = eightBit ? "random-8-bit" : "random-float";
  texture.image = Image(width, height);
  Pcg32 rng(seed, 1);
  auto value = [&] { return eightBit ? float(rng.next() >> 24) / 255.0f : rng.uniform(); };
  for (Rgb& texel : texture.image.pixels) {
    const float r = value(), g = value(), b = value();
    texel = Rgb(r, g, b);
  }
  return texture;
}

}  // namespace pl::test_support
