#pragma once
// The light field: the scene's exitant radiance discretised over its surfaces, as in the
// light-field seed (slides 9–17). This header is the data model shared by the bake (which
// fills it), the .plf file (which stores it) and the renderers (which look it up).
//
// Position: every chart (edge-connected triangles with one material) has an orthonormal frame
// (origin, axisU, axisV, normal) and a uniform grid of resU × resV tixels of side tixelSize
// (scene units) covering the bounding rectangle of its triangles projected along the normal
// onto the plane: tixel (i, j) has centre origin + (i + ½)·tixelSize·axisU + (j + ½)·tixelSize·axisV.
// A chart is planar (coplanar triangles) or, for diffuse and glossy materials that are not
// rough glass and do not emit, curved (`curved`: a smooth
// surface whose face normals stay within a bounded cone around the chart normal, so the
// projection along it is one-to-one; parameterisation.h "Curved charts"). A point on a curved
// chart maps to the grid by the same projection; its tixel size is set so that the most
// foreshortened triangle's tixels are still no larger than the preset's on the surface.
// Every tixel holds valid values, including those whose centre lies outside the polygon, so
// bilinear interpolation at polygon edges never reads garbage.
//
// Direction: a tixel's hemisphere (around the chart normal; on a curved chart around the
// tixel's own normal, in the frame tixelFrameAround gives it, and a lookup at a point in the
// frame around the interpolated normal there: chartShadingNormalAt) is a paraboloid map (seed
// slides 16–17): a local unit direction d (z along the normal) maps to
//     (s, t) = (d.x, d.y) / (1 + d.z)  ∈ unit disk ⊂ [−1, 1]²
// and back by d = (2s, 2t, 1 − s² − t²) / (1 + s² + t²). The dirRes × dirRes texels cover
// [−1, 1]²; texels outside the disk hold the value of the nearest horizon direction.
//
// What is stored per chart kind:
//   Diffuse   1 value per tixel: irradiance E (W·m⁻²; without the sun-masked directional
//             lights, which the lookup adds through the masks: "Sun masks" below). Outgoing radiance is
//             Le + albedo(uv)·E/π, with the albedo texture read by the renderers at the mip
//             level of the view ray's cone (lookup.h albedoTextureLod; the bake's transport
//             albedo is a full-resolution average over each tixel's footprint).
//             A subsurface chart (bake/subsurface.h) is a diffuse chart whose light enters
//             the object and leaves elsewhere: it stores M/ρ̄, M the exitance (W·m⁻²) the
//             subsurface operator sends out of the tixel and ρ̄ its transport albedo, so that
//             the same formula shows M/π (the albedo texture modulating it about ρ̄); its
//             sun masks are empty (the masked lights' light went through the object).
//   Glossy    dirRes² values per tixel: exitant radiance Lo (W·sr⁻¹·m⁻², emission included).
//             When the material has a diffuse part (diffuseValue: Blinn-Phong's or GGX's base
//             with a non-black diffuse albedo) the maps hold only the rest (the specular lobe
//             and emission), and one more value follows each tixel's map: the diffuse part's
//             irradiance Ẽ = ∫ L k(μi) cos θi dωi (W·m⁻²; k the model's diffuseDirectionalFactor,
//             1 for Blinn-Phong). The renderers add albedo(uv)/π · k(μo) · Ẽ, Ẽ bilinear over
//             the 2×2 nearest tixels and the albedo texture read as on a diffuse chart, so a
//             textured glossy material shows its texture (the bake's transport albedo of such
//             a tixel is, as on diffuse charts, the footprint mean of diffuse albedo × texel).
//             Rough glass (a DielectricBsdf with α ≥ kGgxMinAlpha, not thin) is a glossy
//             chart too, always two-sided (see "Rough glass" below).
//   Specular  nothing: an ideal mirror's or smooth glass's radiance is that of whatever the
//             mirrored/refracted direction sees (a reordering), followed at render time.
//
// Normal-mapped diffuse charts (directionalIrradiance). A normal map makes a Lambertian
// surface reflect ρ/π·E(n') with E(n') = ∫ L(ω) max(0, n'·ω) dω the irradiance about the
// mapped normal n' of each point (light from below the geometric surface never arrives), which
// varies within a tixel; one irradiance about the chart's normal n shows the surface flat, and
// too bright where n' turns away from the light. So such a chart's tixels keep, after E = E(n),
// the irradiances E_k = E(b_k) about kTiltedNormals normals tilted by β = kNormalTiltDegrees
// from n at azimuths φ_k = 0°, 120°, 240° (tiltedNormal: b_k = cos β·n + sin β·t_k in the
// tixel's tilt frame, tiltFrameAround). E(n') is taken as the model
//     E(n') ≈ E + a·(1 − n'_z) + g·n'_t        (n'_z along n, n'_t across it)
// fitted exactly to the four values: Ē = mean E_k gives a = (Ē − E)/(1 − cos β), and
// g = 2/(3 sin β)·Σ_k E_k·t_k (three unit vectors 120° apart: Σ_k (g·t_k)·t_k = 3/2·g).
// It is exact for light from one direction above every tilted horizon (a = −E, g = its
// tangential irradiance: E(n') = L·(n'·ω)) and for uniform light over the hemisphere (where
// E(n') = E·(1 + n'_z)/2: a = −E/2, g = 0), so both a lamp's shading of the bumps and the
// dimming of sky light on tilted facets come out right. tiltWeights gives the weights of E and
// the E_k for a normal. All four values are irradiances, never negative, so every value codec
// stores them. The renderers evaluate the model at each pixel's mapped normal (the sun-masked
// lights, below, directly at n'); the bake's transport at each tixel's footprint-mean mapped
// normal (the model is linear in n', so this is the footprint mean of E(n')), since a bumpy
// surface sends on less light than a flat one.
// A normal-mapped glossy chart with a diffuse part (diffuseValue) keeps its Ẽ the same way:
// Ẽ about n, then Ẽ_k = ∫ L k(b_k·ω) max(0, b_k·ω) dω about the tilted normals (k the
// model's diffuseDirectionalFactor, as in Ẽ), and the renderers take the diffuse part's
// irradiance from the same model at the mapped normal. (With k ≠ 1 the model is a fit, no
// longer exact for one direction, since k varies with the angle.) The glossy map stays as it
// is: its lookups follow the normal map (normalMappedLookupDirection, lookup.h).
//
// Sides (the light field's part of the sidedness rule; scatteringFrame in scene.h is the
// path tracer's, emittedRadiance there the emitters'). A reflecting surface scatters on both
// sides (scene.h), so a surface that can be seen and lit from behind stores its back side too:
// a chart with sides = 2 is followed in `charts` by a second record, its back side, with
// isBack set, the same material, kind, origin, axes, grid and dirRes and the normal negated
// (a left-handed frame: axisU × axisV = −normal; nothing relies on handedness). The back record
// has tixels and values of its own (stored like any chart's at its firstTixel / firstValue),
// gathers over the back hemisphere and is what a ray arriving from behind sees (facingChart).
// triangleChart maps triangles to the front record. Which charts get a back side is decided
// by the parameterisation (parameterisation.h: charts on open surfaces); a chart with sides = 1
// (the outside of a closed mesh, mirrors, smooth glass) reflects nothing towards its back: a ray from
// behind sees only two-sided emission.
//
// Rough glass (isRoughGlassChart): both records, always present (closed surfaces too: the back
// record of a glass ball is its inside), store the exitant radiance on their side, which is
// the reflection of the light their own gather rays bring plus the transmission of the light
// the other record's gather rays bring (propagation.cpp). The dielectric BSDF's frame is the
// front record's (+z = the outside, the geometric front: bsdf.h), so a back record's local
// directions are turned into it by negating z (glassBsdfDirection).
//
// Sun masks (refinement where the light changes fastest: the edges of sun shadows). A tixel
// samples the light at its gather point, and bilinear interpolation between tixel centres
// spreads a sun shadow's edge over a tixel (8 cm at Sponza's default density, where the path
// tracer's edge is a step). So for directional lights the light field keeps their visibility
// at 4 × 4 points per tixel: every tixel of a diffuse chart stores, per masked light
// (sunMaskLights: the scene's first kMaxSunMaskLights directional lights; none in a scene with
// thin glass, whose shadow rays carry a colour, not a bit), a 16-bit mask whose bit
// (b·kSunMaskSide + a) says whether the light reaches the tixel's footprint sub-sample (a, b)
// — the point at tixel coordinates (i + (a + ½)/4, j + (b + ½)/4) (a along axisU, b along
// axisV), the same sub-samples the parameterisation's coverage and albedo use. A diffuse
// tixel's stored irradiance E then *excludes* those lights' direct irradiance, and a lookup
// adds it back at the point: E_l·max(0, n·ω_l)·V_l, with V_l bilinear between the four
// nearest sub-sample bits (sunVisibility) — edges resolved to a quarter of a tixel. (The bake
// adds the same lights to the tixel's first shot as E_l·max(0, n_g·ω_l)·(set bits / 16): the
// footprint's mean instead of one ray from the gather point; removeSunMaskedDirect.)
//
// Punctual highlights. A delta light (light/lights.h: point, spot, directional) reflected by a
// glossy surface is a highlight as sharp as the lobe, which a map of dirRes² texels per tixel
// smears into a fan (a point light's reflection on a GGX r 0.2 ceiling: radiance ≈ 50 in the
// path tracer, ≈ 1.2 in the map). So the bake leaves their direct reflection out of the glossy maps it stores (it
// keeps it while propagating, so the light they reflect onwards is transported, and takes it
// out at the end), and the renderers add it where a glossy surface is seen: the model (without
// its diffuse part, which Ẽ holds) against each light at the hit, with the shading normal and
// a shadow ray, as the path tracer's next-event estimation does (PunctualHighlights in
// lookup.h). Rough glass keeps them in its maps. The reflection of every other light — the
// non-delta scene lights and emissive surfaces, whose highlights are as wide as the light —
// stays in the maps.
#include "core/math.h"
#include "scene/scene.h"

#include <nlohmann/json_fwd.hpp>

#include <array>
#include <bit>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace pl {

enum class ChartKind : uint8_t { Diffuse = 0, Glossy = 1, Specular = 2 };

struct Chart {
  uint32_t material = 0;
  ChartKind kind = ChartKind::Diffuse;
  Vec3 origin{0.0f};            ///< corner of tixel (0, 0)
  Vec3 axisU{1, 0, 0}, axisV{0, 1, 0}, normal{0, 0, 1};
  float tixelSize = 1.0f;       ///< scene units
  uint32_t resU = 1, resV = 1;  ///< tixel grid
  uint32_t dirRes = 1;          ///< paraboloid map resolution (1 for diffuse, 0 for specular)
  uint64_t firstTixel = 0;      ///< index of tixel (0, 0) among all tixels of the light field
  uint64_t firstValue = 0;      ///< index of tixel (0, 0), direction texel (0, 0) in values
  uint8_t sides = 1;            ///< 2: a two-sided surface (both records have 2), see "Sides" above
  bool isBack = false;          ///< the back-side record of a two-sided surface (follows its front)
  bool curved = false;          ///< a curved (diffuse or glossy) chart: sides are decided per triangle (chartNormalAt)
  /// A glossy chart whose material has a diffuse part: each tixel's map is followed by its
  /// diffuse irradiance Ẽ (see "What is stored per chart kind" above).
  bool diffuseValue = false;
  /// A diffuse chart, or a diffuseValue glossy chart, of a normal-mapped material: each
  /// tixel's irradiance E (a glossy chart's Ẽ) is followed by its kTiltedNormals tilted
  /// irradiances E_k (see "Normal-mapped diffuse charts" above).
  bool directionalIrradiance = false;

  uint64_t tixelCount() const { return uint64_t(resU) * resV; }
  uint64_t directionTexels() const { return uint64_t(dirRes) * dirRes; }
  uint64_t valuesPerTixel() const;
  /// Values are tixel-major: all direction texels of one tixel are contiguous, direction
  /// texel (s, t) at s + t·dirRes, then (diffuseValue) the tixel's Ẽ, then (directionalIrradiance)
  /// its tilted irradiances E_0 … E_2; tixels row by row (i + j·resU).
  uint64_t valueIndex(uint32_t i, uint32_t j, uint32_t s = 0, uint32_t t = 0) const {
    return firstValue + (uint64_t(j) * resU + i) * valuesPerTixel() + uint64_t(t) * dirRes + s;
  }
  /// The index of tixel (i, j)'s diffuse irradiance Ẽ (diffuseValue charts only).
  uint64_t diffuseValueIndex(uint32_t i, uint32_t j) const { return valueIndex(i, j) + directionTexels(); }
  /// The index of tixel (i, j)'s irradiance about tilted normal k (directionalIrradiance
  /// charts): after its irradiance E (diffuse) or its map and Ẽ (glossy).
  uint64_t tiltedIrradianceIndex(uint32_t i, uint32_t j, uint32_t k) const {
    return valueIndex(i, j) + directionTexels() + (diffuseValue ? 1 : 0) + k;
  }
};

/// Normal-mapped diffuse charts (see above): the number of tilted normals, their tilt β = 45°
/// from the chart's normal (cos β = sin β = √½) and their directions across it,
/// t_k = (cos φ_k, sin φ_k), φ_k = k·120°. Constants, since the renderers use them per pixel.
inline constexpr uint32_t kTiltedNormals = 3;
inline constexpr float kNormalTiltDegrees = 45.0f;
inline constexpr float kNormalTiltCosine = 0.70710678f, kNormalTiltSine = 0.70710678f;
inline constexpr float kTiltAcross[kTiltedNormals][2] = {{1.0f, 0.0f}, {-0.5f, 0.86602540f}, {-0.5f, -0.86602540f}};

inline uint64_t Chart::valuesPerTixel() const {
  return directionTexels() + (diffuseValue ? 1 : 0) + (directionalIrradiance ? kTiltedNormals : 0);
}

/// Tilted normal k (0 … kTiltedNormals − 1) in the tilt frame's local coordinates (z along
/// the chart's normal): b_k = (sin β·t_k, cos β).
inline Vec3 tiltedNormal(uint32_t k) {
  return {kNormalTiltSine * kTiltAcross[k][0], kNormalTiltSine * kTiltAcross[k][1], kNormalTiltCosine};
}

/// The weights of the model above: E(n') ≈ irradiance·E + Σ_k tilted[k]·E_k for a normal n'
/// in the tilt frame's local coordinates (unit, or a mean of unit normals).
struct TiltWeights {
  float irradiance = 1.0f;
  float tilted[kTiltedNormals] = {};
};
inline TiltWeights tiltWeights(const Vec3& localNormal) {
  // E + a(1 − n'_z) with a = (Ē − E)/(1 − cos β): the isotropic part's share s of Ē − E; and
  // g·n'_t with g = 2/(3 sin β)·Σ_k E_k·t_k.
  const float share = (1.0f - localNormal.z) * (1.0f / (1.0f - kNormalTiltCosine));
  constexpr float kGradient = 2.0f / (3.0f * kNormalTiltSine);
  TiltWeights w;
  w.irradiance = 1.0f - share;
  for (uint32_t k = 0; k < kTiltedNormals; ++k)
    w.tilted[k] = share * (1.0f / float(kTiltedNormals)) +
                  kGradient * (kTiltAcross[k][0] * localNormal.x + kTiltAcross[k][1] * localNormal.y);
  return w;
}

/// Quality preset parameters (kBakePresets in bake/bake.h, docs/user-guide.md). The member defaults are
/// those of the "default" preset, so a default-constructed BakeSettings equals
/// bakePreset("default") (a test checks it).
struct BakeSettings {
  std::string preset = "default";
  float tixelsPerUnit = 0.0f;      ///< world-space density; 0 = derive from the scene's room scale
  uint32_t maxTixelsPerChartSide = 16384;  ///< only wider charts get larger tixels (indices stay in 32 bits)
  float tixelsAcrossScene = 40.0f;  ///< used when tixelsPerUnit = 0: tixels across the room scale (sceneScale)
  uint32_t gatherDirections = 256; ///< gather rays per tixel (visibility field)
  uint32_t glossyDirRes = 16;      ///< cap on the paraboloid map size of glossy charts
  float tolerance = 1e-3f;         ///< relative change of total outgoing power to stop at
  uint32_t maxIterations = 200;
  uint32_t mirrorDepth = 256;      ///< longest ideal-specular chain followed (roulette from step 8: lookup.h)
  uint32_t areaLightSamples = 32;  ///< shadow rays per tixel towards emissive surfaces (MIS with the gather); 0 = gather only
  uint64_t seed = 0;
  /// Sun masks for directional lights (lightfield.h "Sun masks"); `bake --sun-masks off`.
  bool sunMasks = true;
  /// Punctual highlights (lightfield.h "Punctual highlights"): the glossy maps leave out the
  /// direct reflection of point, spot and directional lights, which the renderers evaluate per
  /// pixel. False in files written before them, whose maps hold it.
  bool punctualHighlights = true;
  /// Caustics (docs/design.md "Caustics"): photons shot from the emissive surfaces through
  /// mirrors and glass onto diffuse tixels, whose gather then leaves that light out; 0 = none
  /// (the gather finds it, as in files written before them). `bake --caustic-photons N`.
  uint64_t causticPhotons = 0;
  /// Subsurface charts (bake/subsurface.h): random walks per tixel area that estimate the
  /// operator carrying light through subsurface objects. Older files: the default (unused).
  uint32_t subsurfaceWalks = 256;
  /// The visibility field's bilinear fractions kept whole (plf/plv_file.h "Compact entries"):
  /// `bake --visibility-precision exact`; false: quantised (compact), the default.
  bool exactVisibility = false;
};

struct BakeStats {
  double seconds = 0, visibilitySeconds = 0, propagationSeconds = 0;
  uint32_t iterations = 0;
  double residual = 0;
  uint64_t tixels = 0;
  uint64_t values = 0;
  uint64_t visibilityRays = 0;
  uint64_t peakRssBytes = 0;
  bool reusedVisibility = false;
  /// How the propagation read the visibility field: "held" (in memory) or "streamed" (from
  /// its .plv a block at a time; docs/design.md, Visibility field).
  std::string visibilityMemory = "held";
  uint64_t causticPhotons = 0;       ///< photons shot by the caustic pass (0: none)
  uint64_t causticPhotonsLanded = 0; ///< of those, the ones that reached a diffuse tixel through mirrors or glass
  double causticSeconds = 0;         ///< of propagationSeconds, in the caustic pass
};

// The one JSON schema of the bake's settings and statistics (lightfield.cpp): the .plf's META
// section, `plenoptic info --json` ("settings", "stats") and `bake --stats` (the statistics'
// keys, docs/user-guide.md) all write these, and the .plf reader reads them back.
nlohmann::json toJson(const BakeSettings& settings);
nlohmann::json toJson(const BakeStats& stats);
/// The fields `json` holds; a key it lacks leaves its field as it is (a newer writer may add
/// keys, which are ignored), except sun_masks, punctual_highlights and caustic_photons, whose
/// absence means a writer from before them, which baked without them (false, false, 0). Throws nlohmann::json::exception
/// for a value of the wrong type.
void fromJson(const nlohmann::json& json, BakeSettings& settings);
void fromJson(const nlohmann::json& json, BakeStats& stats);

/// Sun masks (see the header comment): at most this many directional lights are masked, with
/// kSunMaskSide² sub-samples per tixel.
inline constexpr uint32_t kMaxSunMaskLights = 4;
inline constexpr int kSunMaskSide = 4;
using SunMask = uint16_t;
/// One tixel's masks, one slot per masked light (the bake's per-tixel layout).
using SunMaskSlots = std::array<SunMask, kMaxSunMaskLights>;
static_assert(kSunMaskSide * kSunMaskSide == 16, "a sun mask is 16 bits");

/// Indices into scene.lights of the lights that get sun masks: its first kMaxSunMaskLights
/// delta lights at infinity (directional lights: light/lights.h parallelLight), or none when
/// a material is thin glass.
inline std::vector<uint32_t> sunMaskLights(const Scene& scene) {
  std::vector<uint32_t> lights;
  if (scene.hasThinGlass()) return lights;
  for (uint32_t i = 0; i < scene.lights.size() && lights.size() < kMaxSunMaskLights; ++i)
    if (parallelLight(scene.lights[i])) lights.push_back(i);
  return lights;
}

struct LightField {
  Scene scene;                                     ///< geometry, materials, textures, cameras, environment
  std::vector<Chart> charts;
  std::vector<std::vector<uint32_t>> triangleChart;  ///< [mesh][triangle] → chart index
  std::vector<Rgb> values;                         ///< see the header comment for units
  /// Sun masks (header comment): sunMaskLightCount = sunMaskLights(scene).size() masks per
  /// tixel, mask of light l of tixel g at [g·sunMaskLightCount + l] (all bits set on tixels
  /// of glossy and specular charts, which keep those lights in their values). Count 0 and no
  /// masks: a light field baked without them (`bake --sun-masks off`, or older files), whose
  /// diffuse values include every light.
  uint32_t sunMaskLightCount = 0;
  std::vector<SunMask> sunMasks;
  BakeSettings settings;
  BakeStats stats;
};

/// The fraction of light l's sun mask that is lit at grid position `grid` of chart c (tixel
/// coordinates with tixel (i, j)'s centre at (i, j), tixelGridCoordinates): bilinear between
/// the four nearest sub-sample centres, clamped to the chart's grid. chartMasks points at the
/// masks of the chart's tixel (0, 0) (sunMasks + firstTixel·lightCount).
inline float sunVisibility(const SunMask* chartMasks, uint32_t lightCount, uint32_t light, const Chart& c, Vec2 grid) {
  // Sub-sample coordinates: sub-sample s (along one axis) of the chart has its centre at
  // grid (s + ½)/4 − ½, so s = 4·(grid + ½) − ½.
  auto axis = [](float g, uint32_t res, uint32_t& s0, uint32_t& s1, float& f) {
    const float last = float(res * kSunMaskSide - 1);
    const float unclamped = float(kSunMaskSide) * (g + 0.5f) - 0.5f;
    const float s = unclamped > 0.0f ? std::min(unclamped, last) : 0.0f;  // NaN → 0
    s0 = uint32_t(s);
    s1 = std::min(s0 + 1, res * kSunMaskSide - 1);
    f = s - float(s0);
  };
  uint32_t u0, u1, v0, v1;
  float fu, fv;
  axis(grid.x, c.resU, u0, u1, fu);
  axis(grid.y, c.resV, v0, v1, fv);
  // Most lookups read four sub-samples of one tixel that is wholly lit or wholly shadowed.
  if (u0 / kSunMaskSide == u1 / kSunMaskSide && v0 / kSunMaskSide == v1 / kSunMaskSide) {
    const SunMask mask = chartMasks[uint64_t((v0 / kSunMaskSide) * c.resU + u0 / kSunMaskSide) * lightCount + light];
    if (mask == 0xffffu) return 1.0f;
    if (mask == 0) return 0.0f;
  }
  auto bit = [&](uint32_t su, uint32_t sv) {
    const uint32_t tixel = (sv / kSunMaskSide) * c.resU + su / kSunMaskSide;
    const uint32_t b = (sv % kSunMaskSide) * kSunMaskSide + su % kSunMaskSide;
    return float((chartMasks[uint64_t(tixel) * lightCount + light] >> b) & 1u);
  };
  return (1.0f - fv) * ((1.0f - fu) * bit(u0, v0) + fu * bit(u1, v0)) + fv * ((1.0f - fu) * bit(u0, v1) + fu * bit(u1, v1));
}

/// The lit fraction of a sun mask (the bake's footprint mean).
inline float sunMaskFraction(SunMask mask) { return float(std::popcount(mask)) / float(kSunMaskSide * kSunMaskSide); }

/// The normal of chart record c at triangle `triangle` of `mesh` (one of its triangles): the
/// chart normal for a planar chart (its triangles are coplanar within
/// kChartNormalToleranceDegrees), the triangle's unit winding normal for a curved one (negated
/// on a back record), since a curved chart's triangles may face up to its cone bound away from
/// the chart normal. Not unit for a degenerate triangle of a curved chart (zero).
inline Vec3 chartNormalAt(const Chart& c, const Mesh& mesh, uint32_t triangle) {
  if (!c.curved) return c.normal;
  const Vec3 n = triangleNormal(mesh, triangle);
  return c.isBack ? -n : n;
}

/// The normal chart record c's values are taken around at barycentrics (b1, b2) of triangle
/// `triangle` of `mesh` (one of its triangles): the chart normal on a planar chart; on a curved
/// one the interpolated shading normal there (interpolatedNormal, scene.h: no normal map, that
/// is render-time detail; the face normal on a flat-shaded mesh), turned to the record's side
/// (negated on a back record). The bake's gather normals (Parameterisation::gatherNormal) are
/// this at each tixel's gather point, and the lookups of glossy charts take their direction
/// frame around it at the hit: continuous over the chart, and within a tixel of the gather
/// normals of the tixels they interpolate.
inline Vec3 chartShadingNormalAt(const Chart& c, const Mesh& mesh, uint32_t triangle, Vec2 barycentrics) {
  if (!c.curved) return c.normal;
  const Vec3 n = interpolatedNormal(mesh, triangle, barycentrics, triangleNormal(mesh, triangle));
  return c.isBack ? -n : n;
}

/// An orthonormal frame (z along n). Directions of a chart record's values are expressed in it:
/// a tixel's gather directions and, on a glossy chart, its paraboloid map. toWorld/toLocal are
/// chartWorldDirection/chartLocalDirection's formulas (lookup.h), so on a planar chart (the
/// chart frame) the results are bit for bit those of the chart frame.
struct TixelFrame {
  Vec3 u, v, n;
  Vec3 toWorld(const Vec3& local) const { return local.x * u + local.y * v + local.z * n; }
  Vec3 toLocal(const Vec3& w) const { return {glm::dot(w, u), glm::dot(w, v), glm::dot(w, n)}; }
};
/// A frame around unit `normal` at a point of chart c that turns continuously over the chart:
/// the chart's frame (axisU, axisV, normal) on a planar chart (`normal` unread); on a curved
/// one u = axisU made orthogonal to the normal (Gram–Schmidt), v = n × u. Directional data
/// read in the frame of a lookup point and interpolated between tixels stored in the frames of
/// their gather points (glossy maps, tilted irradiances) needs such a frame. Frame::fromNormal
/// is not one: at n.z = 0 it turns by 180° about n (n = (1, 0, ±0) gives s = (0, 0, ∓1)), and a
/// sphere's charts straddle that great circle. axisU is orthogonal to the chart normal and the
/// chart's normals stay within about 2 × kCurvedChartConeDegrees of it (parameterisation.h),
/// so axisU is ≥ ≈ 50° off any of them and the projection never vanishes (Frame::fromNormal is
/// the fallback for a degenerate vertex normal that leaves that bound).
inline TixelFrame continuousFrameAround(const Chart& c, const Vec3& normal) {
  if (!c.curved) return {c.axisU, c.axisV, c.normal};
  const Vec3 u = c.axisU - glm::dot(c.axisU, normal) * normal;
  const float length = glm::length(u);
  if (length > 1e-3f) {
    const Vec3 unitU = u / length;
    return {unitU, glm::cross(normal, unitU), normal};
  }
  const Frame f = Frame::fromNormal(normal);
  return {f.s, f.t, f.n};
}
/// The frame at a point of chart c whose unit normal (chartShadingNormalAt, or a tixel's
/// gatherNormal) is `normal`: the chart's frame (axisU, axisV, normal) on a planar chart
/// (`normal` unread); on a curved one a frame around `normal`. The one definition the bake
/// (gather directions, glossy maps) and the lookups of every renderer share.
///  * Curved diffuse charts: Frame::fromNormal(normal). Only the gather directions turn with
///    it, and an irradiance sum does not care how they are turned about the normal.
///  * Curved glossy charts: continuousFrameAround, since a directional map is read in the
///    frame of the lookup point and interpolated between tixels stored in the frames of their
///    gather points.
inline TixelFrame tixelFrameAround(const Chart& c, const Vec3& normal) {
  if (c.kind == ChartKind::Glossy) return continuousFrameAround(c, normal);
  if (!c.curved) return {c.axisU, c.axisV, c.normal};
  const Frame f = Frame::fromNormal(normal);
  return {f.s, f.t, f.n};
}
/// The frame the tilted normals of a directionalIrradiance chart's tixel (tiltedNormal) are
/// taken in, at a point whose unit normal is `normal`: continuousFrameAround, so that the
/// renderers can interpolate tilted irradiances between tixels.
inline TixelFrame tiltFrameAround(const Chart& c, const Vec3& normal) { return continuousFrameAround(c, normal); }

/// The chart record holding the side of record `chart` (as triangleChart gives it) that a
/// viewer in world direction towardsViewer (from the surface; −ray direction) sees at a point
/// whose record normal (chartNormalAt) is `normalAtHit`: its back record chart + 1 when the
/// surface is two-sided and the viewer is behind that normal, otherwise `chart` itself. The
/// one place the bake's gather rays and both renderers choose a side.
inline uint32_t facingChart(const Chart* charts, uint32_t chart, const Vec3& towardsViewer, const Vec3& normalAtHit) {
  const Chart& c = charts[chart];
  return c.sides == 2 && !c.isBack && glm::dot(towardsViewer, normalAtHit) < 0.0f ? chart + 1 : chart;
}
/// facingChart at a ray's hit on triangle `triangle` of `mesh` (the triangle normal is only
/// computed for a curved chart).
inline uint32_t facingChart(const Chart* charts, uint32_t chart, const Vec3& towardsViewer, const Mesh& mesh,
                            uint32_t triangle) {
  return facingChart(charts, chart, towardsViewer, chartNormalAt(charts[chart], mesh, triangle));
}

/// What a renderer's view ray sees: facingChart's record, or kNoChartRecord when the viewer is
/// behind a one-sided *curved* record — the inside of a closed smooth mesh, which reflects
/// nothing (the rule the bake's gather rays follow: `back` in visibility.cpp). Curved charts
/// never emit (parameterisation.h), so nothing is seen there: radiance 0. A planar one-sided
/// record seen from behind is returned as it is, and the lookup's cos θ < 0 against its one
/// normal gives the same answer there, plus a two-sided emitter's emission.
inline constexpr uint32_t kNoChartRecord = 0xffffffffu;
inline uint32_t viewedChart(const Chart* charts, uint32_t chart, const Vec3& towardsViewer, const Mesh& mesh,
                            uint32_t triangle) {
  const Chart& c = charts[chart];
  const Vec3 normal = chartNormalAt(c, mesh, triangle);
  const uint32_t facing = facingChart(charts, chart, towardsViewer, normal);
  return c.curved && c.sides == 1 && glm::dot(towardsViewer, normal) < 0.0f ? kNoChartRecord : facing;
}

/// Whether chart record c (of a material with BSDF bsdf) is rough glass: a glossy chart whose
/// BSDF transmits (lightfield.h "Rough glass"; smooth and thin glass are Specular charts).
inline bool isRoughGlassChart(const Chart& c, const Bsdf& bsdf) {
  return c.kind == ChartKind::Glossy && hasTransmission(bsdf);
}

/// A direction in a record's local frame (z along its normal) in the frame of its material's
/// transmissive BSDF, whose +z is the surface's geometric front: the same for a front record,
/// z negated for a back record (backRecord = Chart::isBack; its normal is the negated front
/// normal, its axes are the front's). Reflection-only BSDFs are evaluated in the record's own
/// frame (the frame turned to the viewer's side, as the path tracer does) and need no turn.
inline Vec3 glassBsdfDirection(bool backRecord, const Vec3& local) {
  return backRecord ? Vec3(local.x, local.y, -local.z) : local;
}

/// Emitted radiance of chart record c's material towards a direction with cosine cosTheta
/// against the record's own normal: emittedRadiance (scene.h) with the cosine turned back to
/// the surface's geometric front for a back record, so a one-sided emitter's back record
/// emits nothing and a two-sided one's emits on both.
inline Rgb chartEmittedRadiance(const Material& m, const Chart& c, float cosTheta) {
  return emittedRadiance(m, c.isBack ? -cosTheta : cosTheta);
}

/// Paraboloid map of the upper hemisphere (local frame, z = normal), see above.
Vec2 directionToParaboloid(const Vec3& localDirection);
Vec3 paraboloidToDirection(Vec2 st);

}  // namespace pl
