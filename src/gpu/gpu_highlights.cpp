// Punctual lights' highlights in the GPU renderer (gpu_highlights.h).
#include "gpu/gpu_highlights.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <optional>

#include "bsdf/bsdf.h"
#include "bsdf/ggx_lobe.h"
#include "light/lights.h"
#include "scene/scene.h"

namespace pl {

bool gpuHighlightsActive(const LightField& lf) {
  if (!lf.settings.punctualHighlights) return false;
  const bool glossy = std::any_of(lf.charts.begin(), lf.charts.end(), [](const Chart& c) { return c.kind == ChartKind::Glossy; });
  return glossy && std::any_of(lf.scene.lights.begin(), lf.scene.lights.end(), [](const Light& l) { return isDeltaLight(l); });
}

std::vector<HighlightLightGpu> highlightLights(const Scene& scene) {
  std::vector<HighlightLightGpu> result;
  for (const Light& light : scene.lights) {
    if (!isDeltaLight(light)) continue;
    HighlightLightGpu g{};
    uint32_t kind = kHighlightPoint;
    Vec3 position(0.0f), axis(0.0f);
    Rgb intensity(0.0f);
    if (const auto* point = std::get_if<PointLight>(&light)) {
      position = point->position, intensity = point->intensity;
    } else if (const auto* spot = std::get_if<SpotLight>(&light)) {
      kind = kHighlightSpot;
      position = spot->position, intensity = spot->intensity, axis = spot->axis;
      g.cone[0] = spot->cosInner, g.cone[1] = spot->cosOuter;
    } else if (const auto* sun = std::get_if<DirectionalLight>(&light)) {
      kind = kHighlightDirectional;
      position = -sun->travel(), intensity = sun->irradiance;  // DirectionalLight::sample's wi
    }
    for (int k = 0; k < 3; ++k) g.position[k] = position[k], g.intensity[k] = intensity[k], g.axis[k] = axis[k];
    std::memcpy(&g.position[3], &kind, sizeof(float));
    result.push_back(g);
  }
  return result;
}

std::vector<HighlightModelGpu> highlightModels(const Scene& scene) {
  std::vector<HighlightModelGpu> result(scene.materials.size());
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    HighlightModelGpu& g = result[i];
    uint32_t kind = kHighlightNoModel;
    const Bsdf& model = scene.materials[i].bsdf;
    if (const auto* phong = std::get_if<BlinnPhongBsdf>(&model)) {
      kind = kHighlightBlinnPhong;
      const float n = std::max(0.0f, phong->exponent);
      for (int k = 0; k < 3; ++k) g.diffuse[k] = phong->diffuse[k], g.lobe[k] = phong->specular[k];
      g.lobe[3] = n;
      g.extra[0] = blinnPhongNormalization(n);
    } else if (const std::optional<GgxLobeParameters> ggx = ggxLobeParameters(model)) {
      kind = kHighlightGgx;
      for (int k = 0; k < 3; ++k) g.diffuse[k] = ggx->diffuse[k], g.lobe[k] = ggx->f0[k], g.diffuseF0[k] = ggx->diffuseF0[k];
      g.lobe[3] = ggx->alpha;
      g.extra[0] = ggx->f90;
      g.extra[1] = ggx->diffuseF90;
      g.extra[2] = scene.materials[i].metallicRoughness.texture >= 0 ? 1.0f : 0.0f;
    }
    std::memcpy(&g.diffuse[3], &kind, sizeof(float));
  }
  return result;
}

std::string highlightGlslConstants() {
  return fmt::format(
      "const uint kHighlightPoint = {}u, kHighlightSpot = {}u, kHighlightDirectional = {}u;\n"
      "const uint kHighlightNoModel = {}u, kHighlightBlinnPhong = {}u, kHighlightGgx = {}u;\n"
      "#define HIGHLIGHT_LIGHTS_BINDING {}\n#define HIGHLIGHT_MODELS_BINDING {}\n",
      kHighlightPoint, kHighlightSpot, kHighlightDirectional, kHighlightNoModel, kHighlightBlinnPhong, kHighlightGgx,
      kHighlightLightsBinding, kHighlightModelsBinding);
}

// PunctualHighlights::radiance (lookup.cpp) with what it calls — scatteringFrame and
// usableSide (scene.cpp) of a reflecting model, sampleLight of the delta lights
// (lights.cpp incidentFromPoint, SpotLight::sample, DirectionalLight::sample), eval of
// Blinn-Phong and the GGX-like models (bsdf.cpp evalBlinnPhong, evalGgx, evalGltfPbr with its
// clear coat and sheen, ggxSpecular, ggxD, ggxLambda, charlieD, charlieL, charlieLambda,
// charlieLobe), materialModelAt of a metallic-roughness texture,
// shadowRayTowards (light.cpp) and ShadowRays::transmittance — statement for statement.
const char* const kHighlightsGlsl = R"glsl(
struct HighlightLight { vec4 position; vec4 intensity; vec4 axis; vec4 cone; };
layout(std430, binding = HIGHLIGHT_LIGHTS_BINDING) readonly buffer HighlightLights { HighlightLight highlightLights[]; };
struct HighlightModel { vec4 diffuse; vec4 lobe; vec4 extra; vec4 diffuseF0; };
layout(std430, binding = HIGHLIGHT_MODELS_BINDING) readonly buffer HighlightModels { HighlightModel highlightModels[]; };
uniform uint highlightLightCount;
uniform bool glossyHighlights;  // gpuHighlightsActive: the glossy records' highlights too
uniform bool shadowsPassThinGlass;

float ggxD(float alpha, vec3 h) {
  float a2 = alpha * alpha;
  float c2 = h.z * h.z;
  float d = c2 * (a2 - 1.0) + 1.0;
  return a2 / (3.14159265358979 * d * d);
}
float ggxLambda(float alpha, vec3 w) {
  float c2 = w.z * w.z;
  if (c2 <= 0.0) return 1.0 / 0.0;
  float tan2 = max(0.0, 1.0 - c2) / c2;
  return 0.5 * (sqrt(1.0 + alpha * alpha * tan2) - 1.0);
}
// ggxSpecular (bsdf.cpp): the GGX lobe α (clamped) with Schlick's Fresnel f0 → f90.
vec3 ggxSpecular(float alpha, vec3 f0, float f90, vec3 wo, vec3 wi) {
  alpha = clamp(alpha, kGgxMinAlpha, 1.0);
  vec3 h = normalize(wo + wi);
  float g2 = 1.0 / (1.0 + ggxLambda(alpha, wo) + ggxLambda(alpha, wi));
  float c = clamp(1.0 - dot(wo, h), 0.0, 1.0), c2 = c * c;
  vec3 fresnel = f0 + (vec3(f90) - f0) * (c2 * c2 * c);
  return fresnel * (ggxD(alpha, h) * g2 / (4.0 * wo.z * wi.z));
}
// The sheen's Charlie lobe D G / (4 cos θo cos θi) for roughness r (clamped): charlieD,
// Estevez & Kulla's fit charlieL of ln Λ, charlieLambda, charlieLobe (bsdf.cpp).
float charlieD(float r, float cosH) {
  float invR = 1.0 / r;
  float sin2 = max(0.0, 1.0 - cosH * cosH);
  return (2.0 + invR) * pow(sin2, 0.5 * invR) * (0.5 * kInvPi);
}
float charlieL(float x, float r) {
  float t = (1.0 - r) * (1.0 - r);
  float a = mix(21.5473, 25.3245, t), b = mix(3.82987, 3.32435, t);
  float c = mix(0.19823, 0.16801, t), d = mix(-1.97760, -1.27393, t);
  float e = mix(-4.32054, -4.85967, t);
  return a / (1.0 + b * pow(x, c)) + d * x + e;
}
float charlieLambda(float cosTheta, float r) {
  return cosTheta < 0.5 ? exp(charlieL(cosTheta, r)) : exp(2.0 * charlieL(0.5, r) - charlieL(1.0 - cosTheta, r));
}
float charlieLobe(float r, vec3 wo, vec3 wi) {
  vec3 h = normalize(wo + wi);
  return charlieD(r, h.z) / ((1.0 + charlieLambda(wo.z, r) + charlieLambda(wi.z, r)) * 4.0 * wo.z * wi.z);
}
// eval of the chart's model in the local frame: Blinn-Phong's (m), or the GGX-like `ggx` under
// `layers` (evalGgx; evalGltfPbr, its clear coat and sheen); withDiffuse: the diffuse part too.
vec3 evalHighlightModel(HighlightModel m, GgxLobe ggx, PbrLayers layers, bool withDiffuse, vec3 wo, vec3 wi) {
  if (!(wo.z > 0.0 && wi.z > 0.0)) return vec3(0.0);
  uint kind = floatBitsToUint(m.diffuse.w);
  if (kind == kHighlightBlinnPhong) {
    vec3 h = normalize(wo + wi);
    vec3 diffuse = withDiffuse ? m.diffuse.rgb : vec3(0.0);
    return diffuse * 0.318309886183791 + m.lobe.rgb * (m.extra.x * pow(max(0.0, h.z), m.lobe.w));
  }
  if (kind != kHighlightGgx) return vec3(0.0);
  vec3 f = ggxSpecular(ggx.alpha, ggx.f0, ggx.f90, wo, wi);
  bool diffuse = withDiffuse && any(notEqual(ggx.diffuse, vec3(0.0)));
  if (!hasLayers(layers)) {
    if (diffuse)
      f += ggx.diffuse * kInvPi * ggxDiffuseFactor(ggx.alpha, ggx.diffuseF0, ggx.diffuseF90, wo.z) *
           ggxDiffuseFactor(ggx.alpha, ggx.diffuseF0, ggx.diffuseF90, wi.z);
    return f;
  }
  // evalGltfPbr: the base lobe under the sheen, the sheen, both under the coat, the coat, and
  // the diffuse part g(μo) g(μi) / Ḡ.
  vec2 o = layerAlbedos(layers, wo.z), i = layerAlbedos(layers, wi.z);
  float sheenWeight = max(0.0, max(layers.sheenColor.r, max(layers.sheenColor.g, layers.sheenColor.b)));
  f *= 1.0 - sheenWeight * max(o.y, i.y);
  if (sheenWeight > 0.0) {
    float r = layers.sheenRoughness;
    f += layers.sheenColor * (sheenAlbedo(0.0, r).y * charlieLobe(r, wo, wi));
  }
  if (layers.clearcoat > 0.0) {
    f *= 1.0 - layers.clearcoat * max(o.x, i.x);
    f += layers.clearcoat * ggxSpecular(layers.clearcoatAlpha, vec3(kClearcoatF0), 1.0, wo, wi);
  }
  if (diffuse)
    f += ggx.diffuse * kInvPi * layeredDiffuseFactor(ggx.alpha, ggx.diffuseF0, ggx.diffuseF90, layers, wo.z) *
         layeredDiffuseFactor(ggx.alpha, ggx.diffuseF0, ggx.diffuseF90, layers, wi.z);
  return f;
}
// The GGX-like model of material `material` at barycentrics uv of `triangle`: the material's
// (highlightModels), or with a metallic-roughness texture the point's (materialModelAt at
// albedoPointAt: the albedo texture at full resolution × the vertex colour, the texel).
GgxLobe highlightLobe(HighlightModel m, uint material, uint triangle, vec2 uv) {
  GgxLobe l = GgxLobe(m.diffuse.rgb, m.lobe.w, m.lobe.rgb, m.extra.x, m.diffuseF0.rgb, m.extra.y);
  if (m.extra.z == 0.0) return l;
  uint record = detail[2] + kMaterialWords * material;
  uvec3 v = triangles[triangle].xyz;
  vec3 modulation = vertexColorAt(v, uv);
  if (detail[record] != kNone) modulation = sampleTexture(detail[record], mappedUv(record + kMaterialAlbedoMapping, v, uv)) * modulation;
  return metallicRoughnessLobe(record, modulation, metallicRoughnessTexelAt(record, v, uv));
}
// ShadowRays::transmittance of the ray (origin, direction) over (0, tMax).
vec3 shadowTransmittance(vec3 origin, vec3 direction, float tMax) {
  if (!shadowsPassThinGlass) return bvhOccluded(origin, direction, 0.0, tMax) ? vec3(0.0) : vec3(1.0);
  vec3 transmittance = vec3(1.0);
  vec3 start = origin;
  float tEnd = tMax;
  for (;;) {
    float t;
    uint triangle;
    vec2 uv;
    if (!bvhIntersect(origin, direction, 0.0, tMax, t, triangle, uv)) return transmittance;
    vec3 position, geometricNormal, shadingNormal;
    surfaceAt(triangle, uv, position, geometricNormal, shadingNormal);
    SpecularMaterial m = specularMaterials[triangleMaterials[triangle]];
    if (floatBitsToUint(m.colour.w) != kSpecularGlass || m.iface.y == 0.0) return vec3(0.0);
    vec3 reflectance, straight;
    thinSheetReflectanceTransmittance(m, dot(shadingNormal, direction), reflectance, straight);
    transmittance *= straight;
    if (all(equal(transmittance, vec3(0.0)))) return transmittance;
    // Continue from just past the sheet; the remaining length is measured from the start.
    origin = offsetRayOrigin(position, geometricNormal, direction);
    tMax = isinf(tEnd) ? tEnd : tEnd - dot(origin - start, direction);
    if (!(tMax > 0.0)) return transmittance;
  }
}
vec3 punctualHighlights(uint record, uint triangle, vec2 uv, vec3 towardsViewer) {
  if (highlightLightCount == 0u) return vec3(0.0);
  uint material = triangleMaterials[triangle];
  // A glossy record's when the bake kept them out of its maps; a specular record's only when
  // mirror-like (a model that is neither mirror nor glass), whatever the setting.
  uint kind = charts[record].info.y;
  if (kind == kGlossy ? !glossyHighlights
                      : kind != kSpecular || floatBitsToUint(specularMaterials[material].colour.w) != kSpecularOther)
    return vec3(0.0);
  HighlightModel model = highlightModels[material];
  if (floatBitsToUint(model.diffuse.w) == kHighlightNoModel) return vec3(0.0);  // rough glass keeps them in its maps
  bool withDiffuse = (charts[record].info.z & kFlagDiffuseValue) == 0u;
  GgxLobe ggx = highlightLobe(model, material, triangle, uv);
  PbrLayers layers = pbrLayersAt(detail[2] + kMaterialWords * material + kMaterialDiffuseLobe);
  // scatteringFrame of a reflecting model: both normals turned to the viewer's side.
  ScatteringFrame frame = scatteringFrameAt(triangle, uv, towardsViewer);
  vec3 position = frame.position, g = frame.g;
  vec3 wo = toLocal(frame, towardsViewer);
  if (!(dot(towardsViewer, g) > 0.0)) return vec3(0.0);
  vec3 sum = vec3(0.0);
  for (uint l = 0u; l < highlightLightCount; ++l) {
    HighlightLight light = highlightLights[l];
    uint kind = floatBitsToUint(light.position.w);
    vec3 wi = light.position.xyz, incident = light.intensity.rgb;
    bool finite = kind != kHighlightDirectional;
    if (finite) {
      vec3 toLight = light.position.xyz - position;
      float distanceSquared = dot(toLight, toLight);
      if (!(distanceSquared > 0.0)) continue;
      wi = toLight / sqrt(distanceSquared);
      float falloff = 1.0;
      if (kind == kHighlightSpot) {
        float c = dot(light.axis.xyz, -wi), cosInner = light.cone.x, cosOuter = light.cone.y;
        if (cosInner <= cosOuter) {
          falloff = c >= cosInner ? 1.0 : 0.0;
        } else {
          float x = clamp((c - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
          falloff = x * x * (3.0 - 2.0 * x);
        }
      }
      if (!(falloff > 0.0)) continue;
      incident = light.intensity.rgb * (falloff / distanceSquared);
    }
    vec3 wiLocal = toLocal(frame, wi);
    if (!(dot(wi, g) > 0.0)) continue;
    vec3 f = evalHighlightModel(model, ggx, layers, withDiffuse, wo, wiLocal);
    float cosIn = abs(wiLocal.z);
    if (all(equal(f, vec3(0.0))) || !(cosIn > 0.0) || all(equal(incident, vec3(0.0)))) continue;
    // shadowRayTowards: to the light's position, or unbounded along wi at infinity.
    vec3 origin = offsetRayOrigin(position, g, wi);
    vec3 direction = wi;
    float tMax = 1.0 / 0.0;
    if (finite) {
      vec3 toTarget = light.position.xyz - origin;
      float distance = length(toTarget);
      if (!(distance > 0.0)) continue;
      direction = toTarget / distance;
      tMax = distance;
    }
    vec3 visible = shadowTransmittance(origin, direction, tMax);
    if (any(notEqual(visible, vec3(0.0)))) sum += visible * f * cosIn * incident;
  }
  return sum;
}
)glsl";

}  // namespace pl
