#pragma once
// Parameterisation of a scene's surfaces for the light-field bake (docs/design.md, Charts and
// Curved charts; seed slides 9–17).
//
// Charts: maximal sets of edge-connected triangles that share a material and a plane. Two
// triangles sharing an edge (vertices welded by position, so split vertices still connect)
// join when their normals differ by less than kChartNormalToleranceDegrees and the far
// triangle's vertices lie within kChartPlaneTolerance × (scene diagonal) of the seed
// triangle's plane. Each chart gets an orthonormal frame — normal = the area-weighted mean of
// its triangles' winding normals (the emitting/front side), axisU along the polygon edge that
// gives the smallest bounding rectangle of the triangles projected along the normal — and a
// square tixel grid over that rectangle.
//
// Curved charts (Chart::curved). A smooth diffuse or glossy surface (banners, curtains,
// arches, a sphere, a sofa, a vase) would otherwise be one flat chart per triangle: faceted
// lookups and tixels smaller than the preset's wherever triangles are. So, for a Lambertian or
// glossy (Blinn-Phong, GGX) material that does not emit (mayGrowCurvedCharts; rough glass
// stays planar: its two records are the two sides of one interface), a triangle also joins a neighbour across a *smooth* edge — welded, with the shading normals
// of both triangles equal (within kSmoothEdgeToleranceDegrees) at both ends of the edge, so a
// modelled crease (split normals) stops the chart; on a flat-shaded mesh (no vertex normals,
// Crytek Sponza's) any edge whose faces meet within kFlatShadedChartEdgeDegrees — when its
// winding normal is within kCurvedChartConeDegrees of the seed triangle's. The flattening is the projection along the chart
// normal: every face normal lies within 2 × kCurvedChartConeDegrees (≤ 40°) of it, so the
// projection is locally one-to-one and linear on each triangle (lookups need no per-triangle
// data). Its distortion is the foreshortening cos θ of a face tilted θ from the chart normal
// (one direction shrinks by cos θ, the other is kept: area stretch cos θ, angle stretch
// 1/cos θ); the tixel size is multiplied by the chart's smallest cos θ,
// so that even the most tilted triangle's tixels are no larger than the preset's on the
// surface — no chart is coarser than the preset. A chart is curved when it grew across a
// smooth edge that is not coplanar, or (a lone facet of a smooth mesh) when a vertex normal
// of its triangles leaves kChartNormalToleranceDegrees of the chart normal; all others are
// the planar charts of before, unchanged.
// Glossy charts grow within the same bounds as diffuse ones (the same cone, smooth-edge and
// flat-shading angles). Specular, rough-glass and emissive charts stay planar. A curved
// chart's tixels gather around the interpolated shading normal at their gather point
// (gatherNormal, chartShadingNormalAt), so a smooth mesh gets smoothly varying values; on a
// flat-shaded mesh that is the face normal of the triangle under the tixel, as the path
// tracer shades it (facets stay facets, blended over one tixel at their edges, but are no
// longer a chart each). A glossy tixel stores its paraboloid map in its frame (tixelFrame:
// tixelFrameAround its gather normal, lightfield.h), and lookups read it in the frame around
// the interpolated normal at the looked-up point, so highlights move smoothly over the mesh.
//
// Tixel size (world units): 1 / tixelsPerUnit when that is set, otherwise the scene's room
// scale (sceneScale) / tixelsAcrossScene, so a preset means the same density in a one-room
// box and in a many-room building. The chart's material refines it: glossy charts use tixels
// kGlossyTixelDensity times finer (their values change with position faster: highlights
// move), and a JSON material's "tixel_density" multiplies the density (Material::tixelDensity).
// No chart is coarsened for being small or large (a chart smaller than a tixel gets one
// tixel of the preset's size; only a chart wider than settings.maxTixelsPerChartSide tixels is
// coarsened, to keep grid indices in 32 bits). The grid is centred on the rectangle.
//
// Directional resolution by material (chartKindOf / directionalResolution):
//   Lambertian → Diffuse, dirRes 1 (irradiance);
//   ideal mirror, smooth or thin glass → Specular, dirRes 0 (a reordering, nothing stored);
//   Blinn-Phong / GGX without a diffuse part whose lobe is narrower than one texel of the
//   largest map (isMirrorLike) → Specular too: followed through by sampling the lobe;
//   Blinn-Phong / GGX / rough glass → Glossy, dirRes from the lobe width (lobeMapResolution),
//   capped by glossyDirRes (twice that for a strong narrow lobe: isStrongNarrowLobe).
//
// Sides (lightfield.h "Sides"): the diffuse and glossy charts of an open surface — a connected
// set of triangles (welded edges, any material) that is not closed and consistently wound —
// get a back record right after their front record, unless nothing can light or see the back
// (black environment, no punctual light behind, the scene's bounding box on or in front of the
// plane: its radiance is exactly 0); closed surfaces stay one-sided. Rough glass charts are
// always two-sided (lightfield.h "Rough glass").
//
// Every tixel gets a gather point on the polygon: its centre when the centre lies on one of
// the chart's triangles, otherwise the closest point of the polygon (pulled slightly inside),
// so tixels outside the polygon still get valid values from a nearby real surface point.
#include "accel/accel.h"
#include "core/math.h"
#include "lightfield/lightfield.h"
#include "scene/scene.h"

#include <cstdint>
#include <string>
#include <utility>
#include <array>
#include <variant>
#include <vector>

namespace pl {

inline constexpr float kChartNormalToleranceDegrees = 2.0f;
/// Curved charts: every face normal within this angle of the seed triangle's normal.
inline constexpr float kCurvedChartConeDegrees = 20.0f;
/// Curved charts: an edge is smooth when both triangles' shading normals at each of its ends
/// are within this angle.
inline constexpr float kSmoothEdgeToleranceDegrees = 1.0f;
/// Curved charts of flat-shaded meshes (no vertex normals): neighbouring faces join when their
/// normals are within this angle.
inline constexpr float kFlatShadedChartEdgeDegrees = 30.0f;
inline constexpr float kChartPlaneTolerance = 0.005f;  ///< relative to the scene diagonal
/// Glossy charts' tixels are this many times finer than diffuse ones (per side).
inline constexpr float kGlossyTixelDensity = 2.0f;
/// Rays sceneScale traces.
inline constexpr uint32_t kSceneScaleRays = 16384;

/// What the bake needs per tixel beyond the stored Chart records.
struct Parameterisation {
  std::vector<Chart> charts;
  std::vector<std::vector<uint32_t>> triangleChart;  ///< [mesh][triangle] → chart
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> chartTriangles;  ///< chart → (mesh, triangle)
  std::vector<double> chartArea;    ///< sum of the chart's triangle areas (scene units²)
  float sceneScale = 0.0f;          ///< sceneScale() (0 when settings.tixelsPerUnit fixed the size)
  float baseTixelSize = 0.0f;       ///< the preset's tixel size before the per-material factors
  uint64_t tixelCount = 0;
  uint64_t valueCount = 0;
  // Per tixel, by global tixel index (Chart::firstTixel + i + j·resU):
  std::vector<uint32_t> tixelChart;   ///< owning chart
  std::vector<Vec3> gatherPoint;      ///< world point on the polygon the tixel gathers from
  /// Curved charts only (else empty entries are never read): the unit interpolated shading
  /// normal at gatherPoint, on the record's side (negated on a back record). See tixelFrame.
  std::vector<Vec3> gatherNormal;
  /// directionalIrradiance charts only (empty when there is none; other entries are never
  /// read): the weights of the tixel's E and tilted irradiances in the irradiance its
  /// transport sends on — the mean over its footprint's mapped normals (lightfield.h
  /// "Normal-mapped diffuse charts"; transportTiltWeights in parameterisation.cpp).
  std::vector<TiltWeights> transportTiltWeights;
  std::vector<float> coverage;        ///< fraction of the tixel's square covered by the polygon
  /// 1 for a wholly buried tixel (no footprint sub-sample outside other geometry), whose
  /// gather point and sun masks are its nearest unburied neighbour's (fillTixels).
  std::vector<uint8_t> borrowedPoint;
  std::vector<Rgb> transportAlbedo;   ///< diffuse charts, and glossy diffuseValue ones' diffuse part: mean albedo over the tixel's footprint
  /// Glossy charts of a material with a metallic-roughness texture (empty when no chart has
  /// one; other entries are never read): the mean over the tixel's footprint of the point
  /// models' lobe f0 (bsdf.h specularF0 of scene.h materialModelAt), which the bake's glossy
  /// maps take in place of the material model's (propagation.cpp GlossyMaterial).
  std::vector<Rgb> specularF0;
  /// Glossy charts with per-tixel lobe widths (perTixelLobeWidth; empty when no chart has
  /// them, other entries never read): the mean over the tixel's footprint of the point models'
  /// GGX α (roughness² of the metallic-roughness texture × factor), which picks the tixel's
  /// lobe among its material's α bins (lobeAlphaBins; propagation.cpp GlossyMaterial).
  std::vector<float> lobeAlpha;
  /// Sun masks (lightfield.h "Sun masks"): the scene lights masked (sunMaskLights, or none
  /// when BakeSettings::sunMasks is off) and per tixel one mask per masked light (slots past
  /// their count unused; every bit set on glossy and specular charts).
  std::vector<uint32_t> sunMaskLights;
  std::vector<std::array<SunMask, kMaxSunMaskLights>> sunMask;
  /// Textured emitters (charts of a material with an emission texture; both empty when the
  /// scene has none, other entries never read): the mean of the emission texture over the
  /// tixel's footprint sub-samples (scene.h emissionModulation), and the triangle (mesh,
  /// triangle) under its gather point, whose light-sampler area density the gather's MIS
  /// weight takes for the whole tixel.
  std::vector<Rgb> emissionModulation;
  std::vector<std::pair<uint32_t, uint32_t>> emitterTriangle;
};

/// Calls f(tag, array) for each per-tixel array that fillTixels fills (the tixel setup), sun
/// masks excepted (the light field stores those; they follow its lights): tag is the array's
/// four-character name in the .plt file (plf/plt_file.h), array a
/// std::vector<Element> of tixelCount trivially copyable elements, or empty when no chart
/// uses it. Element types and the order are part of that file's format.
template <typename P, typename F>
void forEachTixelSetupArray(P& p, F&& f) {
  f("GPNT", p.gatherPoint);
  f("GNRM", p.gatherNormal);
  f("TILT", p.transportTiltWeights);
  f("COVR", p.coverage);
  f("BORR", p.borrowedPoint);
  f("ALBD", p.transportAlbedo);
  f("SPF0", p.specularF0);
  f("LOBA", p.lobeAlpha);
  f("EMOD", p.emissionModulation);
  f("EMTR", p.emitterTriangle);
}

/// Whether chart c is a textured emitter (Parameterisation::emissionModulation holds its tixels).
inline bool texturedEmitter(const Scene& scene, const Chart& c) {
  const Material& m = scene.materials[c.material];
  return m.emissionTexture >= 0 && m.isEmissive();
}

/// Whether chart c is a subsurface chart (bake/subsurface.h): a diffuse chart of a subsurface
/// material (bsdf.h SubsurfaceBsdf), whose light leaves through the object's other tixels. Its
/// stored value is M/ρ̄ (lightfield.h "What is stored per chart kind"), it keeps no tilted
/// irradiances, and its sun masks are empty: the masked lights' light goes through the object.
inline bool isSubsurfaceChart(const Scene& scene, const Chart& c) {
  return c.kind == ChartKind::Diffuse && std::holds_alternative<SubsurfaceBsdf>(scene.materials[c.material].bsdf);
}

/// Whether chart c's tixels keep their own lobe f0 (Parameterisation::specularF0): a glossy
/// chart of a material whose metallic-roughness texture varies its model per point.
inline bool perTixelSpecularF0(const Scene& scene, const Chart& c) {
  return c.kind == ChartKind::Glossy && scene.materials[c.material].metallicRoughness.texture >= 0;
}

/// The GGX α of model `bsdf` (GgxBsdf, GltfPbrBsdf: a glTF metallic-roughness model's), 0 for
/// a model without one; and the model with its α replaced.
float ggxLobeAlpha(const Bsdf& bsdf);
Bsdf withGgxLobeAlpha(const Bsdf& bsdf, float alpha);

/// Whether chart c's tixels take their own lobe width (Parameterisation::lobeAlpha): a chart
/// with its own lobe f0 (perTixelSpecularF0) whose model has a GGX α and transmits nothing.
inline bool perTixelLobeWidth(const Scene& scene, const Chart& c) {
  const Bsdf& bsdf = scene.materials[c.material].bsdf;
  return perTixelSpecularF0(scene, c) && ggxLobeAlpha(bsdf) > 0.0f && !hasTransmission(bsdf);
}

/// The GGX α of a metallic-roughness texel of `material`: ggxAlphaFromRoughness(roughness
/// factor × G), as materialModelAt makes it. lobeAlphaRange: its least and greatest over the
/// texture's texels (the material's finest and widest lobes).
std::pair<float, float> lobeAlphaRange(const Scene& scene, const Material& material);

/// Neighbouring α bins are at most this ratio apart (a tixel's α within ±12 % of its bin's).
inline constexpr float kLobeBinRatio = 1.25f;
/// At most this many α bins per material (each costs the bake one or two glossy operators).
inline constexpr uint32_t kMaxLobeBins = 16;
/// The α bins of a material with per-tixel lobe widths on charts of map resolution dirRes:
/// geometric from the texture's least α to its greatest (lobeAlphaRange), at most
/// kLobeBinRatio apart, with α below one map texel's lobe (FWHM 4/dirRes radians: GGX
/// α = tan(1/dirRes)/√(√2 − 1)) raised to it — the map holds all narrower lobes alike.
std::vector<float> lobeAlphaBins(const Scene& scene, const Material& material, uint32_t dirRes);
/// The bin (index into `bins`, ascending) nearest α, by ratio.
uint32_t nearestLobeBin(const std::vector<float>& bins, float alpha);

/// The radiance tixel `tixel` of chart record c emits towards a direction with cosine
/// cosTheta against the record's normal: chartEmittedRadiance (lightfield.h) times the tixel's
/// mean emission texture on a textured emitter. The bake's gather and glossy emission.
inline Rgb tixelEmittedRadiance(const Scene& scene, const Parameterisation& p, const Chart& c, uint64_t tixel,
                                float cosTheta) {
  const Rgb le = chartEmittedRadiance(scene.materials[c.material], c, cosTheta);
  return texturedEmitter(scene, c) ? le * p.emissionModulation[tixel] : le;
}

/// The frame tixel `tixel` of chart c gathers in and stores its directional map in
/// (tixelFrameAround, lightfield.h, of its gatherNormal on a curved chart).
inline TixelFrame tixelFrame(const Parameterisation& p, const Chart& c, uint64_t tixel) {
  return tixelFrameAround(c, c.curved ? p.gatherNormal[tixel] : c.normal);
}

/// The frame tixel `tixel` of a directionalIrradiance chart c takes its tilted normals in
/// (tiltFrameAround, lightfield.h, of its gatherNormal on a curved chart).
inline TixelFrame tiltFrame(const Parameterisation& p, const Chart& c, uint64_t tixel) {
  return tiltFrameAround(c, c.curved ? p.gatherNormal[tixel] : c.normal);
}

ChartKind chartKindOf(const Bsdf& bsdf, const BakeSettings& settings);
/// The paraboloid map resolution (texels across) that puts four texels across a reflected
/// lobe `lobeWidth` radians wide at half maximum (≈ 16 / lobeWidth), at least 2.
uint32_t lobeMapResolution(float lobeWidth);
/// A glossy lobe counts as mirror-like when lobeMapResolution asks for more than this many
/// times the preset's cap (settings.glossyDirRes): the lobe is narrower than half a texel of
/// the largest map (docs/design.md, "Glossy lobes and the map size", has the measurements
/// that place the boundary there).
inline constexpr uint32_t kMirrorLikeTexels = 8;
/// Whether `bsdf` is a glossy model without a diffuse part (a metal) whose lobe is narrower
/// than half a texel of the preset's largest map: its charts are Specular, and every lookup
/// continues the ray by sampling the lobe (lightfield/lookup.h followSpecular).
bool isMirrorLike(const Bsdf& bsdf, const BakeSettings& settings);
/// Whether charts of `material` may be curved ("Curved charts" above): Lambertian and glossy
/// (Blinn-Phong, GGX) materials that do not emit; not rough glass, mirrors, smooth glass or
/// mirror-like lobes.
bool mayGrowCurvedCharts(const Material& material, const BakeSettings& settings);
/// Paraboloid map resolution for a material (1 diffuse, 0 specular, glossy: lobeMapResolution
/// of its lobe, capped by settings.glossyDirRes, or by kStrongNarrowLobeCapFactor × that for
/// a strong narrow lobe, isStrongNarrowLobe).
uint32_t directionalResolution(const Bsdf& bsdf, const BakeSettings& settings);
/// A glossy chart's map resolution: directionalResolution of the material's model, or with
/// per-tixel lobe widths (perTixelLobeWidth) at least lobeMapResolution of its finest lobe
/// (lobeAlphaRange), capped by settings.glossyDirRes.
uint32_t chartDirectionalResolution(const Scene& scene, const Chart& c, const BakeSettings& settings);
/// A glossy lobe is narrow when lobeMapResolution asks for more than this many times the
/// preset's cap: narrower than two thirds of a texel of the capped map.
inline constexpr uint32_t kStrongNarrowLobeTexels = 6;
/// A narrow lobe is strong when the model without its diffuse part reflects at least this
/// much at normal incidence (luminance): a Blinn-Phong lobe of specular 0.35 or a metal, not a
/// dielectric's f0 0.04, whose smeared reflections are within the targets (docs/design.md,
/// "Glossy lobes and the map size", has the measurements).
inline constexpr float kStrongLobeAlbedo = 0.25f;
/// A strong narrow lobe's map may have this many times the preset's cap across (so this
/// squared times the values per tixel).
inline constexpr uint32_t kStrongNarrowLobeCapFactor = 2;
/// Whether `bsdf` is a glossy model (Blinn-Phong, GGX, not rough glass) whose lobe is narrow
/// and strong (kStrongNarrowLobeTexels, kStrongLobeAlbedo) for the preset's cap. Mirror-like
/// lobes (isMirrorLike) are too, but store no map.
bool isStrongNarrowLobe(const Bsdf& bsdf, const BakeSettings& settings);
/// The scene's room scale (scene units): the side of the empty cube whose mean free path
/// equals the scene's. For a closed cavity of volume V and surface area S, the mean length of
/// the free paths leaving its surface cosine-weighted is 4V/S (Cauchy's formula), 2a/3 for a
/// cube of side a, so the scale is 1.5 × the mean free path, estimated from kSceneScaleRays
/// rays leaving area-uniform surface points (either side, cosine-weighted; escaping rays left
/// out), capped by the largest extent of the scene's bounds. When fewer than 1/16 of the rays
/// hit anything (a lone sheet, open terrain) it is the largest extent. A one-room scene's
/// scale is about its size; a building's is the size of its rooms and courtyards, so tixels
/// stay a fixed fraction of the distances light travels between surfaces (what sets the width
/// of penumbrae and the scale over which indirect light varies). Deterministic.
float sceneScale(const Scene& scene, const Accel& accel);
/// World-space tixel size of the preset (before the per-material factors): 1 / tixelsPerUnit,
/// or scale / tixelsAcrossScene when tixelsPerUnit is 0.
float baseTixelSize(const BakeSettings& settings, float scale);
/// The tixel size of a chart of `material` and `kind` given the preset's base size.
float chartTixelSize(const Scene& scene, uint32_t material, ChartKind kind, float baseSize);

/// Builds charts, tixel grids and per-tixel data. Deterministic for a given scene + settings.
/// It is buildCharts followed by fillTixels of every record.
Parameterisation buildParameterisation(const Scene& scene, const Accel& accel, const BakeSettings& settings);
/// The first part: charts, their frames, grids, sides and tixel/value indices (charts,
/// triangleChart, chartTriangles, chartArea, the counts, tixelChart, sunMaskLights); the
/// per-tixel arrays (gatherPoint, gatherNormal, coverage, transportAlbedo: zero; sunMask: all
/// bits set) are allocated.
Parameterisation buildCharts(const Scene& scene, const Accel& accel, const BakeSettings& settings);
/// The second part, for chart records [firstRecord, endRecord): the per-tixel arrays of their
/// tixels, from footprint sub-samples, the buried-point probes (9 rays per gather point
/// candidate) and the sun masks' rays (16 per diffuse tixel and masked light) — most of the
/// parameterisation's time on a large scene. A record's tixels depend
/// only on the record, so ranks can fill disjoint records and exchange them (shard.h).
void fillTixels(const Scene& scene, const Accel& accel, Parameterisation& p, uint32_t firstRecord, uint32_t endRecord);
/// Traces the sun masks of masked light `slot` (of p.sunMaskLights) again, for every diffuse
/// tixel, as fillTixels does for the light's current direction: what relighting (relight.h)
/// recomputes when a sun moves. The other slots are left alone.
void recomputeSunMasks(const Scene& scene, const Accel& accel, Parameterisation& p, size_t slot);
/// The same, building its own Accel for the scene scale.
Parameterisation buildParameterisation(const Scene& scene, const BakeSettings& settings);

/// Where a bake whose visibility field is `visibilityPath` (X.plv) saves its tixel setup: X.plt.
std::string tixelSetupPathFor(const std::string& visibilityPath);
/// Saves p's tixel setup (forEachTixelSetupArray), its sun masks (array SUNM, after them) and
/// the keys of what they were computed from (tixelSetupKeys) as a .plt file (plf/plt_file.h)
/// for the bake of `scene` whose visibility field has hash `hash` (visibilityHash).
/// `staleMaterials`: materials whose charts p holds other than fillTixels would fill them (a
/// relit albedo, relight.h): their keys are written as 0, which no material hashes to, so
/// that reuseTixelSetup fills their charts again.
void writeTixelSetup(const std::string& path, const Scene& scene, const Parameterisation& p, uint64_t hash,
                     const std::vector<uint32_t>& staleMaterials = {});
/// FNV-1a of a material's model (its variant index) and every parameter (the parameters()
/// hook): equal for the same model with the same parameters. What relighting and the tixel
/// setup's keys compare materials by.
uint64_t modelParameterHash(const Bsdf& bsdf);
/// The parameters of a light other than its emission, in visitLightParameters order (a
/// direction or position: three values): what moving or turning it changes, for relighting
/// and the sun masks' keys.
std::vector<float> lightPlacement(const Light& light);
/// What the tixel setup of `scene` reads beyond the visibility field's inputs (visibilityHash,
/// which covers the geometry, alpha masks and charts), as hashes, in this order: [0] the
/// meshes' normals, uv sets and vertex colours and every texture's texels and sampling; then
/// per material what its charts' footprints read (model and parameters, texture slots and
/// mappings, whether it emits); then per masked light (p.sunMaskLights) its type, index and
/// placement (lightPlacement), which its sun masks follow.
std::vector<uint64_t> tixelSetupKeys(const Scene& scene, const Parameterisation& p);
/// Fills the tixel setup of p (from buildCharts of the baked scene and settings) from the .plt
/// at `path`, and its sun masks from `sunMasks` (LightField::sunMasks, sunMaskLightCount =
/// p.sunMaskLights.size() per tixel) — what fillTixels would give, bit for bit. Returns false
/// and sets *why when the file is absent, of another version, or was written for a visibility
/// field other than `hash`'s (p unchanged); throws pl::Error naming the file when it is corrupt
/// or its arrays do not fit p's charts.
bool readTixelSetup(const std::string& path, uint64_t hash, const std::vector<SunMask>& sunMasks, Parameterisation& p,
                    std::string* why);

/// What reuseTixelSetup took and what it computed again.
struct TixelSetupReuse {
  uint32_t chartsFilled = 0;    ///< chart records filled again (fillTixels) for a changed material
  uint32_t sunMasksTraced = 0;  ///< masked lights whose masks were traced again (recomputeSunMasks)
  bool unchanged() const { return chartsFilled == 0 && sunMasksTraced == 0; }
};
/// For a bake that reuses its visibility field: fills p (from buildCharts of `scene`) with the
/// tixel setup and sun masks saved in the .plt at `path` by a bake of the same geometry (hash
/// `hash`, the .plv's), recomputing only what `scene` changed since (tixelSetupKeys): the
/// charts of a material whose key differs are filled again, the sun masks of a masked light
/// whose placement differs traced again — the result is fillTixels', bit for bit. Returns
/// false and sets *why (p's per-tixel arrays then unspecified: the caller builds them again)
/// when the file is absent, of another hash, for another number of tixels, without keys or
/// sun masks (an older version), written for another number of materials or masked lights,
/// or when the meshes' attributes or the textures changed (key 0) or a changed material needs
/// other arrays; throws pl::Error naming the file when it is corrupt.
bool reuseTixelSetup(const std::string& path, uint64_t hash, const Scene& scene, const Accel& accel, Parameterisation& p,
                     TixelSetupReuse& out, std::string* why);

}  // namespace pl
