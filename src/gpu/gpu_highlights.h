#pragma once
// Punctual lights' highlights in the GPU renderer: lookup.h PunctualHighlights in GLSL. A light
// field baked with punctual highlights (BakeSettings::punctualHighlights) keeps the direct
// glossy reflection of the scene's delta lights (point, spot, directional) out of its maps;
// both renderers add it where a glossy chart record is seen — on the camera ray's hit and at
// the end of a mirror or glass chain — as
//   Σ_l f(wo, wi_l) · E_l · |cos θ_l| · T_l,
// f the chart's model (without its diffuse part when the chart keeps Ẽ: Chart::diffuseValue)
// in the scattering frame of the surface's shading normal, E_l the light's irradiance normal
// to wi_l (sampleLight: the inverse-square law and a spot's smoothstep cone) and T_l its
// shadow ray's transmittance (ShadowRays: 0 when blocked, the straight transmittance of each
// thin glass sheet crossed), traced through the GPU BVH (gpu_bvh.h).
//
// The models evaluated: Blinn-Phong and the GGX-like models of bsdf.h ggxLobeParameters (GGX,
// glTF PBR: the lobe ggxSpecular and the diffuse part ρ/π · k(μo) · k(μi) with k from the GGX
// tables; a glTF model's sheen (the Charlie lobe, its albedo from the sheen table) and clear
// coat over them, each scaling what lies below, and k of the diffuse part under them: read from
// the material's surface-detail record, gpu_surface_detail.h), their diffuse part included on
// a chart without Ẽ; with a metallic-roughness texture the hit point's own model
// (metallicRoughnessLobe of the texel and the albedo modulation at full resolution,
// materialModelAt's point; not with a clear coat or sheen: gpu_surface_detail.h refuses it).
#include <cstdint>
#include <string>
#include <vector>

#include "lightfield/lightfield.h"

namespace pl {

/// Whether the GPU renderer adds highlights for `lf`: it was baked with punctual highlights,
/// has glossy charts and its scene has delta lights (PunctualHighlights::active for the charts
/// the GPU renderer draws).
bool gpuHighlightsActive(const LightField& lf);

/// One delta light as kHighlightsGlsl reads it (std430: four 16-byte rows).
struct HighlightLightGpu {
  float position[4];   ///< xyz: a point or spot light's position, a directional light's unit wi; w: kind (uint bits)
  float intensity[4];  ///< rgb: intensity (W·sr⁻¹), or a directional light's irradiance (W·m⁻²)
  float axis[4];       ///< xyz: a spot light's unit axis (the way it shines)
  float cone[4];       ///< x, y: a spot light's cos inner and cos outer angle
};
static_assert(sizeof(HighlightLightGpu) == 64);

/// One material's reflection model as kHighlightsGlsl evaluates it (std430: four rows).
struct HighlightModelGpu {
  float diffuse[4];    ///< rgb: the diffuse albedo ρ; w: kind (uint bits)
  float lobe[4];       ///< rgb: Blinn-Phong's specular or GGX's f0; w: the exponent n or GGX's α (clamped)
  float extra[4];      ///< x: Blinn-Phong's normalisation N(n) (blinnPhongNormalization) or GGX's f90; y: GGX's
                       ///< diffuseF90; z: 1 where a metallic-roughness texture makes the model per point
  float diffuseF0[4];  ///< rgb: GGX's diffuseF0 (GgxLobeParameters)
};
static_assert(sizeof(HighlightModelGpu) == 64);

/// Kinds of HighlightLightGpu and HighlightModelGpu (GLSL constants of highlightGlslConstants).
inline constexpr uint32_t kHighlightPoint = 0, kHighlightSpot = 1, kHighlightDirectional = 2;
inline constexpr uint32_t kHighlightNoModel = 0, kHighlightBlinnPhong = 1, kHighlightGgx = 2;

/// The scene's delta lights, in its order.
std::vector<HighlightLightGpu> highlightLights(const Scene& scene);
/// Per material of the scene (kHighlightNoModel for what no glossy chart evaluates: rough glass).
std::vector<HighlightModelGpu> highlightModels(const Scene& scene);

/// The storage-buffer bindings of the lights and the models.
inline constexpr uint32_t kHighlightLightsBinding = 20, kHighlightModelsBinding = 21;
/// GLSL constants of the kinds and the bindings (prefixed to kHighlightsGlsl's programs).
std::string highlightGlslConstants();

/// GLSL: vec3 punctualHighlights(uint record, uint triangle, vec2 uv, vec3 towardsViewer) —
/// PunctualHighlights::radiance at barycentrics uv of `triangle`, seen as chart record
/// `record` (viewedRecord) from unit direction towardsViewer — on a glossy record where
/// glossyHighlights (gpuHighlightsActive), on a mirror-like specular record always; uniforms
/// highlightLightCount, glossyHighlights and shadowsPassThinGlass (Scene::hasThinGlass). Needs kBvhGlsl, kSurfaceGlsl and the lookup's
/// chart records and the surface detail's GLSL before it.
extern const char* const kHighlightsGlsl;

}  // namespace pl
