#pragma once
// Test support (header-only; include as "support/mask_texture.h"): alpha-mask textures for
// scenes built in code (the masked-shadow tests of the path tracer and the bake).
#include "image/image.h"
#include "scene/scene.h"

namespace pl::test_support {

/// A 1×4 coverage texture whose top half (v ≥ 0.5, the rows of large v) is opaque (1) and
/// bottom half cut away (0): with uv over [0,1]² a masked quad keeps half of its area.
inline Texture halfMaskTexture() {
  Texture mask;
  mask.path = "half mask";
  mask.decode = ImageDecode::Coverage;
  mask.image = Image(1, 4);
  mask.image.pixels = {Rgb(1.0f), Rgb(1.0f), Rgb(0.0f), Rgb(0.0f)};
  return mask;
}

}  // namespace pl::test_support
