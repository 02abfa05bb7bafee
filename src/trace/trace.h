#pragma once
// The reference path tracer: unidirectional path tracing with next-event estimation (NEE)
// on emissive triangles, the scene's lights and the environment, combined with BSDF sampling by
// multiple importance sampling (power heuristic), and Russian roulette. It is the ground
// truth every other renderer in plenoptic (the light-field bake in particular) is checked
// against, so it favours being obviously right over being clever.
//
// Conventions:
//  * A pixel value is the mean over the pixel's area (box filter) of camera weight × radiance
//    (W·sr⁻¹·m⁻², linear Rec.709), where the camera weight is cos⁴θ with vignetting on, else 1.
//    No exposure is applied here (the caller's ViewSettings do that when writing files).
//  * Every sample's numbers come from a Sampler (core/sampler.h) of (pixel, sample index,
//    seed) — Owen-scrambled ZSobol by default, or the independent PCG32 stream
//    Pcg32::forKey(pixel index, sample index, seed) — so an image depends on the seed only,
//    never on the number of threads or the tile schedule. With the sobol sampler a pixel's
//    samples are stratified, not independent: the per-pixel variance (sample variance / n)
//    then usually overestimates the variance of the mean (which stratification lowers).
//  * Samples whose radiance is not finite (NaN or ±inf) are NOT added to the pixel (that
//    would poison it) and NOT silently replaced by black either: they are counted in
//    TraceStats::nanSamples and the first offending (pixel, sample) is reported so that it
//    can be replayed with renderPixel() / `plenoptic trace --pixel X,Y`.
//  * Emission is one-sided (along the triangle's geometric normal) unless the material says
//    twoSidedEmission. BSDFs are two-sided: the shading frame is flipped to the side the ray
//    arrives from.
#include <cstdint>
#include <memory>
#include <string>

#include "core/math.h"
#include "core/sampler.h"
#include "image/image.h"

namespace pl {

struct Scene;
class Accel;
class Camera;

/// How direct light is found. Mis is the production setting; NeeOnly and BsdfOnly exist to test the
/// estimators against each other (they must agree within their noise).
enum class TraceStrategy {
  Mis,   ///< NEE + BSDF sampling, weighted by the power heuristic
  NeeOnly,   ///< light sampling only; emission found by BSDF sampling counts only after a
             ///< delta bounce (or on the camera ray)
  BsdfOnly,  ///< BSDF sampling only for emissive surfaces and the environment. The scene's
             ///< lights (light/lights.h) cannot be hit by a ray, so they are still sampled by
             ///< NEE in this mode.
};

/// "mis", "nee", "bsdf".
const char* strategyName(TraceStrategy strategy);
/// Parses a strategy name; throws pl::Error listing the valid names otherwise.
TraceStrategy parseStrategy(const std::string& name);

/// TraceSettings::maxDepth for "no cap": Russian roulette alone ends paths, as in Mitsuba
/// (max_depth = -1). The default, so that the reference is unbiased out of the box.
inline constexpr int kUnboundedDepth = -1;
/// Scattering events after which an unbounded path is cut anyway. Russian roulette continues a
/// path with probability at most kRouletteMaxContinue, so reaching it from rouletteDepth = 3
/// has probability ≤ 0.95^1021 ≈ 2e-23: no measurable bias. It only bounds the work of a
/// pathological path (e.g. one whose throughput turned NaN) to a known number of bounces.
inline constexpr int kSafetyDepth = 1024;
/// Largest probability with which Russian roulette continues a path. Below 1 so that every
/// path ends with probability 1 even where its throughput never drops below 1: perfect
/// mirrors facing each other in a closed box, a GGX sample weight above 1 (Mitsuba uses 0.95
/// as well). It only adds variance to paths whose throughput is ≥ 0.95 after
/// rouletteDepth bounces.
inline constexpr float kRouletteMaxContinue = 0.95f;

struct TraceSettings {
  int spp = 64;  ///< samples (paths) per pixel
  /// Maximum number of scattering events along a path: 0 = emission seen directly only,
  /// 1 = direct lighting, ..., kUnboundedDepth (the default) = no cap: Russian roulette
  /// alone ends paths (up to kSafetyDepth). A cap N is biased: in a closed scene of albedo a
  /// it loses the fraction a^(N+1) of the light (3 % for a = 0.9, N = 32).
  int maxDepth = kUnboundedDepth;
  /// Russian roulette starts after this many scattering events. It is unbiased: a path
  /// continues with probability q = min(kRouletteMaxContinue, √(max RGB component of its
  /// throughput)) and its throughput is divided by q.
  int rouletteDepth = 3;
  uint64_t seed = 0;
  TraceStrategy strategy = TraceStrategy::Mis;
  /// Where the path's numbers come from (core/sampler.h). Sobol stratifies each pixel's
  /// samples; Independent is the plain PCG32 stream, whose per-pixel variance estimates are
  /// exact (tests that need independent samples for their statistics ask for it).
  SamplerKind sampler = SamplerKind::Sobol;
  /// A comparison option, off by default: subsurface materials met after a Lambertian bounce
  /// (off a Lambertian material, or out of a subsurface walk) are shaded as Lambertian of their
  /// albedo A instead of walking the medium — the shortcut Blender Cycles takes (a closure under
  /// PATH_RAY_DIFFUSE_ANCESTOR gets radius 0, which turns it into a diffuse BSDF of its colour),
  /// so that bench/sss_vs_cycles.sh can render what Cycles renders. Biased: it drops the light
  /// that crosses an object after the first diffuse bounce. (`trace --subsurface-after-diffuse`.)
  bool subsurfaceLambertAfterDiffuse = false;
  int tileSize = 16;           ///< square tiles, rendered in parallel
  bool showProgress = true;    ///< progress bar with ETA on stderr (still subject to --quiet)
};

struct TraceStats {
  double seconds = 0.0;         ///< wall time of render()
  uint64_t paths = 0;           ///< camera samples traced (= width·height·spp)
  uint64_t rays = 0;            ///< closest-hit + shadow rays
  uint64_t nanSamples = 0;      ///< samples dropped because their radiance was not finite
  int firstNanX = -1, firstNanY = -1;  ///< a pixel with a dropped sample (-1 when none)
  uint64_t firstNanSample = 0;
  double pathsPerSecond() const { return seconds > 0.0 ? double(paths) / seconds : 0.0; }
  double raysPerSecond() const { return seconds > 0.0 ? double(rays) / seconds : 0.0; }
};

struct TraceResult {
  Image radiance;  ///< per-pixel mean of camera weight × radiance
  /// Per-pixel, per-channel variance OF THE MEAN (sample variance / number of samples):
  /// the squared standard error of `radiance`. Used for statistical image comparison.
  Image variance;
  TraceStats stats;
};

/// A Monte Carlo estimate with its own error estimate.
struct RadianceEstimate {
  Rgb mean{0.0f};
  Rgb varianceOfMean{0.0f};  ///< sample variance / samples (squared standard error)
  uint64_t samples = 0;      ///< finite samples that went into the mean
  uint64_t nanSamples = 0;   ///< non-finite samples that were dropped (and counted)
};

class PathTracer {
 public:
  /// Builds the light-selection distribution. The scene and accel must outlive the tracer.
  PathTracer(const Scene& scene, const Accel& accel);
  ~PathTracer();
  PathTracer(const PathTracer&) = delete;
  PathTracer& operator=(const PathTracer&) = delete;

  /// Renders the camera's full image, tiles in parallel on the current thread pool.
  TraceResult render(const Camera& camera, const TraceSettings& settings) const;

  /// Replays one pixel exactly as render() computes it (same random streams, same result).
  RadianceEstimate renderPixel(const Camera& camera, const TraceSettings& settings, int x, int y) const;

  /// settings.spp estimates (independent with the independent sampler) of the radiance arriving at ray.origin from
  /// direction −ray.direction (i.e. the radiance the ray "sees"), streams keyed by
  /// (key, sample index, settings.seed). For tests and for checking other renderers at
  /// chosen points.
  RadianceEstimate estimateRadiance(const Ray& ray, const TraceSettings& settings, uint64_t key) const;

  size_t emissiveTriangleCount() const;
  /// Number of light-selection entries (emissive triangles + scene lights + environment).
  size_t lightCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Statistical comparison of two noisy estimates of the same image (each with its
/// per-pixel variance of the mean). For every pixel and channel
///     z = (a − b) / sqrt(varA + varB + floor²)
/// where floor = 1e-6·max(|a|,|b|) absorbs float rounding of zero-variance pixels (e.g. the
/// light seen directly). Under the hypothesis "same expectation", z is approximately
/// standard normal, so the test rejects when
///   * any |z| exceeds the two-sided Šidák-corrected threshold for `alpha` over all N
///     pixel-channels (catches local errors), or
///   * in any channel, the whole-image z of the summed radiance,
///     (Σa − Σb)/sqrt(ΣvarA + ΣvarB), exceeds the two-sided threshold for alpha/6 (catches
///     small global biases, e.g. a 5 % scale, that no single pixel can reveal). Pixels are
///     independent, so their variances add; the channels of a pixel are not (same paths), so
///     each channel is tested on its own, Bonferroni-corrected over the three.
/// The two parts each use alpha/2 (Bonferroni), so the overall false-rejection rate is ≤ alpha
/// as far as the normal approximation holds.
struct ImageZTest {
  size_t tests = 0;             ///< N = pixels × 3
  double pixelThreshold = 0.0;  ///< Šidák-corrected |z| limit
  double maxAbsZ = 0.0;
  int worstX = -1, worstY = -1, worstChannel = -1;
  double globalZ = 0.0;           ///< whole-image z of the channel with the largest |z|
  int globalChannel = -1;
  double globalThreshold = 0.0;
  double meanSquaredZ = 0.0;      ///< ≈ 1 under the hypothesis (diagnostic)
  bool pass = false;
  std::string summary() const;
};
ImageZTest compareImagesZ(const Image& a, const Image& varianceA, const Image& b, const Image& varianceB,
                          double alpha = 0.01);

/// Two-sided standard-normal critical value: the z with P(|Z| > z) = p.
double twoSidedNormalQuantile(double p);

}  // namespace pl
