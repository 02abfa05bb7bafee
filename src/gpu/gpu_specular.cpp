// Mirrors and smooth glass in the GPU renderer (gpu_specular.h).
#include "gpu/gpu_specular.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

#include "bsdf/bsdf.h"
#include "lightfield/lookup.h"
#include "scene/scene.h"

namespace pl {

bool hasSpecularCharts(const LightField& lf) {
  return std::any_of(lf.charts.begin(), lf.charts.end(), [](const Chart& c) { return c.kind == ChartKind::Specular; });
}

std::string gpuUnsupportedSpecular(const LightField& lf) {
  const Scene& scene = lf.scene;
  for (const Chart& c : lf.charts) {
    if (c.kind != ChartKind::Specular) continue;
    const Material& m = scene.materials[c.material];
    // An albedo texture or vertex colours leave a mirror's or glass's model as it is
    // (materialModelAt: withDiffuseAlbedo of a model without a diffuse part), so the chains
    // read none of them; only glTF's layered model would be made anew per point.
    if (m.layers.layered && (m.layers.any() || m.modelVaries())) return "glTF layered materials on mirrors and glass";
  }
  return {};
}

std::vector<SpecularMaterialGpu> specularMaterials(const Scene& scene) {
  std::vector<SpecularMaterialGpu> result(scene.materials.size());
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    SpecularMaterialGpu& g = result[i];
    uint32_t kind = kSpecularOther;
    if (const auto* mirror = std::get_if<MirrorBsdf>(&m.bsdf)) {
      kind = kSpecularMirror;
      g.colour[0] = mirror->reflectance.r, g.colour[1] = mirror->reflectance.g, g.colour[2] = mirror->reflectance.b;
      g.dielectric[2] = mirror->fresnel ? 1.0f : 0.0f;
    } else if (const auto* glass = std::get_if<DielectricBsdf>(&m.bsdf)) {
      // followSpecular follows every glass as smooth (a rough one is a glossy chart).
      kind = kSpecularGlass;
      g.colour[0] = glass->transmittance.r, g.colour[1] = glass->transmittance.g, g.colour[2] = glass->transmittance.b;
      g.dielectric[0] = glass->ior;
      g.dielectric[1] = glass->thin ? 1.0f : 0.0f;
    }
    std::memcpy(&g.colour[3], &kind, sizeof(float));
    const Rgb sigma = interiorAbsorption(m.bsdf);
    g.absorption[0] = sigma.r, g.absorption[1] = sigma.g, g.absorption[2] = sigma.b;
    g.emission[0] = m.emission.r, g.emission[1] = m.emission.g, g.emission[2] = m.emission.b;
    g.emission[3] = m.twoSidedEmission ? 1.0f : 0.0f;
  }
  return result;
}

std::string specularGlslConstants() {
  return fmt::format("const uint kSpecularOther = {}u, kSpecularMirror = {}u, kSpecularGlass = {}u;\n"
                     "const uint kSpecularRouletteStep = {}u, kFirstHitLobeSamples = {}u;\n"
                     "#define SPECULAR_MATERIALS_BINDING {}\n#define TRIANGLE_MATERIALS_BINDING {}\n",
                     kSpecularOther, kSpecularMirror, kSpecularGlass, kSpecularRouletteStep, kFirstHitLobeSamples,
                     kSpecularMaterialsBinding,
                     kTriangleMaterialsBinding);
}

// followSpecular (lookup.cpp) with what it calls — surfaceAt's normals and point (scene.cpp),
// interiorTransmittance and emittedRadiance (scene.h), scatteringFrame, usableSide and scatter
// (scene.cpp), Frame::fromNormal (core/math.h), the mirror's and smooth glass's sample
// (bsdf.cpp: sample, sampleSmoothDielectric, thinSheetReflectanceTransmittance,
// fresnelDielectricTransmittance, refractDirection; bsdf.h fresnelSchlick) and
// offsetRayOrigin (accel.h) — statement for statement; then the fast renderer's chain.
const char* const kSurfaceGlsl = R"glsl(
struct SpecularMaterial { vec4 colour; vec4 iface; vec4 absorption; vec4 emission; };
layout(std430, binding = SPECULAR_MATERIALS_BINDING) readonly buffer SpecularMaterials { SpecularMaterial specularMaterials[]; };
layout(std430, binding = TRIANGLE_MATERIALS_BINDING) readonly buffer TriangleMaterials { uint triangleMaterials[]; };

float luminanceOf(vec3 c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }
float transmittedShare(float a, float b) { return 4.0 * a * b / ((a + b) * (a + b)); }
float fresnelDielectricTransmittance(float cosTheta, float eta) {
  cosTheta = clamp(cosTheta, -1.0, 1.0);
  if (cosTheta < 0.0) {
    eta = 1.0 / eta;
    cosTheta = -cosTheta;
  }
  float sin2T = (1.0 - cosTheta * cosTheta) / (eta * eta);
  if (sin2T >= 1.0) return 0.0;
  float cosT = sqrt(max(0.0, 1.0 - sin2T));
  return 0.5 * (transmittedShare(eta * cosTheta, cosT) + transmittedShare(cosTheta, eta * cosT));
}
float fresnelDielectric(float cosTheta, float eta) { return 1.0 - fresnelDielectricTransmittance(cosTheta, eta); }
void thinSheetReflectanceTransmittance(SpecularMaterial m, float cosTheta, out vec3 reflectance, out vec3 transmittance) {
  float R = fresnelDielectric(abs(cosTheta), m.iface.x), T = fresnelDielectricTransmittance(abs(cosTheta), m.iface.x);
  reflectance = vec3(1.0);
  transmittance = vec3(0.0);
  if (!(T > 0.0)) return;
  vec3 t = m.colour.rgb;
  vec3 denom = vec3(1.0) - R * R * t * t;
  reflectance = vec3(R) + T * T * R * t * t / denom;
  transmittance = T * T * t / denom;
}
// surfaceAt (scene.cpp): the point from the barycentrics (b1, b2), the unit winding normal,
// the interpolated shading normal on its side (interpolatedNormal), bent by the material's
// normal map (TRACED_DETAIL: gpu_surface_detail.h tracedSurfaceDetail).
void surfaceAt(uint triangle, vec2 uv, out vec3 position, out vec3 geometricNormal, out vec3 shadingNormal) {
  uvec4 tri = triangles[triangle];
  vec3 p0 = positions[tri.x].xyz, p1 = positions[tri.y].xyz, p2 = positions[tri.z].xyz;
  float b1 = uv.x, b2 = uv.y, b0 = 1.0 - b1 - b2;
  position = b0 * p0 + b1 * p1 + b2 * p2;
  geometricNormal = normalize(cross(p1 - p0, p2 - p0));
  shadingNormal = geometricNormal;
  if (normals[tri.x].w != 0.0) {
    vec3 n = b0 * normals[tri.x].xyz + b1 * normals[tri.y].xyz + b2 * normals[tri.z].xyz;
    float len = length(n);
    if (len > 1e-6 && !isinf(len) && !isnan(len)) {
      shadingNormal = n / len;
      if (dot(shadingNormal, geometricNormal) < 0.0) shadingNormal = -shadingNormal;
    }
  }
#ifdef TRACED_DETAIL
  shadingNormal = mappedNormalAt(materialRecord(triangle), tri.xyz, p0, p1, p2, uv, geometricNormal, shadingNormal);
#endif
}
// Frame::fromNormal (core/math.h): the tangents s, t of unit normal n.
void frameFromNormal(vec3 n, out vec3 s, out vec3 t) {
  float sign = (floatBitsToUint(n.z) >> 31) != 0u ? -1.0 : 1.0;  // copysign(1, n.z)
  float a = -1.0 / (sign + n.z);
  float b = n.x * n.y * a;
  s = vec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
  t = vec3(b, sign + n.y * n.y * a, -n.y);
}
// scatteringFrame (bsdf.h) of a reflecting model at barycentrics uv of `triangle`, seen from
// unit world direction `towards`: surfaceAt's point, both normals turned to that side (g, n)
// and n's tangents (s, t).
struct ScatteringFrame { vec3 position, g, n, s, t; };
ScatteringFrame scatteringFrameAt(uint triangle, vec2 uv, vec3 towards) {
  ScatteringFrame f;
  vec3 geometricNormal, shadingNormal;
  surfaceAt(triangle, uv, f.position, geometricNormal, shadingNormal);
  bool turn = dot(geometricNormal, towards) < 0.0;
  f.g = turn ? -geometricNormal : geometricNormal;
  f.n = turn ? -shadingNormal : shadingNormal;
  frameFromNormal(f.n, f.s, f.t);
  return f;
}
// World direction d in frame f's local coordinates (z along the shading normal).
vec3 toLocal(ScatteringFrame f, vec3 d) { return vec3(dot(d, f.s), dot(d, f.t), dot(d, f.n)); }
// offsetRayOrigin (accel.h).
vec3 offsetRayOrigin(vec3 position, vec3 geometricNormal, vec3 direction) {
  float scale = 1.0 + max(abs(position.x), max(abs(position.y), abs(position.z)));
  float offset = 2e-5 * scale;
  return position + (dot(direction, geometricNormal) >= 0.0 ? offset : -offset) * geometricNormal;
}
)glsl";

const char* const kSpecularGlsl = R"glsl(
uint64_t specularRayHash(vec3 o, vec3 d) {
  uint64_t h = 0x5350454355UL;
  h = hashCombine(h, uint64_t(floatBitsToUint(o.x)));
  h = hashCombine(h, uint64_t(floatBitsToUint(o.y)));
  h = hashCombine(h, uint64_t(floatBitsToUint(o.z)));
  h = hashCombine(h, uint64_t(floatBitsToUint(d.x)));
  h = hashCombine(h, uint64_t(floatBitsToUint(d.y)));
  return hashCombine(h, uint64_t(floatBitsToUint(d.z)));
}
// rayHashU2 (lookup.cpp): two numbers in [0, 1) from the ray's hash and `salt`; sample k > 0 of
// a split is Sobol point k rotated by sample 0's numbers (24-bit fixed point, modulo 2^24).
// specularLobeU's salt is 0x4c4f4245, nextEventU's 0x4e45454c.
vec2 rayHashU2(uint64_t rayHash, uint64_t salt, uint k) {
  uint64_t h = hashCombine(rayHash, salt);
  uint x = uint(h >> 40), y = uint((h >> 16) & 0xffffffUL);
  if (k > 0u) {
    x = (x + (bitfieldReverse(k) >> 8)) & 0xffffffu;  // reversedSobolPoint(k, 0) = k
    y = (y + (bitfieldReverse(reversedSobolSecond(k)) >> 8)) & 0xffffffu;
  }
  return vec2(float(x) * exp2(-24.0), float(y) * exp2(-24.0));
}
// The sample in the local frame: false when the BSDF returns nothing.
bool sampleSpecular(SpecularMaterial m, vec3 wo, float u, out vec3 wi, out vec3 weight) {
  uint kind = floatBitsToUint(m.colour.w);
  wi = vec3(0.0);
  weight = vec3(0.0);
  if (kind == kSpecularMirror) {
    if (!(wo.z > 0.0)) return false;
    wi = vec3(-wo.x, -wo.y, wo.z);
    float f = clamp(1.0 - wo.z, 0.0, 1.0), f2 = f * f;
    weight = m.iface.z != 0.0 ? m.colour.rgb + (vec3(1.0) - m.colour.rgb) * (f2 * f2 * f) : m.colour.rgb;
    return true;
  }
  if (kind != kSpecularGlass) return false;
  if (!(wo.z != 0.0) || any(isinf(wo)) || any(isnan(wo))) return false;
  float ior = m.iface.x;
  if (m.iface.y != 0.0) {
    vec3 r, t;
    thinSheetReflectanceTransmittance(m, wo.z, r, t);
    float lr = max(0.0, luminanceOf(r)), lt = max(0.0, luminanceOf(t));
    if (!(lr + lt > 0.0)) return false;
    float pR = lr / (lr + lt);
    if (u < pR) {
      wi = vec3(-wo.x, -wo.y, wo.z);
      weight = r / pR;
    } else {
      wi = -wo;
      weight = t / (1.0 - pR);
    }
    return true;
  }
  float F = fresnelDielectric(wo.z, ior);
  if (u < F) {
    wi = vec3(-wo.x, -wo.y, wo.z);
    weight = vec3(1.0);
    return true;
  }
  float etap = wo.z > 0.0 ? ior : 1.0 / ior;
  vec3 n = vec3(0.0, 0.0, wo.z > 0.0 ? 1.0 : -1.0);
  // refractDirection
  float cosI = dot(n, wo);
  float sin2T = max(0.0, 1.0 - cosI * cosI) / (etap * etap);
  if (sin2T >= 1.0) return false;
  float cosT = sqrt(1.0 - sin2T);
  wi = -wo / etap + (cosI / etap - cosT) * n;
  weight = m.colour.rgb / (etap * etap);
  return true;
}
// followSpecular at the hit (t, triangle, uv) of the ray (origin, direction); a mirror-like
// lobe (kSpecularOther on a specular record) sampled with specularLobeU(ray, lobeSample).
// lobePdf and straightThrough: SpecularStep's.
bool followSpecular(vec3 origin, vec3 direction, float t, uint triangle, vec2 uv, uint step, uint stepLimit, uint lobeSample,
                    out vec3 emitted, out vec3 nextOrigin, out vec3 nextDirection, out vec3 weight, out float lobePdf,
                    out bool straightThrough) {
  nextOrigin = vec3(0.0);
  nextDirection = vec3(0.0);
  weight = vec3(0.0);
  lobePdf = 0.0;
  straightThrough = false;
  vec3 position, geometricNormal, shadingNormal;
  surfaceAt(triangle, uv, position, geometricNormal, shadingNormal);
  SpecularMaterial m = specularMaterials[triangleMaterials[triangle]];
  vec3 wo = -direction;
  float cosWoGeometric = dot(geometricNormal, wo);
  vec3 attenuation = vec3(1.0);
  if (cosWoGeometric < 0.0 && any(notEqual(m.absorption.rgb, vec3(0.0)))) attenuation = exp(-m.absorption.rgb * t);
  vec3 emission = cosWoGeometric > 0.0 || m.emission.w != 0.0 ? m.emission.rgb : vec3(0.0);
#ifdef TRACED_DETAIL
  emission *= emissionTexelAt(materialRecord(triangle), triangles[triangle].xyz, uv);  // emissionModulation
#endif
  emitted = emission * attenuation;
  if (step >= stepLimit) return false;
  // scatteringFrame: a reflecting model's frame turned to wo's side, glass's never.
  uint kind = floatBitsToUint(m.colour.w);
  bool glass = kind == kSpecularGlass;
  bool turn = cosWoGeometric < 0.0 && !glass;
  vec3 g = turn ? -geometricNormal : geometricNormal;
  vec3 n = turn ? -shadingNormal : shadingNormal;
  vec3 s, tt;
  frameFromNormal(n, s, tt);
  vec3 woLocal = vec3(dot(wo, s), dot(wo, tt), dot(wo, n));
  // usableSide for wo, the sample, usableSide for wi.
  float cosWo = dot(wo, g);
  if (!(glass ? cosWo * woLocal.z > 0.0 : cosWo > 0.0)) return false;
  uint64_t hash = specularRayHash(origin, direction);
  vec3 wiLocal, sampleWeight;
#ifdef MIRROR_LIKE
  if (kind == kSpecularOther) {
    if (!sampleMirrorLikeLobe(highlightModels[triangleMaterials[triangle]], woLocal, rayHashU2(hash, 0x4c4f4245UL, lobeSample),
                              wiLocal, sampleWeight, lobePdf))
      return false;
  } else
#endif
  {
    float branchU = float(uint(hash >> 40)) * exp2(-24.0);
    if (!sampleSpecular(m, woLocal, branchU, wiLocal, sampleWeight)) return false;
  }
  vec3 wi = wiLocal.x * s + wiLocal.y * tt + wiLocal.z * n;
  float cosWi = dot(wi, g);
  if (!(glass ? cosWi * wiLocal.z > 0.0 : cosWi > 0.0)) return false;
  nextOrigin = offsetRayOrigin(position, g, wi);
  nextDirection = wi;
  weight = sampleWeight * attenuation;
  straightThrough = glass && m.iface.y != 0.0 && woLocal.z * wiLocal.z < 0.0;
  if (step >= kSpecularRouletteStep) {
    float survival = min(1.0, max(weight.r, max(weight.g, weight.b)));
    float rouletteU = float(uint((hash >> 16) & 0xffffffUL)) * exp2(-24.0);
    if (!(rouletteU < survival)) return false;
    weight /= survival;
  }
  return true;
}
#ifdef LOBE_LIGHTS
// MirrorLikeLights (lookup.h) with nextEventEstimate (light.cpp, NextEvent::MisExceptDelta):
// the light sample at a mirror-like hit and the power-heuristic weights of what the lobe's
// sampled rays find. lobePdf 0 (a camera ray, a delta step): every weight 1, nothing added.
const PbrLayers kNoLobeLayers = PbrLayers(0.0, 0.0, vec3(0.0), 0.0, vec3(0.0));
vec3 lobeLightRadiance(vec3 origin, vec3 direction, uint triangle, vec2 uv, uint k) {
  uint material = triangleMaterials[triangle];
  if (floatBitsToUint(specularMaterials[material].colour.w) != kSpecularOther) return vec3(0.0);
  HighlightModel model = highlightModels[material];
  vec3 wo = -direction;
  ScatteringFrame frame = scatteringFrameAt(triangle, uv, wo);
  vec3 position = frame.position, g = frame.g;
  vec3 woLocal = toLocal(frame, wo);
  if (!(dot(wo, g) > 0.0)) return vec3(0.0);
  LightSampleGpu light;
  if (!lightSample(position, rayHashU2(specularRayHash(origin, direction), 0x4e45454cUL, k), light) || light.delta)
    return vec3(0.0);
  vec3 wiLocal = toLocal(frame, light.wi);
  if (!(dot(light.wi, g) > 0.0)) return vec3(0.0);
  vec3 f = evalHighlightModel(model, mirrorLikeGgx(model), kNoLobeLayers, false, woLocal, wiLocal);
  float cosIn = abs(wiLocal.z);
  if (all(equal(f, vec3(0.0))) || !(cosIn > 0.0)) return vec3(0.0);
  vec3 shadowOrigin = offsetRayOrigin(position, g, light.wi);
  vec3 shadowDirection = light.wi;
  float tMax = 1.0 / 0.0;
  if (!light.infinite) {  // shadowRayTo
    vec3 toTarget = light.target - shadowOrigin;
    float distance = length(toTarget);
    if (!(distance > 0.0)) return vec3(0.0);
    shadowDirection = toTarget / distance;
    tMax = distance;
  }
  vec3 visible = shadowTransmittance(shadowOrigin, shadowDirection, tMax);
  if (all(equal(visible, vec3(0.0)))) return vec3(0.0);
  return visible * f * cosIn * light.incident / light.pdf * powerHeuristic(light.pdf, mirrorLikeLobePdf(model, woLocal, wiLocal));
}
// emissionWeight: `distance` from the lobe's vertex to the hit on `triangle`.
float lobeEmissionWeight(vec3 direction, uint triangle, float lobePdf, float distance) {
  if (!(lobePdf > 0.0)) return 1.0;
  uvec4 tri = triangles[triangle];
  vec3 p0 = positions[tri.x].xyz;
  vec3 normal = cross(positions[tri.y].xyz - p0, positions[tri.z].xyz - p0);
  float length2 = dot(normal, normal);
  normal = length2 > 0.0 ? normal / sqrt(length2) : vec3(0.0);  // triangleNormal
  return powerHeuristic(lobePdf, emitterPdf(triangle, distance, abs(dot(normal, direction))));
}
float lobeEnvironmentWeight(vec3 direction, float lobePdf) {
  return lobePdf > 0.0 ? powerHeuristic(lobePdf, environmentLightPdf(direction)) : 1.0;
}
vec3 lobeSphereEmission(vec3 origin, vec3 direction, float tHit, float lobePdf, float lobeDistance) {
  vec3 radiance;
  float pdf;
  if (!(lobePdf > 0.0) || !sphereLightAlong(origin, direction, 0.0, tHit, origin - lobeDistance * direction, radiance, pdf))
    return vec3(0.0);
  return radiance * powerHeuristic(lobePdf, pdf);
}
// overcountedEmission at the hit (uv on `triangle`, `distance` from the lobe's vertex).
vec3 lobeOvercountedEmission(vec3 direction, uint triangle, vec2 uv, float lobePdf, float distance) {
  if (!(lobePdf > 0.0)) return vec3(0.0);
  SpecularMaterial m = specularMaterials[triangleMaterials[triangle]];
  uvec4 tri = triangles[triangle];
  vec3 p0 = positions[tri.x].xyz;
  float cosFront = -dot(cross(positions[tri.y].xyz - p0, positions[tri.z].xyz - p0), direction);
  vec3 le = cosFront > 0.0 || m.emission.w != 0.0 ? m.emission.rgb : vec3(0.0);
  if (all(equal(le, vec3(0.0)))) return vec3(0.0);
#ifdef TRACED_DETAIL
  le *= emissionTexelAt(materialRecord(triangle), tri.xyz, uv);
#endif
  return (1.0 - lobeEmissionWeight(direction, triangle, lobePdf, distance)) * le;
}
#endif
// The fast renderer's chain (realtime.h step 3) of the ray (origin, direction) from its
// `firstStep`-th specular step on: `hit` with (t, triangle, uv) its closest hit, `throughput`
// its weight, `distance` the chain's length up to its origin (the lookup at its end reads the
// surface detail with a ray cone coneSpread × the summed length, as the CPU renderer does),
// lobePdf and lobeDistance the MIS state (LobeChain).
vec3 followChain(vec3 origin, vec3 direction, bool hit, float t, uint triangle, vec2 uv, uint firstStep, uint stepLimit,
                 vec3 throughput, float distance, float lobePdf, float lobeDistance) {
  vec3 radiance = vec3(0.0);
  for (uint step = firstStep;; ++step) {
#ifdef LOBE_LIGHTS
    radiance += throughput * lobeSphereEmission(origin, direction, hit ? t : 1.0 / 0.0, lobePdf, lobeDistance);
#endif
    if (!hit) {
      vec3 sky = environmentRadiance(direction);
#ifdef LOBE_LIGHTS
      sky *= lobeEnvironmentWeight(direction, lobePdf);
#endif
      return radiance + throughput * sky;
    }
    distance += t;
    uvec4 tri = triangles[triangle];
    vec3 normalAtHit, shadingNormal;
    hitNormals(tri, uv, normalAtHit, shadingNormal);
    uint record = viewedRecord(tri.w, -direction, normalAtHit);
    if (record == kNoRecord) return radiance;  // inside a closed smooth mesh: nothing seen
    if (charts[record].info.y != kSpecular) {
      SurfaceDetail detail = hitSurfaceDetail(triangle, uv, direction, coneSpread * distance);
      vec3 seen = lookupRadiance(tri.w, origin + t * direction, -direction, normalAtHit, shadingNormal, detail);
#ifdef LOBE_LIGHTS
      seen -= lobeOvercountedEmission(direction, triangle, uv, lobePdf, lobeDistance + t);
#endif
      radiance += throughput * seen;
#ifdef HIGHLIGHTS
      radiance += throughput * punctualHighlights(record, triangle, uv, -direction);
#endif
      return radiance;
    }
    vec3 emitted, nextOrigin, nextDirection, weight;
    float stepPdf;
    bool straight;
    bool more = followSpecular(origin, direction, t, triangle, uv, step, stepLimit, 0u, emitted, nextOrigin, nextDirection,
                               weight, stepPdf, straight);
#ifdef LOBE_LIGHTS
    emitted *= lobeEmissionWeight(direction, triangle, lobePdf, lobeDistance + t);
#endif
    radiance += throughput * emitted;
#ifdef HIGHLIGHTS
    radiance += throughput * punctualHighlights(record, triangle, uv, -direction);  // a mirror-like lobe's
#endif
#ifdef LOBE_LIGHTS
    radiance += throughput * lobeLightRadiance(origin, direction, triangle, uv, 0u);
#endif
    if (!more) return radiance;
    throughput *= weight;
    if (straight) {
      lobeDistance += t;
    } else {
      lobePdf = stepPdf;
      lobeDistance = 0.0;
    }
    origin = nextOrigin;
    direction = nextDirection;
    hit = bvhIntersect(origin, direction, 0.0, 1.0 / 0.0, t, triangle, uv);
  }
}
// The radiance along a camera ray whose closest hit (t, triangle, uv) is on a specular
// record: its first specular step, split into kFirstHitLobeSamples stratified lobe samples on
// a mirror-like lobe (firstHitLobeSamples), each with its own light sample and chain, each of
// weight 1/kFirstHitLobeSamples — the fast renderer's first hit, term for term.
vec3 specularChain(vec3 origin, vec3 direction, float t, uint triangle, vec2 uv, uint mirrorDepth) {
  uint samples = floatBitsToUint(specularMaterials[triangleMaterials[triangle]].colour.w) == kSpecularOther
                     ? kFirstHitLobeSamples
                     : 1u;
  float share = 1.0 / float(samples);
  vec3 radiance = vec3(0.0);
  for (uint k = 0u; k < samples; ++k) {
    vec3 emitted, nextOrigin, nextDirection, weight;
    float stepPdf;
    bool straight;
    bool more = followSpecular(origin, direction, t, triangle, uv, 0u, mirrorDepth, k, emitted, nextOrigin, nextDirection,
                               weight, stepPdf, straight);
    if (k == 0u) {
      radiance = emitted;
#ifdef HIGHLIGHTS
      uvec4 tri = triangles[triangle];
      vec3 normalAtHit, shadingNormal;
      hitNormals(tri, uv, normalAtHit, shadingNormal);
      radiance += punctualHighlights(viewedRecord(tri.w, -direction, normalAtHit), triangle, uv, -direction);
#endif
    }
#ifdef LOBE_LIGHTS
    radiance += share * lobeLightRadiance(origin, direction, triangle, uv, k);
#endif
    if (!more) continue;
    float nextT;
    uint nextTriangle;
    vec2 nextUv;
    bool hit = bvhIntersect(nextOrigin, nextDirection, 0.0, 1.0 / 0.0, nextT, nextTriangle, nextUv);
    // LobeChain{}.after(step, t): a straight pass keeps the camera ray's density (0).
    radiance += followChain(nextOrigin, nextDirection, hit, nextT, nextTriangle, nextUv, 1u, mirrorDepth, share * weight, t,
                            straight ? 0.0 : stepPdf, straight ? t : 0.0);
  }
  return radiance;
}
)glsl";

}  // namespace pl
