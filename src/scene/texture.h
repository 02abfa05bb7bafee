#pragma once
// Textures: linear RGB images on surfaces (albedo, normal maps, alpha masks), their mip levels
// and the packed 8-bit palettes they are sampled from, and how they are made from image files.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "image/image.h"

namespace pl {

/// What a texture coordinate outside [0, 1] reads, per axis (glTF sampler wrapS / wrapT):
/// Repeat the image, hold its edge texels (ClampToEdge), or repeat it mirrored every other
/// time (MirroredRepeat: texel index i of the infinite plane reads i mod 2W when below W,
/// else 2W − 1 − (i mod 2W), as OpenGL defines it). The numbers are the .plf's.
enum class TextureWrap : uint8_t { Repeat = 0, ClampToEdge = 1, MirroredRepeat = 2 };

/// How a texture is filtered (a glTF sampler; OBJ and JSON textures keep the defaults):
/// `nearest` (magFilter NEAREST): level-0 reads take the texel the uv falls in instead of the
/// bilinear blend — what the path tracer and the bake always read, and the renderers where
/// a texture is magnified. `mipmaps` false (minFilter NEAREST or LINEAR, which name no mip
/// levels): the renderers read level 0 at every distance; otherwise they blend mip levels
/// trilinearly whatever the *_MIPMAP_* variant asks.
struct TextureSampling {
  TextureWrap wrapU = TextureWrap::Repeat, wrapV = TextureWrap::Repeat;
  bool nearest = false;
  bool mipmaps = true;
  bool isDefault() const { return *this == TextureSampling{}; }
  bool operator==(const TextureSampling&) const = default;
};

/// A linear RGB texture, sampled bilinearly with wrap-around (repeat) unless its `sampling`
/// says otherwise.
/// uv = (0,0) is the *bottom-left* of the image (OBJ/OpenGL convention); glTF loaders flip v.
/// `decode` says what the file's channels became (image.h): sRGB-decoded colour for albedo
/// textures, raw values for normal maps, the alpha channel (coverage in [0, 1], in all three
/// channels) for alpha masks. One file used in two roles is two textures.
struct Texture {
  std::string path;
  ImageDecode decode = ImageDecode::Colour;
  Image image;
  /// The image file's own bytes (PNG/JPEG/TGA/BMP as found on disk or in a glTF buffer), from
  /// which `image` was decoded by decodeLdrImage; null for textures read from HDR files, which
  /// exist only decoded. A .plf embeds these bytes instead of the float pixels (8–40× smaller)
  /// and decodes them on load. Shared, so that copying a Scene does not copy them.
  std::shared_ptr<const std::vector<unsigned char>> encoded;
  Rgb average{0.0f};  ///< mean over all texels (used where one albedo per region is needed)
  TextureSampling sampling;  ///< wrap modes and filters (default: repeat, bilinear, mip-mapped)

  /// Checks the pixels (present, finite) and computes `average`; throws pl::Error naming
  /// `sceneSource` and the texture. Scene::finalize and the .plf reader call it.
  void finish(const std::string& sceneSource);

  /// Bilinear at full resolution (level 0), wrapped as `sampling` says. A non-finite uv (only possible from a NaN
  /// hit, since loaders reject non-finite uvs) returns `average` rather than spreading the NaN
  /// into the albedo; the renderers count and report non-finite radiance where it arises. The
  /// path tracer, the bake and normal/alpha maps read textures here.
  Rgb sample(Vec2 uv) const;
  /// The per-channel maximum of every level-0 texel that sample() may read at a uv in the
  /// rectangle [lo, hi] (wrapped as `sampling` says; the whole image's for a non-finite
  /// corner): a bound on sample() over the rectangle, so 0 only where sample() is 0 all over
  /// it. The light sampler's test of which emitting triangles are black (light/emitters.h).
  Rgb maxOver(Vec2 lo, Vec2 hi) const;
  /// Trilinear: bilinear in mip levels ⌊lod⌋ and ⌊lod⌋ + 1 (`levels`), blended by the
  /// fraction of lod. lod ≤ 0 or NaN is exactly sample(uv) (magnified or unfiltered: full
  /// resolution, the same bits); lod beyond the coarsest level reads that level alone. Level l
  /// has the same uv convention as the image (texel centres at (x + ½)/W_l), so levels line up.
  /// The light-field renderers' albedo (lookup.h albedoTextureLod chooses lod).
  Rgb sampleLod(Vec2 uv, float lod) const;
  /// Asks the processor to fetch the cache lines sampleLod(uv, lod) will read (the packed
  /// texels, or the float rows), without waiting for them. The fast renderer issues it for a
  /// whole tile before shading it, so that the texel reads of many pixels overlap instead of
  /// missing the cache one after another.
  void prefetch(Vec2 uv, float lod) const;

  /// The same texels as `image`, packed for sampling, when all their channel values are among
  /// at most 256 floats (every texture decoded from 8 bits): per texel one byte per channel,
  /// an index into `palette`, in blocks of 4×4 texels (64 bytes, one cache line), so that a
  /// bilinear footprint usually reads one cache line instead of two rows of 12-byte texels,
  /// and a texture takes a third of the cache. The palette holds the exact floats, so
  /// sample() gives the same values bit for bit. Built by finish(); empty for other textures
  /// (16-bit and HDR images), which sample() reads from `image`. Measured on Sponza's
  /// walk-through, where texel reads missing the cache were a quarter of the frame: docs/benchmarks.md, Walk-through speed.
  struct alignas(64) PackedBlock {
    uint32_t texels[16];  ///< texel (x, y) of the block at [4·y + x]: palette indices r | g << 8 | b << 16
  };
  std::vector<PackedBlock> packed;
  std::vector<float> palette;

  /// One mip level: its texels as floats, and packed like level 0 when their values allow.
  struct Level {
    Image image;
    std::vector<PackedBlock> packed;  ///< empty unless ≤ 256 distinct values per channel
    std::vector<float> palette;
  };
  /// Mip levels 1, 2, … down to 1×1 (mips[l − 1] is level l), built by finish() from the
  /// linear texels: level l + 1 is W_{l+1} = max(1, ⌊W_l / 2⌋) by H_{l+1} = max(1, ⌊H_l / 2⌋)
  /// texels, each the exact box average of the level-l texels under it (a texel of level l
  /// covers [x, x+1) × [y, y+1); the one of level l+1 covers W_l/W_{l+1} × H_l/H_{l+1} of
  /// them, partial texels weighted by the area they cover — so an even size gives plain 2×2
  /// averages and an odd one 2.5- or 3-texel-wide boxes, and the average of every level is
  /// the image's). Averages rarely keep ≤ 256 values per channel, so most levels stay float:
  /// 12 bytes per texel, ≤ ⅓ of level 0's texel count in all, i.e. +4 bytes per level-0
  /// texel beside its 12 (floats) + 4 (packed) bytes — +25 % for an 8-bit texture, +33 %
  /// for a float-only one. Only colour textures (ImageDecode::Colour: albedo) get levels;
  /// normal maps and alpha masks are read at full resolution everywhere, so theirs stay empty.
  std::vector<Level> mips;
};

/// A texture read from an image file (any format readImage reads), keeping the bytes of
/// 8-bit formats in `encoded`. Scene loaders call it; errors name the file.
Texture loadTextureFile(const std::string& path, ImageDecode decode = ImageDecode::Colour);

/// A texture decoded from an 8-bit image file's bytes (a glTF buffer, a .plf's scene section):
/// path is what the texture is called, label prefixes decoding errors.
Texture textureFromEncoded(std::string path, std::vector<unsigned char> bytes, const std::string& label,
                           ImageDecode decode = ImageDecode::Colour);

}  // namespace pl
