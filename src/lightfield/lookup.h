#pragma once
// Looking the light field up: the 16-neighbour interpolation of seed slide 36 — bilinear over
// the 2×2 nearest tixels (position) × bilinear over the 2×2 nearest paraboloid texels
// (direction). Used by the renderers and, through the same functions, by the bake itself.
//
// Interpolation conventions (match lightfield.h):
//   tixel (i, j) has its centre at continuous grid coordinate (i, j), where a world point p has
//   grid coordinates ((p − origin)·axisU / tixelSize − ½, (p − origin)·axisV / tixelSize − ½);
//   paraboloid texel (a, b) has its centre at continuous coordinate (a, b), see paraboloid.h.
//   Outside the outermost centres the edge values are held (clamp-to-edge), never extrapolated.
#include "accel/accel.h"
#include "core/math.h"
#include "core/simd4.h"
#include "lightfield/lightfield.h"
#include "light/emitters.h"
#include "light/light.h"
#include "lightfield/paraboloid.h"
#include "scene/scene.h"

#include <cmath>
#include <limits>
#include <cstdint>
#include <optional>
#include <vector>

namespace pl {

/// One axis of a clamp-to-edge bilinear interpolation: value = (1−f)·v[i0] + f·v[i1].
struct LinearTap {
  uint32_t i0 = 0, i1 = 0;
  float f = 0.0f;
};

/// The tap for continuous coordinate x over `count` samples centred at 0 … count−1:
///   x ≤ 0 or NaN   → (0, 0, f = 0)            (hold the first sample)
///   x ≥ count − 1  → (count−1, count−1, f = 0) (hold the last sample)
///   otherwise      → (⌊x⌋, ⌊x⌋ + 1, x − ⌊x⌋).
/// Written without branches (the renderers call it four times per pixel with data-dependent
/// clamping): the clamp compiles to maxss/minss, `x > 0 ? x : 0` maps NaN to 0, and the
/// upper index is ⌊x⌋ + [x > 0] capped at count − 1, which is exactly the case list above.
inline LinearTap linearTap(float x, uint32_t count) {
  const uint32_t last = count - 1;
  const float positive = x > 0.0f ? x : 0.0f;  // NaN → 0
  const float lastF = float(last);
  const float clamped = positive < lastF ? positive : lastF;
  LinearTap tap;
  tap.i0 = uint32_t(clamped);
  const uint32_t next = tap.i0 + uint32_t(clamped > 0.0f);
  tap.i1 = next < last ? next : last;
  tap.f = clamped - float(tap.i0);
  return tap;
}

/// Continuous tixel grid coordinates of world point p on chart c (p need not lie on it), given
/// inverseTixelSize = 1 / c.tixelSize (the lookups precompute it per chart).
inline Vec2 tixelGridCoordinates(const Chart& c, const Vec3& p, float inverseTixelSize) {
  const Vec3 d = p - c.origin;
  return {glm::dot(d, c.axisU) * inverseTixelSize - 0.5f, glm::dot(d, c.axisV) * inverseTixelSize - 0.5f};
}
inline Vec2 tixelGridCoordinates(const Chart& c, const Vec3& p) { return tixelGridCoordinates(c, p, 1.0f / c.tixelSize); }

/// A world direction in the chart's local frame (z along the chart normal).
inline Vec3 chartLocalDirection(const Chart& c, const Vec3& w) {
  return {glm::dot(w, c.axisU), glm::dot(w, c.axisV), glm::dot(w, c.normal)};
}
inline Vec3 chartWorldDirection(const Chart& c, const Vec3& local) {
  return local.x * c.axisU + local.y * c.axisV + local.z * c.normal;
}

/// Where the interpolation reads values from, as four lanes: a LightField::values-style Rgb
/// array, or the same values padded to 16 bytes (Lanes4), which loads in one aligned access —
/// the fast renderer's layout. Both give the same lanes, so the same results.
struct RgbValues {
  const Rgb* values;
  F4 operator()(uint64_t i) const { return f4FromRgb(values[i]); }
};
struct PaddedValues {
  const Lanes4* values;
  F4 operator()(uint64_t i) const { return f4Load(values[i].v); }
};

/// Bilinear × bilinear interpolation over values laid out like LightField::values, read
/// through `load` (RgbValues or PaddedValues), four lanes at a time. Specular charts give 0.
template <typename Load>
inline F4 interpolateLanes(const Load& load, const Chart& c, Vec2 grid, Vec2 st) {
  if (c.kind == ChartKind::Specular || c.dirRes == 0) return f4Zero();
  const LinearTap tu = linearTap(grid.x, c.resU);
  const LinearTap tv = linearTap(grid.y, c.resV);
  const uint32_t is[2] = {tu.i0, tu.i1}, js[2] = {tv.i0, tv.i1};
  const float wu[2] = {1.0f - tu.f, tu.f}, wv[2] = {1.0f - tv.f, tv.f};
  F4 sum = f4Zero();
  if (c.dirRes == 1) {
    // c.valueIndex(i, j) (one value per tixel, or a directionalIrradiance chart's E among its
    // four); the rows summed separately, then together (a shorter chain of dependent
    // additions than one running sum).
    const uint64_t stride = c.valuesPerTixel();
    const uint64_t row0 = c.firstValue + uint64_t(js[0]) * c.resU * stride, row1 = c.firstValue + uint64_t(js[1]) * c.resU * stride;
    const F4 lower = f4Add(f4Mul(f4Splat(wu[0] * wv[0]), load(row0 + is[0] * stride)),
                           f4Mul(f4Splat(wu[1] * wv[0]), load(row0 + is[1] * stride)));
    const F4 upper = f4Add(f4Mul(f4Splat(wu[0] * wv[1]), load(row1 + is[0] * stride)),
                           f4Mul(f4Splat(wu[1] * wv[1]), load(row1 + is[1] * stride)));
    return f4Add(lower, upper);
  }
  const LinearTap ta = linearTap(paraboloidTexelCoordinate(st.x, c.dirRes), c.dirRes);
  const LinearTap tb = linearTap(paraboloidTexelCoordinate(st.y, c.dirRes), c.dirRes);
  const uint32_t as[2] = {ta.i0, ta.i1}, bs[2] = {tb.i0, tb.i1};
  const float wa[2] = {1.0f - ta.f, ta.f}, wb[2] = {1.0f - tb.f, tb.f};
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) {
      const float wPos = wu[x] * wv[y];
      if (wPos == 0.0f) continue;
      F4 inner = f4Zero();
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a)
          inner = f4Add(inner, f4Mul(f4Splat(wa[a] * wb[b]), load(c.valueIndex(is[x], js[y], as[a], bs[b]))));
      sum = f4Add(sum, f4Mul(f4Splat(wPos), inner));
    }
  return sum;
}

/// Bilinear interpolation over the 2×2 tixels of chart c nearest grid position `grid`
/// (tixelGridCoordinates) of perTixel(i, j) (four lanes), clamped to the grid like
/// interpolateLanes: the glossy charts' diffuse irradiance Ẽ (lightfield.h) is read this way by
/// the renderers and, weighted by each tixel's transport albedo, by the bake.
template <typename PerTixel>
inline F4 bilinearOverTixels(const Chart& c, Vec2 grid, const PerTixel& perTixel) {
  const LinearTap tu = linearTap(grid.x, c.resU);
  const LinearTap tv = linearTap(grid.y, c.resV);
  const F4 lower = f4Add(f4Mul(f4Splat((1.0f - tu.f) * (1.0f - tv.f)), perTixel(tu.i0, tv.i0)),
                         f4Mul(f4Splat(tu.f * (1.0f - tv.f)), perTixel(tu.i1, tv.i0)));
  const F4 upper = f4Add(f4Mul(f4Splat((1.0f - tu.f) * tv.f), perTixel(tu.i0, tv.i1)),
                         f4Mul(f4Splat(tu.f * tv.f), perTixel(tu.i1, tv.i1)));
  return f4Add(lower, upper);
}

/// The irradiance about mapped normal n' (lanes r, g, b, 0; W·m⁻²) at grid position `grid` of
/// a directionalIrradiance chart c (lightfield.h "Normal-mapped diffuse charts") whose
/// interpolated irradiance about its normal is `irradiance`: the model of tiltWeights with the
/// tilted irradiances bilinear over the tixels like E, clamped at 0. localMappedNormal: n' in
/// the tilt frame at the point (tiltFrameAround).
template <typename Load>
inline F4 mappedNormalIrradiance(const Load& load, const Chart& c, Vec2 grid, F4 irradiance, const Vec3& localMappedNormal) {
  const TiltWeights w = tiltWeights(localMappedNormal);
  F4 total = f4Mul(f4Splat(w.irradiance), irradiance);
  for (uint32_t k = 0; k < kTiltedNormals; ++k) {
    const F4 tilted = bilinearOverTixels(c, grid, [&](uint32_t i, uint32_t j) { return load(c.tiltedIrradianceIndex(i, j, k)); });
    total = f4Add(total, f4Mul(f4Splat(w.tilted[k]), tilted));
  }
  return f4Max(total, f4Zero());
}

/// interpolateLanes over a raw Rgb value array (the bake uses it on its working arrays).
inline Rgb interpolateValues(const Rgb* values, const Chart& c, Vec2 grid, Vec2 st) {
  return f4Rgb(interpolateLanes(RgbValues{values}, c, grid, st));
}


/// Diffuse albedo of `material` at albedo point p (scene.h: the albedo slot's uv, the mip level
/// and the vertex colour): the Lambertian albedo times albedoModulation(p) — the albedo
/// texture read at mip level p.lod (Texture::sampleLod; lod ≤ 0 is full resolution, exactly the
/// texel the path tracer's bsdfAt reads) times the vertex colour. The renderers pass
/// albedoTextureLod's level; the bake kFullResolution (its transport albedo is already an
/// average over each gather point's footprint, parameterisation.cpp).
Rgb diffuseAlbedoAt(const Scene& scene, uint32_t material, const AlbedoPoint& p);
inline constexpr float kFullResolution = 0.0f;
/// The albedo ρ of a glossy chart's diffuse part (Chart::diffuseValue) at albedo point p: the
/// model's diffuse albedo times albedoModulation(p) — the path tracer's texturing (bsdfAt),
/// whose diffuse term is ρ/π · k(μo) · k(μi). With a metallic-roughness texture the diffuse
/// albedo is baseColor × modulation × (1 − metalness) at the point (MetallicRoughnessMap).
Rgb glossyDiffuseAlbedoAt(const Scene& scene, uint32_t material, const AlbedoPoint& p);
/// A glossy chart's diffuse part per unit Ẽ at albedo point p towards a viewer at cosine μo, for
/// a material with a metallic-roughness texture: ρ(p)/π · k(μo) of the point's model
/// (materialModelAt), its k of the point's own roughness as in the path tracer.
Rgb glossyDiffuseReflectanceAt(const Scene& scene, uint32_t material, const AlbedoPoint& p, float cosViewer);

/// The mip level a light-field renderer reads an albedo texture at, by ray cones
/// (Akenine-Möller et al., "Texture Level of Detail Strategies for Real-Time Ray Tracing",
/// Ray Tracing Gems, ch. 20): a ray arriving along unit `direction` at triangle `triangle` of
/// `mesh` with a cone of width w = coneWidth (scene units; RenderSettings' textureConeSpread
/// × the distance travelled from the camera, summed over the mirror/glass chain) covers an
/// elliptical footprint on the surface with axes w (across the view) and w / |cos θ| (along
/// it; θ between the ray and the triangle's normal). The triangle maps world area
/// P_a = ½|c|, c = (p1 − p0) × (p2 − p0), to texel area T_a = W·H·½|(uv1 − uv0) × (uv2 − uv0)|
/// (W × H texels; uv = the slot's uv set with its transform `mapping` applied, so T_a scales
/// with |det| of its linear part; the barycentrics without uvs). One isotropic level must stand for that
/// ellipse: it is taken with the footprint's area, i.e. the geometric mean w / √|cos θ| of its
/// axes, so the level covers as many texels as the footprint does — not its long axis, as the
/// paper's rule (and GPU trilinear filtering without anisotropy) does, which blurs grazing
/// surfaces across the view by 1/|cos θ|. Measured on a Sponza frame at 1 sample per pixel
/// against 256 samples at full resolution: relMSE 0.0057 with the area, 0.0066 with the long
/// axis, 0.0089 at full resolution (docs/benchmarks.md, Texture level of detail). The level is log2 of
/// the texels across that mean width:
///   λ = log2(w · √(T_a / P_a) / √|cos θ|),  |cos θ| = |d·c| / |c|
///     = ½ · log2(W·H·|uv cross| · w² / |d·c|)          (one log2, no square root or length).
/// w = 0 (texture LOD off) gives −∞, degenerate uvs −∞ (level 0), a grazing ray a level
/// beyond the coarsest (read as the coarsest); a NaN reads level 0 (Texture::sampleLod). The
/// log2 is core/math.h approximateLog2 (within 0.008 of a level).
inline float albedoTextureLod(const Mesh& mesh, uint32_t triangle, const Texture& texture, const TextureMapping& mapping,
                              const Vec3& direction, float coneWidth) {
  if (!(coneWidth > 0.0f)) return kFullResolution;  // LOD off: the same level 0, without the triangle's loads
  const UVec3 tri = mesh.triangles[triangle];
  const Vec3 c = glm::cross(mesh.positions[tri[1]] - mesh.positions[tri[0]], mesh.positions[tri[2]] - mesh.positions[tri[0]]);
  float uvCross = 1.0f;  // uvAt's barycentric uvs: (0,0), (1,0), (0,1)
  const std::vector<Vec2>& uvs = mapping.uvSet == 1 ? mesh.uvs1 : mesh.uvs;
  if (!uvs.empty()) {
    const Vec2 a = uvs[tri[1]] - uvs[tri[0]], b = uvs[tri[2]] - uvs[tri[0]];
    uvCross = std::abs(a.x * b.y - a.y * b.x);
  }
  if (!mapping.isDefault()) uvCross *= std::abs(glm::determinant(mapping.linear));
  const float cosArea = std::abs(glm::dot(direction, c));  // |c| |cos θ|
  const float texelsSquared =
      float(texture.image.width) * float(texture.image.height) * uvCross * (coneWidth * coneWidth) / cosArea;
  return 0.5f * approximateLog2(texelsSquared);
}

/// albedoTextureLod for a hit on a diffuse chart of `material`: the level its albedo texture
/// is read at, or kFullResolution for a material without one.
inline float albedoLodAt(const Scene& scene, uint32_t material, uint32_t mesh, uint32_t triangle, const Vec3& direction,
                         float coneWidth) {
  const Material& m = scene.materials[material];
  if (m.albedoTexture < 0) return kFullResolution;
  return albedoTextureLod(scene.meshes[mesh], triangle, scene.textures[size_t(m.albedoTexture)], m.albedoMapping, direction,
                          coneWidth);
}

/// One step of an ideal-specular chain at `hit` (a specular chart: a mirror or glass) of
/// `ray`, the step every light-field stage takes — gather rays in the visibility field, view
/// rays in the reference and the fast renderer. `emitted` gets the surface's own emission
/// towards the arriving ray; then, if `step` (the reflections/refractions already followed in
/// this chain, 0 at the first specular hit) is below `stepLimit`, `next` is the reflected or
/// refracted ray (offset off the surface) and `weight` its throughput.
///  * Mirrors: the BSDF's delta sample (Schlick Fresnel when the material asks for it), with
///    the frame facing the arriving ray (two-sided, as in the path tracer).
///  * Mirror-like lobes (a Blinn-Phong or GGX model without a diffuse part whose lobe is too
///    narrow for a map, bake/parameterisation.h isMirrorLike): a direction importance-sampled
///    from the lobe with the two numbers specularLobeU, weight f·cos θ/pdf — one sample per
///    ray, so, like glass's branches, unbiased over pixels, samples or gather directions.
///  * Glass (DielectricBsdf, frame unflipped: +z outside): reflection or refraction is chosen
///    stochastically with the BSDF's own probabilities (Fresnel F for solid glass, R'/(R'+T')
///    by luminance for thin sheets), so the weight is the branch's reflectance or radiance
///    transmittance over its probability: 1 for reflection, t/η'² for refraction. The random
///    number is a hash of the arriving ray's bits (specularBranchU): deterministic, identical
///    in every stage that traces the same ray, and decorrelated between rays, so averages
///    over pixels, samples or gather directions are unbiased. Rough glass is a glossy chart
///    (lightfield.h "Rough glass"), so chains end there; only a light field baked before
///    that has it as a specular chart, and it is then followed as smooth, as that bake did.
///  * A segment that arrives on the inside (back) of glass ran through it: `weight` and
///    `emitted` include its Beer–Lambert attenuation exp(−σa t).
///  * From step kSpecularRouletteStep on, the chain survives with probability
///    q = min(1, max channel of the weight) and the weight is divided by q (Russian roulette,
///    unbiased), drawn with a second hash of the ray's bits (specularRouletteU). Chains up to
///    that length cost what they did with a hard cut there; longer ones (light circling inside
///    a glass ball by near-total internal reflection, mirror corridors) go on to `stepLimit`.
/// Returns false when the chain ends here (step limit, roulette, no delta lobe, a direction
/// on the wrong side of the geometric surface at grazing angles). `sampled`, when given, gets
/// how `next` was chosen (SpecularStep), for the renderers' MIS at mirror-like lobes.
/// `lobeSample` k > 0 draws a mirror-like lobe's direction with specularLobeU(ray, k) instead:
/// the k-th of several stratified samples at one hit (firstHitLobeSamples).
struct SpecularStep;
bool followSpecular(const Scene& scene, const Ray& ray, const RayHit& hit, uint32_t step, uint32_t stepLimit,
                    Rgb& emitted, Ray& next, Rgb& weight, SpecularStep* sampled = nullptr, uint32_t lobeSample = 0);

/// How one followSpecular step chose its continued ray.
struct SpecularStep {
  /// The solid-angle density (sr⁻¹) of the continued direction when a mirror-like lobe
  /// sampled it; 0 after a delta step (mirror, glass), a direction no light sample can take.
  float lobePdf = 0.0f;
  /// A straight pass through a thin glass sheet (direction unchanged; shadow rays pass such
  /// sheets too), which keeps the density of the direction sampled before it.
  bool straightThrough = false;
};

/// The MIS state of a view ray along a specular chain (MirrorLikeLights): the density with
/// which a mirror-like lobe sampled its direction (0: the camera ray, or a delta step) and the
/// distance travelled since the vertex that sampled it (straight passes through thin sheets
/// keep both, as in the path tracer).
struct LobeChain {
  float pdf = 0.0f;
  float distance = 0.0f;  ///< scene units, up to the ray's origin
  /// The chain after a followSpecular step at a hit `hitDistance` along the current ray.
  LobeChain after(const SpecularStep& step, float hitDistance) const {
    return step.straightThrough ? LobeChain{pdf, distance + hitDistance} : LobeChain{step.lobePdf, 0.0f};
  }
};

/// A specular chart record of a glossy model: a mirror-like lobe (bake/parameterisation.h
/// isMirrorLike), not a mirror or glass.
bool isMirrorLikeRecord(const Chart& c, const Bsdf& model);

/// Splitting at a view ray's first hit when it is a mirror-like lobe. A traced lobe's noise is
/// that of the path tracer's chains of reflections: rare, bright samples (a sample in one
/// lobe's tail that finds the lamp's reflection in the next metal surface, and so on down the
/// chain). At that first hit the renderers take kFirstHitLobeSamples stratified lobe samples
/// (followSpecular's lobeSample k: specularLobeU), each with its own light sample, stratified
/// too (MirrorLikeLights, nextEventU(ray, k)), each of weight 1/kFirstHitLobeSamples and
/// followed to its chain's end: the pixels that see such a lobe get that many chains per camera sample, the others none
/// more (unlike more samples per pixel). 1 elsewhere (mirrors, glass, later hits).
inline constexpr uint32_t kFirstHitLobeSamples = 8;
uint32_t firstHitLobeSamples(const LightField& lf, uint32_t chart);

/// The chain step from which followSpecular plays Russian roulette on the branch weight.
inline constexpr uint32_t kSpecularRouletteStep = 8;

/// The uniform number in [0, 1) that followSpecular draws its branch with for `ray`.
float specularBranchU(const Ray& ray);

/// The two uniform numbers in [0, 1) with which followSpecular samples a mirror-like lobe for
/// `ray` (a second hash of its bits: independent of the branch and the roulette); sample k > 0
/// of a split (firstHitLobeSamples) is point k of the 2-D Sobol sequence rotated by sample 0's
/// numbers (lookup.cpp rayHashU2), so the split's samples are stratified over the lobe.
Vec2 specularLobeU(const Ray& ray, uint32_t sample = 0);

/// The uniform number in [0, 1) that followSpecular plays its roulette with for `ray`
/// (other bits of the same hash as specularBranchU: independent of the branch).
float specularRouletteU(const Ray& ray);

/// The two uniform numbers in [0, 1) of the light sample MirrorLikeLights takes at the hit of
/// `ray` (a third hash of its bits: independent of the lobe's own sample there); sample k > 0
/// of a split is stratified as specularLobeU's.
Vec2 nextEventU(const Ray& ray, uint32_t sample = 0);

struct SunLights;

/// The per-chart constants of exitantRadiance (its material's emission and, when no texture
/// varies it, its diffuse albedo). The fast renderer (src/realtime) precomputes one per chart;
/// the plain exitantRadiance below builds it on the fly, so both run the same formula.
struct ChartShading {
  Lanes4 emission;                ///< Le of the chart's material (W·sr⁻¹·m⁻²), as lanes r, g, b, 0
  Lanes4 albedoOverPi;            ///< diffuse albedo / π when !texturedAlbedo (diffuse charts, glossy diffuseValue ones)
  float inverseTixelSize = 1.0f;  ///< 1 / chart.tixelSize (tixelGridCoordinates)
  bool emissive = false;          ///< emission is not black
  bool twoSidedEmission = false;
  bool texturedAlbedo = false;    ///< diffuse albedo varies over the surface (Material::modelVaries): diffuseAlbedoAt per point
  /// An emissive diffuse chart with an emission texture: its emission × AlbedoPoint::emission
  /// per point (a glossy chart's stored values carry its tixels' mean emission instead).
  bool texturedEmission = false;
  bool needsUv = false;           ///< a diffuse (or diffuseValue glossy) chart whose albedo varies, or a texturedEmission one: the lookup needs the hit's AlbedoPoint
  /// A normal-mapped glossy chart (lookupDirection bends the lookup by the hit's mapped normal)
  /// or directionalIrradiance diffuse chart (the irradiance is taken about it): lookupInputs
  /// needs surfaceAt's shading normal.
  bool normalMapped = false;
  /// A curved glossy chart: its map is read in the frame around the hit's interpolated normal
  /// (chartShadingNormalAt), so the lookup needs the hit's triangle and barycentrics.
  bool curvedGlossy = false;
  /// Sun masks (lightfield.h): on a diffuse chart of a light field that has them, the masks
  /// of the chart's tixel (0, 0) and the masked lights; the lookup adds those lights'
  /// irradiance through the masks (sunIrradianceLanes). Null otherwise.
  const SunMask* sunMasks = nullptr;
  const SunLights* sun = nullptr;
};

/// The lights a light field's sun masks stand for (LightField::sunMaskLightCount of
/// sunMaskLights(scene)): unit direction towards each and its irradiance (W·m⁻²) on a surface
/// facing it.
struct SunLights {
  uint32_t count = 0;
  std::array<Vec3, kMaxSunMaskLights> towardsLight{};
  std::array<Lanes4, kMaxSunMaskLights> irradiance{};  ///< r, g, b, 0 (one load per lookup)
};
SunLights sunLightsOf(const LightField& lf);

/// The lookup's precomputed shading of chart record `chart` of lf; `sun` (sunLightsOf(lf)) must
/// outlive it.
ChartShading chartShading(const LightField& lf, uint32_t chart, const SunLights& sun);

/// Whether the lookup needs the hit's interpolated normal on chart c: curved glossy charts
/// (their maps), curved diffuse charts with sun masks (the masked lights' cos θ) or tilted
/// irradiances (their frame).
inline bool needsInterpolatedNormal(const Chart& c, const ChartShading& shading) {
  return shading.curvedGlossy || (c.curved && (shading.sunMasks != nullptr || c.directionalIrradiance));
}

/// The masked lights' irradiance (W·m⁻², lanes r, g, b, 0) at grid position `grid` of diffuse
/// chart c (tixelGridCoordinates) on a surface with unit normal `normal` (the chart's, or on a
/// curved chart the interpolated normal at the point): Σ_l E_l·max(0, n·ω_l)·V_l(grid), V_l the
/// bilinear mask visibility (sunVisibility). Zero without masks. With a mapped normal n'
/// (a directionalIrradiance chart) the cosine is max(0, n'·ω_l), for lights above the
/// surface's normal n only, as the path tracer's sidedness rule has it.
inline F4 sunIrradianceLanes(const Chart& c, const ChartShading& shading, Vec2 grid, const Vec3& normal,
                             const Vec3& mappedNormal) {
  F4 sum = f4Zero();
  if (shading.sunMasks == nullptr) return sum;
  const SunLights& sun = *shading.sun;
  for (uint32_t l = 0; l < sun.count; ++l) {
    if (!(glm::dot(normal, sun.towardsLight[l]) > 0.0f)) continue;
    const float cosTheta = glm::dot(mappedNormal, sun.towardsLight[l]);
    if (!(cosTheta > 0.0f)) continue;
    const float lit = sunVisibility(shading.sunMasks, sun.count, l, c, grid);
    if (lit > 0.0f) sum = f4Add(sum, f4Mul(f4Load(sun.irradiance[l].v), f4Splat(cosTheta * lit)));
  }
  return sum;
}

/// The direction to look a glossy chart up in, for a viewer towards wo (unit, world) at a
/// point whose shading normal n' (normal-mapped, surfaceAt) differs from the normal n its map
/// is stored around there (mapNormal: the chart normal, or on a curved chart the interpolated
/// normal at the point, chartShadingNormalAt). The value stored towards d is the glossy
/// reflection of light arriving around d mirrored about n; the normal-mapped surface reflects
/// light arriving around wo mirrored about n'. So d = mirror about n of (wo mirrored about n'),
/// which moves the highlight as the normal map says. wo itself when d would fall behind n
/// (grazing tilts).
Vec3 normalMappedLookupDirection(const Vec3& mapNormal, const Vec3& shadingNormal, const Vec3& wo);

/// The unit normal chart c's lookup takes at barycentrics (b1, b2) of triangle `triangle` of
/// mesh `mesh` (exitantRadianceLanes' lookupNormal: a glossy map is read around it, the sun
/// masks' lights shine on it): chartShadingNormalAt where needsInterpolatedNormal, the chart
/// normal otherwise.
inline Vec3 lookupNormalAt(const Scene& scene, const Chart& c, const ChartShading& shading, uint32_t mesh,
                           uint32_t triangle, Vec2 barycentrics) {
  return needsInterpolatedNormal(c, shading) ? chartShadingNormalAt(c, scene.meshes[mesh], triangle, barycentrics)
                                             : c.normal;
}

/// What exitantRadianceLanes needs of a ray's hit on chart c besides the position: the uv
/// and mip level (for an albedo texture: albedoLodAt with the ray's cone width `coneWidth`
/// at the hit), the normal the glossy map is read around (the chart normal; on a curved
/// glossy chart the interpolated normal at the hit, chartShadingNormalAt) and the mapped
/// normal (surfaceAt's shading normal, turned to the record's side, on a normal-mapped chart:
/// ChartShading::normalMapped; lookupNormal elsewhere). surfaceAt is evaluated only where the
/// chart's shading needs it.
inline void lookupInputs(const Scene& scene, const Chart& c, const ChartShading& shading, const RayHit& hit,
                         const Vec3& towardsViewer, float coneWidth, AlbedoPoint& albedo, Vec3& lookupNormal,
                         Vec3& mappedNormal) {
  albedo = AlbedoPoint{};
  lookupNormal = lookupNormalAt(scene, c, shading, hit.mesh, hit.triangle, hit.barycentrics);
  mappedNormal = lookupNormal;
  const bool glossyMapped = shading.normalMapped && c.kind == ChartKind::Glossy;
  if (shading.needsUv) {
    albedo = albedoPointAt(scene, hit.mesh, hit.triangle, hit.barycentrics);
    // A normal-mapped glossy chart reads its albedo at full resolution (its surfaceAt below).
    if (!glossyMapped) albedo.lod = albedoLodAt(scene, c.material, hit.mesh, hit.triangle, -towardsViewer, coneWidth);
  }
  if (!shading.normalMapped) return;
  const SurfaceHit surface = surfaceAt(scene, hit.mesh, hit.triangle, hit.barycentrics);
  mappedNormal = c.isBack ? -surface.shadingNormal : surface.shadingNormal;
}

/// The cos θ towards the viewer that the lookups use on a curved chart record. Its triangles
/// face up to the cone bound away from the chart normal, so the chart normal cannot tell the
/// side; the caller's viewedChart has turned a two-sided surface to the record the viewer is
/// in front of and left out a one-sided record seen from behind (by the hit triangle's
/// normal), so the record reflects.
inline constexpr float kCurvedChartCosine = 1.0f;

/// Exitant radiance (W·sr⁻¹·m⁻²) of chart `chart` at worldPosition towards the viewer:
///   diffuse chart:  Le + albedo(uv)·E/π with E bilinearly interpolated over the 2×2 nearest
///                   tixels and the albedo texture read at `uv`, at full resolution (this
///                   overload has no ray cone);
///   glossy chart:   the 16-neighbour interpolation of the stored exitant radiance (this
///                   overload has no triangle: on a curved glossy chart it reads the maps in
///                   the frame around the chart normal, an approximation — ray hits go through
///                   the SurfaceHit overload, which uses the hit's interpolated normal);
///   specular chart: 0 — the caller follows the mirrored ray (reordering) and looks up what it
///                   sees.
/// `chart` may be any record; a viewer behind a front record is turned to its back record
/// (facingChart). Behind a one-sided chart (the inside of a closed mesh) nothing is reflected:
/// the viewer sees only emission, if the material emits on both sides — the rule the bake's
/// gather rays follow (lightfield.h "Sides").
Rgb exitantRadiance(const LightField& lf, uint32_t chart, const Vec3& worldPosition,
                    const Vec3& worldDirectionTowardsViewer, Vec2 uv);

/// The same for a ray hit at worldPosition (chart from lf.triangleChart and viewedChart; uv,
/// mip level and normals from lookupInputs: surfaceAt only where the chart needs it), the
/// albedo texture read at the mip level of a ray cone `coneWidth` wide at the hit (scene
/// units; albedoLodAt; 0 = full resolution).
Rgb exitantRadiance(const LightField& lf, const RayHit& hit, const Vec3& worldPosition,
                    const Vec3& worldDirectionTowardsViewer, float coneWidth);

/// exitantRadiance given the chart's precomputed shading and the values read through `load`
/// (RgbValues over LightField::values, or PaddedValues): the one implementation every caller
/// goes through, as four lanes (r, g, b, 0). Defined inline so that the fast renderer's
/// per-pixel loop inlines it instead of calling across files. lookupNormal: lookupNormalAt's
/// normal at worldPosition (lookupInputs): a curved glossy chart's map is read around it, a
/// curved diffuse chart's sun-masked lights shine on it. mappedNormal: a normal-mapped chart's
/// mapped normal (lookupInputs; lookupNormal on other charts). worldDirectionTowardsViewer: the
/// unit direction towards the viewer (a normal-mapped glossy chart bends its lookup itself). albedo: where, at which
/// mip level and with which vertex colour a diffuse chart's albedo is read (lookupInputs).
template <typename Load>
inline F4 exitantRadianceLanes(const Scene& scene, const Chart& c, const ChartShading& shading, const Load& load,
                               const Vec3& worldPosition, const Vec3& worldDirectionTowardsViewer,
                               const Vec3& lookupNormal, const Vec3& mappedNormal, const AlbedoPoint& albedo) {
  if (c.kind == ChartKind::Specular) return f4Zero();
  const Vec2 grid = tixelGridCoordinates(c, worldPosition, shading.inverseTixelSize);
  // cos θ towards the viewer (chartLocalDirection's z; a diffuse lookup needs no more of it).
  // A curved chart (diffuse or glossy, never emissive: parameterisation.h) has no single normal: the
  // caller's viewedChart chose its side by the hit triangle's normal, and it reflects
  // (cos θ taken as 1, see kCurvedChartCosine).
  const float cosTheta = c.curved ? kCurvedChartCosine : glm::dot(worldDirectionTowardsViewer, c.normal);
  // chartEmittedRadiance (lightfield.h) on the precomputed emission of this record (× the
  // emission texture at the point on a texturedEmission chart).
  const bool emits = cosTheta > 0.0f || shading.twoSidedEmission;
  const F4 emission = shading.texturedEmission ? f4Mul(f4Load(shading.emission.v), f4FromRgb(albedo.emission))
                                               : f4Load(shading.emission.v);
  // Behind a one-sided record: no reflected light (the caller turned two-sided ones with
  // facingChart), only two-sided emission.
  if (!(cosTheta >= 0.0f)) return shading.emissive && emits ? emission : f4Zero();
  if (c.kind == ChartKind::Diffuse) {
    // Le + (albedo/π) · E, lane by lane; E = the stored irradiance plus the sun masks' lights,
    // about the mapped normal on a directionalIrradiance chart.
    F4 stored = interpolateLanes(load, c, grid, Vec2(0.0f));
    if (c.directionalIrradiance) {
      // The path tracer's Lambertian lobe reflects only towards viewers above the mapped
      // normal (bsdf.cpp sameHemisphereUp in the shading frame).
      if (!(glm::dot(worldDirectionTowardsViewer, mappedNormal) > 0.0f))
        return shading.emissive && emits ? emission : f4Zero();
      stored = mappedNormalIrradiance(load, c, grid, stored, tiltFrameAround(c, lookupNormal).toLocal(mappedNormal));
    }
    const F4 irradiance = f4Add(stored, sunIrradianceLanes(c, shading, grid, lookupNormal, mappedNormal));
    const F4 albedoOverPi = shading.texturedAlbedo ? f4Mul(f4FromRgb(diffuseAlbedoAt(scene, c.material, albedo)), f4Splat(kInvPi))
                                                   : f4Load(shading.albedoOverPi.v);
    const F4 reflected = f4Mul(albedoOverPi, irradiance);
    return shading.emissive && emits ? f4Add(emission, reflected) : reflected;
  }
  // Glossy: the stored values already include the record's emission. On a normal-mapped
  // chart the path tracer's model reflects only towards viewers above the mapped normal
  // (bsdf.cpp sameHemisphereUp in the shading frame), and the map is read in the direction
  // bent by the normal map (normalMappedLookupDirection).
  Vec3 lookup = worldDirectionTowardsViewer;
  if (shading.normalMapped) {
    if (!(glm::dot(worldDirectionTowardsViewer, mappedNormal) > 0.0f))
      return shading.emissive && emits ? f4Load(shading.emission.v) : f4Zero();
    lookup = normalMappedLookupDirection(lookupNormal, mappedNormal, worldDirectionTowardsViewer);
  }
  // The direction in the map's frame (tixelFrameAround: the chart frame, chartLocalDirection's
  // formula, on a planar chart; on a curved one the frame around the interpolated normal here,
  // which varies continuously over the chart and is within a tixel of each interpolated
  // tixel's gather frame). A direction below that normal (a silhouette of a smooth mesh, where
  // the shading normal turns away from a viewer the triangle still faces) reads the horizon
  // texels.
  const Vec3 local = tixelFrameAround(c, lookupNormal).toLocal(lookup);
  const F4 mapped = interpolateLanes(load, c, grid, directionToParaboloid(local));
  if (!c.diffuseValue) return mapped;
  // Plus the diffuse part, ρ(uv)/π · k(μo) · Ẽ (lightfield.h), with Ẽ bilinear over the tixels
  // (on a directionalIrradiance chart: about the mapped normal).
  F4 irradiance = bilinearOverTixels(c, grid, [&](uint32_t i, uint32_t j) { return load(c.diffuseValueIndex(i, j)); });
  if (c.directionalIrradiance)
    irradiance = mappedNormalIrradiance(load, c, grid, irradiance, tiltFrameAround(c, lookupNormal).toLocal(mappedNormal));
  // k(μo), μo against the mapped normal on a normal-mapped chart (the path tracer's shading frame).
  const float cosViewer = shading.normalMapped ? glm::dot(worldDirectionTowardsViewer, mappedNormal) : local.z;
  if (shading.texturedAlbedo && scene.materials[c.material].metallicRoughness.texture >= 0)
    return f4Add(mapped, f4Mul(f4FromRgb(glossyDiffuseReflectanceAt(scene, c.material, albedo, cosViewer)), irradiance));
  const F4 albedoOverPi = shading.texturedAlbedo
                              ? f4Mul(f4FromRgb(glossyDiffuseAlbedoAt(scene, c.material, albedo)), f4Splat(kInvPi))
                              : f4Load(shading.albedoOverPi.v);
  const F4 factor = f4FromRgb(diffuseDirectionalFactor(scene.materials[c.material].bsdf, cosViewer));
  return f4Add(mapped, f4Mul(f4Mul(albedoOverPi, factor), irradiance));
}
template <typename Load>
inline Rgb exitantRadiance(const Scene& scene, const Chart& c, const ChartShading& shading, const Load& load,
                           const Vec3& worldPosition, const Vec3& worldDirectionTowardsViewer, const Vec3& lookupNormal,
                           const Vec3& mappedNormal, const AlbedoPoint& albedo) {
  return f4Rgb(exitantRadianceLanes(scene, c, shading, load, worldPosition, worldDirectionTowardsViewer, lookupNormal,
                                    mappedNormal, albedo));
}
/// Four light-field lookups on one diffuse chart that is not directionalIrradiance (one value
/// per tixel; callers send those through exitantRadianceLanes): the camera rays origin + t·direction
/// (structure of arrays: x[k], y[k], z[k] for lookups k = 0…3), seen against their directions,
/// at albedo points albedo[k] (uv, mip level, vertex colour; read only when the chart's albedo
/// varies, shading.needsUv), and — on a curved chart with sun masks, where the masked lights shine on
/// the interpolated normal — at lookupNormals[k] (lookupNormalAt; null: the chart normal).
/// result[k] = exitantRadianceLanes(…, origin_k + t_k·direction_k, −direction_k, albedo[k]) to the
/// bit — the same IEEE operations lane by lane, with the four lookups in the four SSE lanes
/// for everything up to the value reads (the fast renderer's common case, where a dependent
/// chain of ~40 scalar operations per pixel would otherwise dominate).
struct RaysSoA4 {
  alignas(16) float ox[4], oy[4], oz[4], dx[4], dy[4], dz[4], t[4];
};
inline void exitantRadianceDiffuse4(const Scene& scene, const Chart& c, const ChartShading& shading, const Lanes4* values,
                                    const RaysSoA4& r, const AlbedoPoint albedo[4], F4 result[4],
                                    const Vec3* lookupNormals = nullptr) {
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), half = _mm_set1_ps(0.5f);
  const __m128 t = _mm_load_ps(r.t), dx = _mm_load_ps(r.dx), dy = _mm_load_ps(r.dy), dz = _mm_load_ps(r.dz);
  // Position o + t·d, then d − chart origin (tixelGridCoordinates).
  const __m128 px = _mm_sub_ps(_mm_add_ps(_mm_load_ps(r.ox), _mm_mul_ps(t, dx)), _mm_set1_ps(c.origin.x));
  const __m128 py = _mm_sub_ps(_mm_add_ps(_mm_load_ps(r.oy), _mm_mul_ps(t, dy)), _mm_set1_ps(c.origin.y));
  const __m128 pz = _mm_sub_ps(_mm_add_ps(_mm_load_ps(r.oz), _mm_mul_ps(t, dz)), _mm_set1_ps(c.origin.z));
  auto dot = [&](const Vec3& axis) {  // glm::dot's order: (x·ax + y·ay) + z·az
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(px, _mm_set1_ps(axis.x)), _mm_mul_ps(py, _mm_set1_ps(axis.y))),
                      _mm_mul_ps(pz, _mm_set1_ps(axis.z)));
  };
  const __m128 inverse = _mm_set1_ps(shading.inverseTixelSize);
  const __m128 gridU = _mm_sub_ps(_mm_mul_ps(dot(c.axisU), inverse), half);
  const __m128 gridV = _mm_sub_ps(_mm_mul_ps(dot(c.axisV), inverse), half);
  // cos θ = dot(−d, normal).
  const __m128 sign = _mm_set1_ps(-0.0f);
  const __m128 cosTheta = _mm_add_ps(
      _mm_add_ps(_mm_mul_ps(_mm_xor_ps(dx, sign), _mm_set1_ps(c.normal.x)), _mm_mul_ps(_mm_xor_ps(dy, sign), _mm_set1_ps(c.normal.y))),
      _mm_mul_ps(_mm_xor_ps(dz, sign), _mm_set1_ps(c.normal.z)));
  // linearTap, lane by lane (see its comment for the case list).
  struct Taps {
    alignas(16) uint32_t i0[4], i1[4];
    alignas(16) float w0[4], w1[4];  // 1 − f, f
  };
  auto taps = [&](__m128 x, uint32_t count) {
    const uint32_t last = count - 1;
    const __m128 positive = _mm_and_ps(_mm_cmpgt_ps(x, zero), x);  // NaN → 0
    const __m128 clamped = _mm_min_ps(positive, _mm_set1_ps(float(last)));
    const __m128i i0 = _mm_cvttps_epi32(clamped);
    const __m128i next = _mm_sub_epi32(i0, _mm_castps_si128(_mm_cmpgt_ps(clamped, zero)));  // + [clamped > 0]
    const __m128i lastI = _mm_set1_epi32(int(last));
    const __m128i below = _mm_cmplt_epi32(next, lastI);
    const __m128i i1 = _mm_or_si128(_mm_and_si128(below, next), _mm_andnot_si128(below, lastI));
    const __m128 f = _mm_sub_ps(clamped, _mm_cvtepi32_ps(i0));
    Taps out;
    _mm_store_si128(reinterpret_cast<__m128i*>(out.i0), i0);
    _mm_store_si128(reinterpret_cast<__m128i*>(out.i1), i1);
    _mm_store_ps(out.w0, _mm_sub_ps(one, f));
    _mm_store_ps(out.w1, f);
    return out;
  };
  const Taps u = taps(gridU, c.resU), v = taps(gridV, c.resV);
  // The sun masks' lights, lookup by lookup (the scalar sunIrradianceLanes on the same grid
  // coordinates and the same normals: lookupNormalAt's, which a curved chart's caller passes).
  F4 sunIrradiance[4] = {f4Zero(), f4Zero(), f4Zero(), f4Zero()};
  if (shading.sunMasks != nullptr) {
    alignas(16) float gu[4], gv[4];
    _mm_store_ps(gu, gridU);
    _mm_store_ps(gv, gridV);
    for (int k = 0; k < 4; ++k)
      sunIrradiance[k] = sunIrradianceLanes(c, shading, Vec2(gu[k], gv[k]), lookupNormals ? lookupNormals[k] : c.normal,
                                            lookupNormals ? lookupNormals[k] : c.normal);
  }
  // bit k: cos θ_k > 0, and cos θ_k ≥ 0 (a curved chart: kCurvedChartCosine > 0 in every lane).
  const int frontSide = c.curved ? 0xf : _mm_movemask_ps(_mm_cmpgt_ps(cosTheta, zero));
  const int reflectingSide = c.curved ? 0xf : _mm_movemask_ps(_mm_cmpge_ps(cosTheta, zero));
  const F4 emission = f4Load(shading.emission.v);
  // exitantRadianceLanes' albedo / π, per lookup when textured (one branch for all four).
  F4 albedoOverPi[4];
  if (shading.texturedAlbedo)
    for (int k = 0; k < 4; ++k) albedoOverPi[k] = f4Mul(f4FromRgb(diffuseAlbedoAt(scene, c.material, albedo[k])), f4Splat(kInvPi));
  else
    albedoOverPi[0] = albedoOverPi[1] = albedoOverPi[2] = albedoOverPi[3] = f4Load(shading.albedoOverPi.v);
  for (int k = 0; k < 4; ++k) {
    // interpolateLanes' diffuse branch and exitantRadianceLanes' diffuse return, for lookup k.
    const uint64_t row0 = c.firstValue + uint64_t(v.i0[k]) * c.resU, row1 = c.firstValue + uint64_t(v.i1[k]) * c.resU;
    const F4 lower = f4Add(f4Mul(f4Splat(u.w0[k] * v.w0[k]), f4Load(values[row0 + u.i0[k]].v)),
                           f4Mul(f4Splat(u.w1[k] * v.w0[k]), f4Load(values[row0 + u.i1[k]].v)));
    const F4 upper = f4Add(f4Mul(f4Splat(u.w0[k] * v.w1[k]), f4Load(values[row1 + u.i0[k]].v)),
                           f4Mul(f4Splat(u.w1[k] * v.w1[k]), f4Load(values[row1 + u.i1[k]].v)));
    const F4 reflected = f4Mul(albedoOverPi[k], f4Add(f4Add(lower, upper), sunIrradiance[k]));
    const bool front = ((frontSide >> k) & 1) != 0;
    // As exitantRadianceLanes: cos θ = 0 reflects but emits only if two-sided; NaN neither.
    const bool reflects = ((reflectingSide >> k) & 1) != 0;
    const bool emits = front || shading.twoSidedEmission;
    const F4 seen = reflects ? reflected : f4Zero();
    const F4 le = shading.texturedEmission ? f4Mul(emission, f4FromRgb(albedo[k].emission)) : emission;
    result[k] = shading.emissive && emits ? f4Add(le, seen) : seen;
  }
#else
  for (int k = 0; k < 4; ++k) {
    const Vec3 d(r.dx[k], r.dy[k], r.dz[k]);
    const Vec3 normal = lookupNormals ? lookupNormals[k] : c.normal;
    result[k] = exitantRadianceLanes(scene, c, shading, PaddedValues{values}, Vec3(r.ox[k], r.oy[k], r.oz[k]) + r.t[k] * d, -d,
                                     normal, normal, albedo[k]);
  }
#endif
}

/// The direct glossy reflection of the delta lights (light/lights.h isDeltaLight) that a
/// light field baked with punctual highlights (BakeSettings::punctualHighlights) keeps out of
/// its glossy maps, evaluated where a glossy surface is seen (lightfield.h "Punctual
/// highlights"): at a hit on a reflecting glossy chart record,
///   Σ_l f(wo, wi_l) · E_l · |cos θ_l| · T_l
/// with f the chart's model without its diffuse part when the chart keeps Ẽ (Chart::
/// diffuseValue; the model the maps hold otherwise) — with a metallic-roughness texture the
/// hit point's own model (materialModelAt), as in the path tracer — in the scattering frame
/// of the shading normal at the hit (normal map included), E_l the light's irradiance normal to wi_l and T_l
/// its shadow ray's transmittance (ShadowRays) — the path tracer's next-event estimation of
/// that light, term for term. Both renderers add it to their lookups. Mirror-like charts
/// (Specular records of a glossy model, bake/parameterisation.h isMirrorLike), which no
/// sampled ray can take a delta light's light to, get theirs too, whatever the setting.
class PunctualHighlights {
 public:
  /// lf and accel must outlive it.
  PunctualHighlights(const LightField& lf, const Accel& accel);
  /// Whether there is anything to add: the light field was baked with punctual highlights or
  /// has mirror-like charts, and its scene has delta lights.
  bool active() const { return !lights_.empty(); }
  /// The highlights on chart record `chart` (the record the viewer sees: viewedChart) at ray
  /// hit `hit`, towards the unit direction `towardsViewer`; 0 on other kinds, mirrors, glass.
  Rgb radiance(uint32_t chart, const RayHit& hit, const Vec3& towardsViewer) const;

 private:
  const LightField& lf_;
  bool glossyCharts_ = false;  ///< the glossy charts' highlights too (BakeSettings::punctualHighlights)
  std::vector<Light> lights_;  ///< the scene's delta lights
  std::optional<ShadowRays> shadows_;
  std::vector<Bsdf> withoutDiffuse_;  ///< per material
};

/// Next-event estimation of the emissive surfaces and the sky at the hits of mirror-like
/// lobes (Specular records of a glossy model, bake/parameterisation.h isMirrorLike), which the
/// renderers otherwise find only by the lobe's own sample: a small lamp in a metal's lobe
/// would then be fireflies. As the path tracer does, each mirror-like hit of a view ray takes
/// one light sample (light/light.h nextEventEstimate, the numbers nextEventU of the arriving
/// ray), weighted by the power heuristic against the lobe's density, and the emission the
/// lobe's sampled ray then finds — on an emitter's chart, a mirror-like or mirror chart, or the
/// sky — is weighted by the power heuristic the other way (emissionWeight,
/// environmentWeight). Sphere lights, which are no geometry, are sampled here too and found
/// by the lobe's sampled rays as they pass through them (sphereEmission), the two weighted by
/// the power heuristic as for the emissive surfaces (the path tracer counts their light sample
/// in full and no ray finds them, an estimator equal in the mean, but a sharp lobe is then
/// found by its light samples alone, as fireflies); a sample that chooses a point, spot or
/// directional light counts 0 (NextEvent::MisExceptDelta): PunctualHighlights adds those.
/// Inactive (nothing added, every weight 1) without mirror-like charts or without emissive
/// triangles, a lit sky and sphere lights.
class MirrorLikeLights {
 public:
  /// lf and accel must outlive it.
  MirrorLikeLights(const LightField& lf, const Accel& accel);
  bool active() const { return sampler_.has_value(); }
  /// The MIS-weighted light sample at record `chart` (any record of the hit triangle's chart)
  /// where `ray` hits it at `hit`; 0 unless it is mirror-like. `sample`: nextEventU's.
  Rgb radiance(uint32_t chart, const Ray& ray, const RayHit& hit, uint32_t sample = 0) const;
  /// The weight of the emission that `ray`, continued along `chain`, finds at `hit`: the power
  /// heuristic of the lobe's density against the light sampler's for that point of the
  /// emitter (1 when chain.pdf is 0 or inactive).
  float emissionWeight(const Ray& ray, const RayHit& hit, const LobeChain& chain) const;
  /// The same for the sky that `direction` (unit) leaves the scene in.
  float environmentWeight(const Vec3& direction, const LobeChain& chain) const;
  /// The MIS-weighted emission of the sphere light that `ray`, continued along `chain`, enters
  /// before `tHit` (its hit's distance, kInfinity when it leaves the scene): 0 when chain.pdf
  /// is 0 (a camera ray or a delta step: the camera and mirrors show no sphere, as in the path
  /// tracer), else Le times the power heuristic of the lobe's density against the light
  /// sample's from the lobe's vertex.
  Rgb sphereEmission(const Ray& ray, float tHit, const LobeChain& chain) const;
  /// The part of the emission a lookup at `hit` counts that next-event estimation at the
  /// chain's mirror-like hit counted already: (1 − emissionWeight) · Le there, towards the
  /// viewer, its emission texture included (0 when chain.pdf is 0 or inactive).
  Rgb overcountedEmission(const Ray& ray, const RayHit& hit, const LobeChain& chain) const;

 private:
  const LightField& lf_;
  std::optional<LightSampler> sampler_;
  std::optional<ShadowRays> shadows_;
};

inline Rgb exitantRadiance(const Scene& scene, const Chart& c, const ChartShading& shading, const Rgb* values,
                           const Vec3& worldPosition, const Vec3& worldDirectionTowardsViewer, const Vec3& lookupNormal,
                           const Vec3& mappedNormal, const AlbedoPoint& albedo) {
  return exitantRadiance(scene, c, shading, RgbValues{values}, worldPosition, worldDirectionTowardsViewer, lookupNormal,
                         mappedNormal, albedo);
}

}  // namespace pl
