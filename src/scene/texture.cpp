// Textures: packing, mip levels, sampling (see texture.h).
#include "scene/texture.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "core/error.h"

namespace pl {

namespace {

/// The blocks per row of a texture packed in 4×4-texel blocks, and the place of texel (x, y).
int packedBlocksPerRow(int width) { return (width + 3) / 4; }
template <typename Blocks>  // const or not
auto& packedTexel(Blocks& blocks, int blocksPerRow, int x, int y) {
  return blocks[size_t(y >> 2) * size_t(blocksPerRow) + size_t(x >> 2)].texels[(y & 3) * 4 + (x & 3)];
}

/// Texture::packed and palette for `image`, or false (nothing changed) when its channels take
/// more than 256 distinct values. The distinct values go through a small open-addressing hash
/// table keyed by their bits (−0 and +0 stay distinct, so the palette gives back every bit).
bool packTexels(const Image& image, std::vector<Texture::PackedBlock>& packed, std::vector<float>& palette) {
  constexpr uint32_t kSlots = 1024, kEmpty = 0xffffffffu;  // kEmpty: a NaN pattern, never a finite texel
  std::vector<uint32_t> keys(kSlots, kEmpty);
  std::vector<uint8_t> indices(kSlots, 0);
  std::vector<float> values;
  auto indexOf = [&](float v, uint32_t& index) {
    const uint32_t bits = std::bit_cast<uint32_t>(v);
    for (uint32_t slot = (bits * 2654435761u) >> 22;; slot = (slot + 1) & (kSlots - 1)) {
      if (keys[slot] == bits) return index = indices[slot], true;
      if (keys[slot] != kEmpty) continue;
      if (values.size() == 256) return false;
      keys[slot] = bits;
      indices[slot] = uint8_t(values.size());
      index = uint32_t(values.size());
      values.push_back(v);
      return true;
    }
  };
  const int blocksPerRow = packedBlocksPerRow(image.width);
  std::vector<Texture::PackedBlock> blocks(size_t(blocksPerRow) * size_t((image.height + 3) / 4), Texture::PackedBlock{});
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Rgb& texel = image.at(x, y);
      uint32_t r, g, b;
      if (!indexOf(texel.r, r) || !indexOf(texel.g, g) || !indexOf(texel.b, b)) return false;
      packedTexel(blocks, blocksPerRow, x, y) = r | g << 8 | b << 16;
    }
  packed = std::move(blocks);
  palette = std::move(values);
  return true;
}

}  // namespace

namespace {

/// The 2×2 texels sample(uv) blends and their weights, or false for a non-finite uv.
struct BilinearFootprint {
  int x0, x1, y0, y1;
  float fx, fy;
};
/// Wrap-around (repeat) of texel index i (a whole number) with a non-negative modulo. Below
/// 2^30 in magnitude the integer remainder is exactly fmod's (and much cheaper per pixel);
/// fmod keeps huge coordinates in range.
int repeatIndex(float i, int n) {
  // Most lookups are inside the image (uv in [0, 1)): no division at all (an integer
  // remainder costs tens of cycles, four per footprint).
  if (i >= 0.0f && i < float(n)) return int(i);
  if (std::abs(i) < 0x1p30f) {
    const int k = int(i) % n;
    return k < 0 ? k + n : k;
  }
  float m = std::fmod(i, float(n));
  if (m < 0.0f) m += float(n);
  int k = int(m);
  return k >= n ? 0 : k;
}

bool bilinearFootprint(const Image& image, Vec2 uv, BilinearFootprint& f) {
  // Texel (x, y) has its centre at u = (x + 0.5)/W and v = 1 − (y + 0.5)/H (row 0 is the top
  // of the image, v = 0 its bottom). Continuous texel coordinates of uv:
  const float x = uv.x * float(image.width) - 0.5f;
  const float y = (1.0f - uv.y) * float(image.height) - 0.5f;
  if (!std::isfinite(x) || !std::isfinite(y)) return false;
  const float x0f = std::floor(x), y0f = std::floor(y);
  f.fx = x - x0f;
  f.fy = y - y0f;
  f.x0 = repeatIndex(x0f, image.width), f.x1 = repeatIndex(x0f + 1.0f, image.width);
  f.y0 = repeatIndex(y0f, image.height), f.y1 = repeatIndex(y0f + 1.0f, image.height);
  return true;
}

/// Texel index i (a whole number) of an axis of n texels wrapped as `wrap` says (TextureWrap).
int wrapIndex(float i, int n, TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::ClampToEdge: return i <= 0.0f ? 0 : i >= float(n - 1) ? n - 1 : int(i);
    case TextureWrap::MirroredRepeat: {
      const int m = repeatIndex(i, 2 * n);
      return m < n ? m : 2 * n - 1 - m;
    }
    case TextureWrap::Repeat: break;
  }
  return repeatIndex(i, n);
}

/// bilinearFootprint under a texture's own sampling (TextureSampling): its wrap modes, and
/// with `nearest` the one texel the uv falls in (weights 0, both indices equal, so the bilinear
/// blend returns that texel exactly). False for a non-finite uv.
bool sampledFootprint(const Image& image, Vec2 uv, TextureWrap wrapU, TextureWrap wrapV, bool nearest,
                      BilinearFootprint& f) {
  // As bilinearFootprint; nearest: the texel [x, x + 1) × [y, y + 1) holding the point.
  const float half = nearest ? 0.0f : 0.5f;
  const float x = uv.x * float(image.width) - half;
  const float y = (1.0f - uv.y) * float(image.height) - half;
  if (!std::isfinite(x) || !std::isfinite(y)) return false;
  const float x0f = std::floor(x), y0f = std::floor(y);
  f.fx = nearest ? 0.0f : x - x0f;
  f.fy = nearest ? 0.0f : y - y0f;
  const float step = nearest ? 0.0f : 1.0f;
  f.x0 = wrapIndex(x0f, image.width, wrapU), f.x1 = wrapIndex(x0f + step, image.width, wrapU);
  f.y0 = wrapIndex(y0f, image.height, wrapV), f.y1 = wrapIndex(y0f + step, image.height, wrapV);
  return true;
}

}  // namespace

namespace {

/// bilinearFootprint for a uv already reduced to [0, 1)² (Texture::sampleLod): the texel
/// coordinate x = u·W − ½ lies in [−½, W − ½), so ⌊x⌋ ∈ [−1, W − 1] is the truncation of x + 1
/// minus 1, and the wrap is one comparison per index — no floor, no division. Always true
/// (a NaN uv was sent to sample() before).
bool reducedFootprint(const Image& image, Vec2 uv, BilinearFootprint& f) {
  auto axis = [](float x, int n, int& i0, int& i1, float& fraction) {
    const int below = int(x + 1.0f) - 1;  // ⌊x⌋ for x ≥ −1
    fraction = x - float(below);
    i0 = below < 0 ? n - 1 : below;
    i1 = below + 1 >= n ? 0 : below + 1;
  };
  axis(uv.x * float(image.width) - 0.5f, image.width, f.x0, f.x1, f.fx);
  axis((1.0f - uv.y) * float(image.height) - 0.5f, image.height, f.y0, f.y1, f.fy);
  return true;
}

/// The two footprints as function objects of their own types, so that sampleLevel and
/// prefetchLevel inline them (passed as plain functions they were called through a pointer:
/// perf showed the call and reducedFootprint itself at 6 % of a Sponza walk-through frame).
constexpr auto kBilinearFootprint = [](const Image& image, Vec2 uv, BilinearFootprint& f) {
  return bilinearFootprint(image, uv, f);
};
constexpr auto kReducedFootprint = [](const Image& image, Vec2 uv, BilinearFootprint& f) {
  return reducedFootprint(image, uv, f);
};

/// Bilinear, repeat, in one level (its float image, and its packed texels when present), the
/// footprint from `footprint` (kBilinearFootprint or kReducedFootprint); false for a non-finite uv.
template <typename Footprint>
bool sampleLevel(const Image& image, const std::vector<Texture::PackedBlock>& packed, const std::vector<float>& palette,
                 Vec2 uv, Footprint&& footprint, Rgb& result) {
  BilinearFootprint f;
  if (!footprint(image, uv, f)) return false;
  auto bilinear = [&](auto&& texel) {
    const Rgb top = (1.0f - f.fx) * texel(f.x0, f.y0) + f.fx * texel(f.x1, f.y0);
    const Rgb bottom = (1.0f - f.fx) * texel(f.x0, f.y1) + f.fx * texel(f.x1, f.y1);
    return (1.0f - f.fy) * top + f.fy * bottom;
  };
  if (packed.empty()) {
    result = bilinear([&](int tx, int ty) { return image.at(tx, ty); });
    return true;
  }
  const int blocksPerRow = packedBlocksPerRow(image.width);
  const float* values = palette.data();
  result = bilinear([&](int tx, int ty) {
    const uint32_t p = packedTexel(packed, blocksPerRow, tx, ty);
    return Rgb(values[p & 0xffu], values[(p >> 8) & 0xffu], values[(p >> 16) & 0xffu]);
  });
  return true;
}

template <typename Footprint>
void prefetchLevel(const Image& image, const std::vector<Texture::PackedBlock>& packed, Vec2 uv, Footprint&& footprint) {
  BilinearFootprint f;
  if (!footprint(image, uv, f)) return;
  if (packed.empty()) {
    __builtin_prefetch(&image.at(f.x0, f.y0));
    __builtin_prefetch(&image.at(f.x1, f.y1));
    return;
  }
  // Two opposite corners: all the blocks of a footprint that spans one or two (most of them),
  // two of the four at a block corner.
  const int blocksPerRow = packedBlocksPerRow(image.width);
  __builtin_prefetch(&packedTexel(packed, blocksPerRow, f.x0, f.y0));
  __builtin_prefetch(&packedTexel(packed, blocksPerRow, f.x1, f.y1));
}

/// The source texels under each texel of one axis shrunk from n to m ≤ n texels, with their
/// weights: target texel i covers source [i·n/m, (i+1)·n/m), and source texel j gets the
/// length of [j, j+1) inside it divided by n/m (the weights of a target texel sum to 1).
struct BoxTap {
  int source;
  double weight;
};
std::vector<std::vector<BoxTap>> boxTaps(int n, int m) {
  std::vector<std::vector<BoxTap>> taps(size_t(m), std::vector<BoxTap>{});
  const double scale = double(n) / double(m);
  for (int i = 0; i < m; ++i) {
    // Exact in doubles for the sizes of images: i·n and (i+1)·n are integers, divided once.
    const double lo = double(i) * double(n) / double(m), hi = double(i + 1) * double(n) / double(m);
    for (int j = int(std::floor(lo)); j < n && double(j) < hi; ++j) {
      const double overlap = std::min(hi, double(j + 1)) - std::max(lo, double(j));
      if (overlap > 0.0) taps[size_t(i)].push_back({j, overlap / scale});
    }
  }
  return taps;
}

/// The next mip level of `image`: max(1, ⌊W/2⌋) × max(1, ⌊H/2⌋) exact box averages (Texture::mips).
Image downsampleBox(const Image& image) {
  const int width = std::max(1, image.width / 2), height = std::max(1, image.height / 2);
  const auto tapsX = boxTaps(image.width, width), tapsY = boxTaps(image.height, height);
  Image next(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      glm::dvec3 sum(0.0);
      for (const BoxTap& ty : tapsY[size_t(y)])
        for (const BoxTap& tx : tapsX[size_t(x)]) sum += (ty.weight * tx.weight) * glm::dvec3(image.at(tx.source, ty.source));
      next.at(x, y) = Rgb(sum);
    }
  }
  return next;
}

}  // namespace

Rgb Texture::sample(Vec2 uv) const {
  if (image.empty()) return Rgb(1.0f);
  Rgb result;
  if (!sampling.isDefault()) {
    const auto footprint = [&](const Image& level, Vec2 at, BilinearFootprint& f) {
      return sampledFootprint(level, at, sampling.wrapU, sampling.wrapV, sampling.nearest, f);
    };
    return sampleLevel(image, packed, palette, uv, footprint, result) ? result : average;
  }
  return sampleLevel(image, packed, palette, uv, kBilinearFootprint, result) ? result : average;
}

Rgb Texture::maxOver(Vec2 lo, Vec2 hi) const {
  if (image.empty()) return Rgb(1.0f);
  // The continuous texel coordinates of the corners (sampledFootprint's, v flipped), widened
  // by one texel on each side: that covers both the bilinear and the nearest footprints.
  // Spans wider than the image, and coordinates too large to step through by 1 (or not
  // finite: sample() then reads `average`), take the whole axis.
  const float x0 = std::floor(lo.x * float(image.width)) - 1.0f, x1 = std::floor(hi.x * float(image.width)) + 1.0f;
  const float y0 = std::floor((1.0f - hi.y) * float(image.height)) - 1.0f,
              y1 = std::floor((1.0f - lo.y) * float(image.height)) + 1.0f;
  auto indices = [](float first, float last, int n, TextureWrap wrap) {
    std::vector<int> out;
    if (!(last - first < float(n) && std::abs(first) < 0x1p24f && std::abs(last) < 0x1p24f)) {
      for (int i = 0; i < n; ++i) out.push_back(i);
      return out;
    }
    for (float i = first; i <= last; i += 1.0f) out.push_back(wrapIndex(i, n, wrap));
    return out;
  };
  Rgb result(0.0f);
  const std::vector<int> xs = indices(x0, x1, image.width, sampling.wrapU);
  for (const int y : indices(y0, y1, image.height, sampling.wrapV))
    for (const int x : xs) result = glm::max(result, image.at(x, y));
  return result;
}

Rgb Texture::sampleLod(Vec2 uv, float lod) const {
  if (!(lod > 0.0f) || mips.empty() || !sampling.mipmaps) return sample(uv);  // also NaN
  if (!sampling.isDefault()) {
    // Wrapped per level, bilinear in each (`nearest` is the magnification filter: level 0 read
    // alone, by sample()); the same blend of two levels as below.
    const auto footprint = [&](const Image& level, Vec2 at, BilinearFootprint& f) {
      return sampledFootprint(level, at, sampling.wrapU, sampling.wrapV, false, f);
    };
    const float clamped = std::min(lod, float(mips.size()));
    const size_t fine = size_t(clamped);
    const float f = clamped - float(fine);
    auto level = [&](size_t l, Rgb& out) {
      return l == 0 ? sampleLevel(image, packed, palette, uv, footprint, out)
                    : sampleLevel(mips[l - 1].image, mips[l - 1].packed, mips[l - 1].palette, uv, footprint, out);
    };
    Rgb a, b;
    if (!level(fine, a)) return average;
    if (f == 0.0f) return a;
    level(fine + 1, b);
    return (1.0f - f) * a + f * b;
  }
  // uv reduced to [0, 1) once for both levels (repeat), so that each level's footprint is
  // reducedFootprint's few integer operations (per pixel the renderers take four footprints:
  // two levels, sampled and prefetched). Not bit-identical to sample() at level 0 (the
  // rounding of u·W differs), which is why lod ≤ 0 goes through sample().
  uv -= glm::floor(uv);
  if (!(uv.x < 1.0f)) uv.x = 0.0f;  // u − ⌊u⌋ rounds up to 1 for tiny negative u
  if (!(uv.y < 1.0f)) uv.y = 0.0f;
  const size_t coarsest = mips.size();                   // level index of mips.back()
  const float clamped = std::min(lod, float(coarsest));
  const size_t fine = size_t(clamped);  // ⌊lod⌋ ≥ 0
  const float f = clamped - float(fine);
  auto level = [&](size_t l, Rgb& out) {
    return l == 0 ? sampleLevel(image, packed, palette, uv, kReducedFootprint, out)
                  : sampleLevel(mips[l - 1].image, mips[l - 1].packed, mips[l - 1].palette, uv, kReducedFootprint, out);
  };
  Rgb a, b;
  if (!(uv.x >= 0.0f && uv.y >= 0.0f)) return average;  // a non-finite uv
  level(fine, a);
  if (f == 0.0f) return a;
  level(fine + 1, b);  // fine < coarsest here (f > 0 needs clamped < coarsest)
  return (1.0f - f) * a + f * b;
}

void Texture::prefetch(Vec2 uv, float lod) const {
  if (image.empty() || !sampling.isDefault()) return;  // a hint only: other samplings go without
  if (!(lod > 0.0f) || mips.empty()) return prefetchLevel(image, packed, uv, kBilinearFootprint);
  uv -= glm::floor(uv);  // as sampleLod
  if (!(uv.x >= 0.0f && uv.x < 1.0f && uv.y >= 0.0f && uv.y < 1.0f)) return;
  // The finer level of the pair only: the coarser one has a quarter of its texels and is
  // more often cached, and its footprint would cost as much again.
  const size_t fine = size_t(std::min(lod, float(mips.size())));
  if (fine == 0)
    prefetchLevel(image, packed, uv, kReducedFootprint);
  else
    prefetchLevel(mips[fine - 1].image, mips[fine - 1].packed, uv, kReducedFootprint);
}

void Texture::finish(const std::string& sceneSource) {
  if (image.empty() || image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != size_t(image.width) * size_t(image.height))
    fail("{}: texture '{}' is empty", sceneSource, path);
  Rgb sum(0.0f);
  for (const Rgb& texel : image.pixels) {
    if (!isFinite(texel)) fail("{}: texture '{}' contains a non-finite texel", sceneSource, path);
    sum += texel;
  }
  average = sum / float(image.pixels.size());
  packed.clear();
  palette.clear();
  packTexels(image, packed, palette);
  // The mip pyramid, each level from the one before (box averages of linear values); albedo
  // textures only (the light-field renderers' LOD reads no other kind).
  mips.clear();
  if (decode != ImageDecode::Colour) return;
  for (const Image* above = &image; above->width > 1 || above->height > 1; above = &mips.back().image) {
    Level level;
    level.image = downsampleBox(*above);
    packTexels(level.image, level.packed, level.palette);
    mips.push_back(std::move(level));
  }
}

Texture loadTextureFile(const std::string& path, ImageDecode decode) {
  ImageFile file = readImageFile(path, decode);
  Texture texture;
  texture.path = path;
  texture.decode = decode;
  texture.image = std::move(file.image);
  if (!file.ldrBytes.empty())
    texture.encoded = std::make_shared<const std::vector<unsigned char>>(std::move(file.ldrBytes));
  return texture;
}

Texture textureFromEncoded(std::string path, std::vector<unsigned char> bytes, const std::string& label,
                           ImageDecode decode) {
  Texture texture;
  texture.path = std::move(path);
  texture.decode = decode;
  texture.image = decodeLdrImage(bytes, label, decode);
  texture.encoded = std::make_shared<const std::vector<unsigned char>>(std::move(bytes));
  return texture;
}

}  // namespace pl
