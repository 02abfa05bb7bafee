#pragma once
// Image-based lighting on top of env.h: spherical harmonics, irradiance environment maps,
// prefiltered specular maps, the split-sum BRDF table and the split-sum error analysis.
//
// ─── Spherical harmonics ────────────────────────────────────────────────────────────────────
// Real, orthonormal SH (∫ Y_i Y_j dω = δ_ij over the sphere), bands l = 0, 1, 2, index
// k = l(l+1) + m, evaluated on the WORLD direction (x, y, z) with +y up:
//   Y0 = ½√(1/π)                       = 0.282095
//   Y1 = √(3/4π)·y   Y2 = √(3/4π)·z   Y3 = √(3/4π)·x          (0.488603)
//   Y4 = ½√(15/π)·xy  Y5 = ½√(15/π)·yz                         (1.092548)
//   Y6 = ¼√(5/π)·(3z² − 1)                                      (0.315392)
//   Y7 = ½√(15/π)·xz  Y8 = ¼√(15/π)·(x² − y²)                  (1.092548, 0.546274)
// These are Ramamoorthi & Hanrahan's (2001) formulas applied to world coordinates; since
// the irradiance convolution acts per band and each band's span is rotation invariant, no
// change of axes is needed. Radiance coefficients: L_k = ∫ L(ω) Y_k(ω) dω (per RGB
// channel). A constant environment L = c has L_0 = c·2√π and all others 0.
//
// Projection treats each texel as constant radiance over its exact footprint and integrates
// the basis over that footprint: in closed form for lat-long texels (products of integrals
// in cos θ and φ), with 2×2 Gauss points rescaled to the exact quad solid angle for cube
// texels. Hence the constant environment is exact to rounding in both layouts.
//
// Irradiance (R-H 2001, eq. 8): E(n) = Σ_k Â_l L_k Y_k(n) with Â_0 = π, Â_1 = 2π/3,
// Â_2 = π/4 (the clamped-cosine kernel's coefficients). The neglected bands l ≥ 3 change
// E by at most 0.1927·max L for any 0 ≤ L ≤ max L (tight; shTruncationBound()), and by at
// most Σ_{l≥4, even} Â_l² (2l+1)/(4π) ≈ 0.0162 for a unit clamped-cosine lobe of light.
#include "bsdf/bsdf.h"
#include "env/env.h"

#include <array>
#include <string>
#include <vector>

namespace pl {

// ─── SH ────────────────────────────────────────────────────────────────────────────────────

struct Sh9 {
  std::array<DVec3, 9> coefficients{};  ///< L_k per RGB channel (W·m⁻²·sr⁻¹·sr = W·m⁻²)
};

/// The 9 basis functions at a unit direction.
std::array<double, 9> shBasis(const DVec3& dir);
/// Radiance SH coefficients of an environment (parallel, double precision).
Sh9 projectSh9(const EnvImage& env);
/// Radiance reconstructed from the 9 coefficients (band-limited).
DVec3 shRadiance(const Sh9& sh, const DVec3& dir);
/// Irradiance E(n) = ∫ L(ω) max(0, n·ω) dω from the coefficients (R-H 2001), W·m⁻².
DVec3 shIrradiance(const Sh9& sh, const DVec3& normal);
/// Â_l, the SH coefficients of the clamped cosine max(0, cos θ) scaled as in R-H 2001:
/// π, 2π/3, π/4, 0, −π/24, … (exact formula for every l).
double clampedCosineCoefficient(int l);
/// Tight upper bound of |E(n) − E_SH(n)| for every radiance 0 ≤ L ≤ 1 when bands
/// 0…maxBand are kept: π ∫_{−1}^{1} |max(0,t) − K(t)| dt, with K the clamped-cosine kernel
/// truncated after maxBand (derivation in sh.cpp). For maxBand = 2 it is 0.1927, i.e. 6.1 %
/// of the irradiance π of a unit constant environment; multiply by max L for other maps.
double shTruncationBound(int maxBand = 2);
/// JSON object {"basis": ..., "coefficients": [[r,g,b] × 9]}.
std::string shToJson(const Sh9& sh, const std::string& source);

// ─── Irradiance environment maps ───────────────────────────────────────────────────────────

/// Brute force: E(n) = Σ_texels L·max(0, n·ω_texel)·ΔΩ_texel over every texel of `source`
/// (typically a downsampled map), evaluated at each texel centre of a map of the given
/// layout and size. O(target × source), parallel over target rows, with a progress bar.
EnvImage irradianceBruteForce(const EnvImage& source, bool cube, int size);
/// From SH: E(n) per texel centre of a map of the given layout and size.
EnvImage irradianceFromSh(const Sh9& sh, bool cube, int size);

/// Per-texel relative difference between two maps of identical layout and size, measured on
/// luminance: |Y(a) − Y(b)| / Y(b) (texels with Y(b) = 0 are skipped). RMS is solid-angle
/// weighted.
struct MapDifference {
  double maxRelative = 0.0;
  double rmsRelative = 0.0;
  Vec3 maxAt{0.0f};  ///< direction of the largest difference
};
MapDifference compareMaps(const EnvImage& a, const EnvImage& reference);

// ─── Prefiltered specular maps and the split-sum table ─────────────────────────────────────

enum class SpecularModel { Ggx, BlinnPhong };
SpecularModel parseSpecularModel(const std::string& name);  ///< "ggx" | "blinn-phong"
const char* specularModelName(SpecularModel model);

/// The BSDF (from bsdf.h) used for a perceptual roughness r ∈ [0,1] with Fresnel
/// reflectance f0 and no diffuse part. GGX: α = max(r², 1e-3). Blinn-Phong: the exponent
/// with the same Beckmann-equivalent width, n = 2/α² − 2 (Walter et al. 2007), specular = f0
/// (the model has no Fresnel term).
Bsdf specularBsdf(SpecularModel model, float roughness, float f0);

/// Prefiltered radiance for reflection direction R (Karis 2013 with N = V = R): the
/// BRDF-weighted mean of L around R,
///   P(R) = ∫ L(ω) f(R, ω) cos θ dω / ∫ f(R, ω) cos θ dω,
/// with f the model at roughness r seen along its normal R. Estimated with `samples`
/// stratified BSDF samples (bsdf.h sample()), each reading a pre-averaged (coarser) level of
/// the lat-long pyramid matched to the sample's solid angle 1/(N·pdf) (filtered importance
/// sampling, Křivánek & Colbert 2008), which removes most of the noise of a small N.
struct LatLongPyramid {
  std::vector<LatLongMap> levels;  ///< levels[0] = the map; each next one halves the height
  explicit LatLongPyramid(LatLongMap base);
  /// Bilinear lookup in the level whose texels subtend about `solidAngle` sr (rounded down).
  Rgb lookup(const Vec3& dir, double solidAngle) const;
};

struct PrefilterOptions {
  SpecularModel model = SpecularModel::Ggx;
  int levels = 6;        ///< roughness r_k = k/(levels−1), k = 0 … levels−1
  int height = 128;      ///< lat-long height of level 0; halved per level, not below 16
  int samples = 1024;    ///< BSDF samples per texel
};
struct PrefilteredLevel {
  float roughness = 0.0f;
  LatLongMap map;
};
/// Level 0 (r = 0, a mirror) is the source itself resampled; the others are filtered.
std::vector<PrefilteredLevel> prefilter(const EnvImage& env, const PrefilterOptions& options);

/// Split-sum ("DFG") term: for unit radiance, ∫ f cos θi dωi = f0·A + B (Karis 2013).
/// Computed with the bsdf.h model itself: B = albedo at f0 = 0, A = albedo at f0 = 1 minus B,
/// with `samples` stratified BSDF samples. Blinn-Phong (no Fresnel) gives B = 0.
struct DfgTerm {
  double scale = 0.0;  ///< A
  double bias = 0.0;   ///< B
};
DfgTerm dfgTerm(SpecularModel model, float roughness, float cosView, int samples);
/// The lookup table: x = N·V in ((i+½)/size), y = roughness ((j+½)/size, top row = 0),
/// R = A, G = B, B = 0.
Image dfgTable(SpecularModel model, int size, int samples);

// ─── Split-sum error analysis ──────────────────────────────────────────────────────────────

struct SplitSumOptions {
  SpecularModel model = SpecularModel::Ggx;
  std::vector<float> roughness{0.1f, 0.2f, 0.3f, 0.45f, 0.6f, 0.8f, 1.0f};
  std::vector<float> viewDegrees{0.0f, 20.0f, 40.0f, 60.0f, 75.0f, 85.0f};
  int normals = 16;           ///< surface normals spread over the sphere (Fibonacci)
  int samples = 4096;         ///< per MIS strategy per integral
  float f0 = 1.0f;            ///< Fresnel reflectance at normal incidence
  uint64_t seed = 0;
};
/// One (roughness, view angle) cell: relative error (approx − exact)/exact of luminance,
/// over all normals.
struct SplitSumCell {
  float roughness = 0.0f, viewDegrees = 0.0f;
  double meanAbsRelative = 0.0;   ///< mean |error| over normals
  double maxAbsRelative = 0.0;    ///< worst normal
  double meanSignedRelative = 0.0;
  double monteCarloRelative = 0.0;  ///< largest relative standard error of the exact integrals
};
struct SplitSumReport {
  std::vector<SplitSumCell> cells;  ///< roughness-major
  int rows = 0, columns = 0;        ///< roughness count, view-angle count
  double maxMonteCarloRelative = 0.0;
};
/// For each cell and normal n (view v at the cell's angle from n):
///   exact  = ∫ f(v, ω) L(ω) cos θ dω, MC with MIS (BSDF sampling + environment sampling,
///            power heuristic), `samples` per strategy;
///   approx = P(R)·(f0·A + B) with R = reflect(v, n), P(R) = exact integral at v = n = R
///            (f0 = 1) divided by its albedo (so P is the same BRDF-weighted mean as the
///            prefiltered maps, without their discretisation), A, B from dfgTerm.
/// The difference is the decomposition error alone, plus Monte Carlo noise (reported).
SplitSumReport splitSumError(const EnvironmentMap& env, const SplitSumOptions& options);
std::string splitSumToJson(const SplitSumReport& report, const SplitSumOptions& options, const std::string& source);
std::string splitSumTable(const SplitSumReport& report);
/// A heat map of mean |relative error|: one 32×32 block per cell (rows = roughness from
/// the top, columns = view angle from the left), colour scale 0 … maxValue (black → blue →
/// red → yellow → white), with a colour bar on the right. Returns 8-bit sRGB pixels.
Image8 splitSumHeatMap(const SplitSumReport& report, double maxValue);

}  // namespace pl
