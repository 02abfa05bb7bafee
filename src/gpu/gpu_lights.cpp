// The light sampler on the GPU (gpu_lights.h).
#include "gpu/gpu_lights.h"

#include <fmt/format.h>

#include <bit>
#include <variant>

namespace pl {

std::string gpuUnsupportedLights(const LightSampler& sampler) {
  return sampler.hasEnvironment() && sampler.environment().mapProbability() > 0.0f ? "environment maps lighting mirror-like lobes"
                                                                                    : "";
}

std::vector<uint32_t> gpuLightTable(const LightSampler& sampler) {
  const auto entries = sampler.entries();
  const auto cdf = sampler.selection().cdf();
  const auto triangles = sampler.emitterTriangles();
  const auto lights = sampler.sceneLights();
  const auto entryOfTriangle = sampler.entryOfTriangle();
  LightTableHeader header;
  header.entryCount = uint32_t(entries.size());
  header.cdfRow = 2 + header.entryCount;
  header.triangleRow = header.cdfRow + uint32_t((cdf.size() + 1) / 2);
  header.sceneLightRow = header.triangleRow + 5 * uint32_t(triangles.size());
  const uint32_t entryOfTriangleRow = header.sceneLightRow + 2 * uint32_t(lights.size());
  std::vector<uint32_t> words(4 * (size_t(entryOfTriangleRow) + (entryOfTriangle.size() + 3) / 4), 0u);
  auto put = [&](size_t row, int column, float value) { words[4 * row + size_t(column)] = std::bit_cast<uint32_t>(value); };
  auto putVec = [&](size_t row, const Vec3& v, float w) {
    put(row, 0, v.x), put(row, 1, v.y), put(row, 2, v.z), put(row, 3, w);
  };
  words[0] = header.entryCount, words[1] = header.cdfRow, words[2] = header.triangleRow, words[3] = header.sceneLightRow;
  // The environment: a constant sky (a map is refused by gpuUnsupportedLights).
  if (sampler.hasEnvironment()) {
    const Rgb sky = sampler.environment().radiance(Vec3(0.0f, 0.0f, 1.0f));
    putVec(1, Vec3(sky.r, sky.g, sky.b), 0.0f);
  }
  words[7] = entryOfTriangleRow;
  for (size_t e = 0; e < entries.size(); ++e) {
    uint32_t kind = kLightEnvironment;
    if (entries[e].kind == LightSampler::Kind::Triangle) kind = kLightTriangle;
    if (entries[e].kind == LightSampler::Kind::SceneLight)
      kind = std::holds_alternative<SphereLight>(lights[entries[e].index]) ? kLightSphere : kLightDelta;
    const size_t row = 2 + e;
    words[4 * row] = kind;
    words[4 * row + 1] = entries[e].index;
    put(row, 2, sampler.selection().probability(e));
  }
  for (size_t i = 0; i < cdf.size(); ++i) {
    const auto bits = std::bit_cast<uint64_t>(cdf[i]);
    const size_t word = 4 * size_t(header.cdfRow) + 2 * i;  // packDouble2x32's order: low word first
    words[word] = uint32_t(bits), words[word + 1] = uint32_t(bits >> 32);
  }
  // Each emissive triangle's index among the scene's (entryOfTriangle's numbering).
  std::vector<uint32_t> sceneTriangle(triangles.size(), 0u);
  for (size_t g = 0; g < entryOfTriangle.size(); ++g)
    if (entryOfTriangle[g] >= 0 && entries[size_t(entryOfTriangle[g])].kind == LightSampler::Kind::Triangle)
      sceneTriangle[entries[size_t(entryOfTriangle[g])].index] = uint32_t(g);
  for (size_t t = 0; t < triangles.size(); ++t) {
    const EmissiveTriangle& e = triangles[t];
    const size_t row = header.triangleRow + 5 * t;
    putVec(row, e.p0, e.area);
    putVec(row + 1, e.edge1, e.twoSided ? 1.0f : 0.0f);
    putVec(row + 2, e.edge2, 0.0f);
    words[4 * (row + 2) + 3] = sceneTriangle[t];
    putVec(row + 3, e.normal, e.textured ? 1.0f : 0.0f);
    putVec(row + 4, Vec3(e.radiance.r, e.radiance.g, e.radiance.b), 0.0f);
  }
  for (size_t l = 0; l < lights.size(); ++l) {
    const size_t row = header.sceneLightRow + 2 * l;
    if (const auto* sphere = std::get_if<SphereLight>(&lights[l])) {
      putVec(row, sphere->position, sphere->radius);
      putVec(row + 1, Vec3(sphere->intensity.r, sphere->intensity.g, sphere->intensity.b), 0.0f);
    }
  }
  for (size_t g = 0; g < entryOfTriangle.size(); ++g) words[4 * size_t(entryOfTriangleRow) + g] = uint32_t(entryOfTriangle[g]);
  return words;
}

std::string lightGlslConstants() {
  return fmt::format("const uint kLightTriangle = {}u, kLightSphere = {}u, kLightDelta = {}u, kLightEnvironment = {}u;\n"
                     "const float kLightPi = uintBitsToFloat({}u);\n#define LIGHT_TABLE_BINDING {}\n",
                     kLightTriangle, kLightSphere, kLightDelta, kLightEnvironment, std::bit_cast<uint32_t>(kPi),
                     kLightTableBinding);
}

// LightSampler::sample, sampleEntry, emitterPdf, environmentPdf and sphereLightAlong (light.cpp)
// with what they call — Distribution1D::sample and probability (core/sampling.h),
// EmissiveTriangle::barycentricsAt (sampleUniformTriangle), pointAt and Le (emitters.h),
// emitterShadowTarget (light.cpp), SphereLight::sample and pdf with oneMinusCosCone
// (lights.cpp), the environment's uniform sample (EnvironmentLight::sample without a map,
// sampleUniformSphere) — statement for statement.
const char* const kLightsGlsl = R"glsl(
layout(std430, binding = LIGHT_TABLE_BINDING) readonly buffer LightTable { uvec4 lightRows[]; };

struct LightSampleGpu {
  vec3 wi;        // unit, towards the light
  vec3 incident;  // radiance Le
  float pdf;      // solid angle, selection included
  bool delta;     // a point, spot or directional light was chosen (nothing else is set)
  bool infinite;  // the environment: the shadow ray is unbounded
  vec3 target;    // finite lights: the point the shadow ray ends at
};

vec3 lightRowVec(uint row) { return uintBitsToFloat(lightRows[row].xyz); }
float lightRowW(uint row) { return uintBitsToFloat(lightRows[row].w); }
double lightCdf(uint i) {
  uvec4 row = lightRows[lightRows[0].y + i / 2u];
  return packDouble2x32((i & 1u) == 0u ? row.xy : row.zw);
}
float lightProbability(uint entry) { return uintBitsToFloat(lightRows[2u + entry].z); }
float powerHeuristic(float pdfA, float pdfB) {
  float a = pdfA * pdfA, b = pdfB * pdfB;
  return a + b > 0.0 ? a / (a + b) : 0.0;
}
float oneMinusCosCone(float r2, float d2) {
  float sin2 = r2 / d2;
  return sin2 / (1.0 + sqrt(max(0.0, 1.0 - sin2)));
}
// Distribution1D::sample: std::upper_bound on the cdf, then u stretched within the bin.
uint selectLight(float u, out float remapped) {
  uint n = lightRows[0].x;
  uint lo = 0u, hi = n + 1u;
  double du = double(u);
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (lightCdf(mid) > du) hi = mid;
    else lo = mid + 1u;
  }
  uint i = min(lo == 0u ? 0u : lo - 1u, n - 1u);
  double width = lightCdf(i + 1u) - lightCdf(i);
  remapped = width > 0.0LF ? float(min((du - lightCdf(i)) / width, 0.99999994LF)) : 0.0;
  return i;
}
bool lightSample(vec3 position, vec2 u, out LightSampleGpu s) {
  s.wi = vec3(0.0);
  s.incident = vec3(0.0);
  s.pdf = 0.0;
  s.delta = false;
  s.infinite = false;
  s.target = vec3(0.0);
  if (lightRows[0].x == 0u) return false;
  float remapped;
  uint entry = selectLight(u.x, remapped);
  float selectProbability = lightProbability(entry);
  if (!(selectProbability > 0.0)) return false;
  u.x = remapped;
  uint kind = lightRows[2u + entry].x, index = lightRows[2u + entry].y;
  if (kind == kLightTriangle) {
    uint row = lightRows[0].z + 5u * index;
    vec2 b;  // sampleUniformTriangle
    if (u.x < u.y) {
      b.x = u.x / 2.0;
      b.y = u.y - b.x;
    } else {
      b.y = u.y / 2.0;
      b.x = u.x - b.y;
    }
    vec3 point = lightRowVec(row) + b.x * lightRowVec(row + 1u) + b.y * lightRowVec(row + 2u);
    vec3 toLight = point - position;
    float distanceSquared = dot(toLight, toLight);
    if (!(distanceSquared > 0.0)) return false;
    s.wi = toLight / sqrt(distanceSquared);
    vec3 normal = lightRowVec(row + 3u);
    float cosFront = -dot(normal, s.wi);
    s.incident = cosFront > 0.0 || lightRowW(row + 1u) != 0.0 ? lightRowVec(row + 4u) : vec3(0.0);
#ifdef TRACED_DETAIL
    if (lightRowW(row + 3u) != 0.0) {
      uint triangle = lightRows[row + 2u].w;
      s.incident *= emissionTexelAt(materialRecord(triangle), triangles[triangle].xyz, b);
    }
#endif
    float cosLight = abs(cosFront);
    if (all(equal(s.incident, vec3(0.0))) || !(cosLight > 0.0)) return false;
    s.pdf = selectProbability * distanceSquared / (cosLight * lightRowW(row));
    s.target = offsetRayOrigin(point, normal, -s.wi);  // emitterShadowTarget
  } else if (kind == kLightEnvironment) {
    float z = 1.0 - 2.0 * u.x;  // sampleUniformSphere
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = 2.0 * kLightPi * u.y;
    s.wi = vec3(r * cos(phi), r * sin(phi), z);
    s.pdf = selectProbability * (1.0 / (4.0 * kLightPi));
    s.incident = lightRowVec(1u);
    s.infinite = true;
  } else if (kind == kLightSphere) {
    uint row = lightRows[0].w + 2u * index;
    vec3 toCentre = lightRowVec(row) - position;
    float radius = lightRowW(row);
    float d2 = dot(toCentre, toCentre), r2 = radius * radius;
    if (!(d2 > r2)) return false;
    float d = sqrt(d2);
    float coneWidth = oneMinusCosCone(r2, d2);
    float oneMinusCos = u.x * coneWidth;
    float cosTheta = 1.0 - oneMinusCos;
    float sin2Theta = max(0.0, oneMinusCos * (2.0 - oneMinusCos));
    float sinTheta = sqrt(sin2Theta), phi = 2.0 * kLightPi * u.y;
    vec3 axisS, axisT, axis = toCentre / d;
    frameFromNormal(axis, axisS, axisT);
    s.wi = normalize(sinTheta * cos(phi) * axisS + sinTheta * sin(phi) * axisT + cosTheta * axis);
    float distance = max(0.0, d * cosTheta - sqrt(max(0.0, r2 - d2 * sin2Theta)));
    s.target = position + distance * s.wi;
    s.incident = lightRowVec(row + 1u) / (kLightPi * r2);
    s.pdf = selectProbability / (2.0 * kLightPi * coneWidth);
  } else {
    s.delta = true;  // a delta light: the callers count it 0
    return true;
  }
  return s.pdf > 0.0;
}
float emitterPdf(uint triangle, float distance, float cosLight) {
  uint entry = lightRows[lightRows[1].w + triangle / 4u][triangle % 4u];
  if (entry == 0xffffffffu || !(cosLight > 0.0)) return 0.0;
  uint row = lightRows[0].z + 5u * lightRows[2u + entry].y;
  return lightProbability(entry) * distance * distance / (cosLight * lightRowW(row));
}
// The environment is the last entry when it is one.
float environmentLightPdf(vec3 direction) {
  uint n = lightRows[0].x;
  return n > 0u && lightRows[1u + n].x == kLightEnvironment ? lightProbability(n - 1u) * (1.0 / (4.0 * kLightPi)) : 0.0;
}
bool sphereLightAlong(vec3 origin, vec3 direction, float tMin, float tMax, vec3 receiver, out vec3 radiance, out float pdf) {
  radiance = vec3(0.0);
  pdf = 0.0;
  bool found = false;
  float nearestT = tMax;
  for (uint e = 0u; e < lightRows[0].x; ++e) {
    if (lightRows[2u + e].x != kLightSphere) continue;
    uint row = lightRows[0].w + 2u * lightRows[2u + e].y;
    vec3 centre = lightRowVec(row);
    float radius = lightRowW(row);
    vec3 toCentre = centre - origin;
    float b = dot(toCentre, direction), r2 = radius * radius;
    float discriminant = b * b - (dot(toCentre, toCentre) - r2);
    if (!(discriminant >= 0.0)) continue;
    float t = b - sqrt(discriminant);
    if (!(t > tMin && t < nearestT)) continue;
    nearestT = t;
    found = true;
    radiance = lightRowVec(row + 1u) / (kLightPi * r2);
    // SphereLight::pdf at the receiver.
    vec3 toSphere = centre - receiver;
    float d2 = dot(toSphere, toSphere);
    float spherePdf = 0.0;
    if (d2 > r2) {
      float coneWidth = oneMinusCosCone(r2, d2);
      float cosTheta = dot(direction, toSphere) / sqrt(d2);
      spherePdf = cosTheta >= 1.0 - coneWidth ? 1.0 / (2.0 * kLightPi * coneWidth) : 0.0;
    }
    pdf = lightProbability(e) * spherePdf;
  }
  return found;
}
)glsl";

}  // namespace pl
