#pragma once
// Compression of a light field's values (the VALS section of a .plf file).
//
// Three codecs besides raw float32 storage, selected by the section's encoding field
// (a ValuesCodec number, stored as it is in the .plf section table):
//
//   lossless  bit-exact. Each float's IEEE bits are mapped to an order-preserving unsigned
//             integer (negative floats reversed below positive ones), predicted from its
//             neighbours in the layout's images (below) with the LOCO-I/JPEG-LS
//             median edge detector (MED: left a, up b, up-left c → median(a, b, a + b − c)),
//             the wrapping difference zig-zag coded, the 32-bit residuals split into four
//             byte planes (all high bytes together, …) and the whole stream zstd'ed.
//             Green's and blue's prediction errors are coded relative to red's (the
//             channels of one value share the bake's noise).
//             For glossy charts a texel is predicted from its neighbouring directions in
//             the same tixel's texture (see the layout below for why not from the
//             neighbouring tixels' textures).
//   bc1       lossy, S3TC/BC1 (DXT1) blocks through libsquish, 4 bits per RGB value. Every
//             value is tone mapped per "image" (see the layout below) to 8-bit
//             y = 255·(x / scale)^(1/γ), γ = 2.2, scale = the image's largest component;
//             the scale is stored, so decoding inverts the tone mapping exactly up to
//             BC1's quantisation: x = scale·(y/255)^γ. Negative components are stored as 0.
//   hdr       lossy, keeps the dynamic range: every component x > 0 becomes a
//             logarithmic code round((log2 x − log2Min)·stepsPerStop) + 1 (0 = zero),
//             i.e. a relative error of at most 2^(1/(2·stepsPerStop)) − 1 (0.54% at the
//             default 64 steps per stop, 2.2% at 16), codes predicted with MED as in lossless, the
//             green and blue prediction residuals taken relative to red's (the channels of
//             a radiance change together), zig-zag, two byte planes, zstd.
//             Chosen over shared-exponent RGB9E5 by measurement (bench/hdr_alternatives.py:
//             RGB9E5 + zstd reaches 4–5:1 with up to 7.5% error on weak channels, these
//             codes 12–15:1 at ≤ 2.2% on every channel at 16 steps per stop). The default
//             of 64 steps per stop, with hdr the default codec of a bake
//             (kDefaultValuesCodec), keeps renders of Cornell and Sponza within a relMSE of
//             1e-6 of the float values' (docs/benchmarks.md "Light-field compression").
//
// Layout ("images"): the values are visited as 2-D images so that neighbours in an image
// are neighbours on a surface or on the hemisphere. A diffuse chart is one resU × resV image
// (one irradiance per tixel; a directionalIrradiance chart one more per tilted irradiance,
// Chart::directionalIrradiance); a glossy chart is one dirRes × dirRes image per tixel, its
// paraboloid texture, plus (Chart::diffuseValue) one resU × resV image of its tixels'
// diffuse irradiance (and of each tilted irradiance, Chart::directionalIrradiance). Values that no chart covers form 1-pixel-high images. BC1 pads
// images to whole 4 × 4 blocks (padding texels are masked out of the endpoint fit).
// Chosen by measurement on CornellBox-Glossy (533 mostly small glossy charts, dirRes 12)
// against the alternative of dirRes² images of resU × resV (one per direction texel, i.e.
// prediction across neighbouring tixels' textures): textures gave lossless 1.85:1 vs
// 1.72:1, hdr 19.3:1 vs 15.5:1 at the same render error, bc1 45.7:1 at 49.8 dB vs 25.0:1 at
// 49.2 dB — small charts make tiny, padded per-direction images.
//
// Stored stream (little-endian), for every codec but raw:
//   magic "PLVC", u32 codec, u64 valueCount, u64 imageCount, codec parameters
//   (hdr: f32 log2Min, u32 stepsPerStop; bc1: f32 gamma), u64 payload bytes,
//   then exactly one zstd frame (with its content checksum) holding the payload.
// Decoding checks every field against the layout the charts imply before it allocates, so
// a corrupt or truncated stream throws pl::Error, never crashes.
#include "lightfield/lightfield.h"

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pl {

enum class ValuesCodec : uint32_t { Raw = 0, Lossless = 1, Bc1 = 2, Hdr = 3 };

/// How `bake` (and Python's LightField.save) store the values unless told otherwise: hdr at
/// the default steps per stop below, and with it the other sections as zstd frames
/// (plf_file.h kPlfSectionZstd). `--compress none` keeps float32 values bit for bit.
inline constexpr ValuesCodec kDefaultValuesCodec = ValuesCodec::Hdr;

/// "none", "lossless", "bc1", "hdr" (the --compress / --mode spellings).
std::string_view valuesCodecName(ValuesCodec codec);
/// The inverse of valuesCodecName ("raw" is accepted for none); anything else → pl::Error.
ValuesCodec parseValuesCodec(std::string_view name);
/// Whether `code` (a section table's encoding field) names a codec this build knows.
bool isKnownValuesCodec(uint32_t code);

struct ValuesCodecOptions {
  int zstdLevel = 9;            ///< lossless, hdr and the zstd sections; decoding speed does not depend on it
  uint32_t hdrStepsPerStop = 64;  ///< hdr: logarithmic codes per factor of 2 (max relative error 0.54%)
};

/// Encodes `values` (laid out by `charts`, see above). Raw returns the float bytes. Lossy
/// codecs refuse non-finite values (pl::Error).
std::vector<unsigned char> encodeValues(ValuesCodec codec, const std::vector<Chart>& charts,
                                        std::span<const Rgb> values, const ValuesCodecOptions& options = {});

/// Decodes a stored stream into `valueCount` values. `context` (e.g. "scene.plf: values
/// section (VALS)") starts every error message. The charts must already be range-checked
/// against valueCount by the caller or not: they are checked again here.
std::vector<Rgb> decodeValues(ValuesCodec codec, const std::vector<Chart>& charts, uint64_t valueCount,
                              std::span<const unsigned char> stored, const std::string& context);

/// Errors of decoded values against the originals, per component.
struct ValuesError {
  double rmse = 0;                ///< root mean square of (decoded − original)
  double relativeRmse = 0;        ///< √(mean of (decoded − original)² / (original² + 1e-4·mean²))
  double maxRelative = 0;         ///< largest |decoded − original| / max(|original|, 1e-3·mean)
  double meanOriginal = 0;        ///< mean component value (the scale of the two floors above)
};
ValuesError measureValuesError(std::span<const Rgb> original, std::span<const Rgb> decoded);

}  // namespace pl
