// The GPU light-field renderer (gpu.h): uploads, shaders and the two passes of a frame.
#include <epoxy/gl.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>

#include "camera/camera.h"
#include "core/error.h"
#include "env/env.h"
#include "gpu/egl_context.h"
#include "gpu/gpu.h"
#include "gpu/gpu_bvh.h"
#include "gpu/gpu_display.h"
#include "gpu/gpu_highlights.h"
#include "gpu/gpu_lights.h"
#include "gpu/gpu_mirror_like.h"
#include "gpu/gpu_specular.h"
#include "gpu/gpu_memory.h"
#include "gpu/gpu_surface_detail.h"
#include "image/display.h"
#include "lightfield/lookup.h"

namespace pl {
namespace {

// Chart record flags (ChartGpu::info.z; gpu_surface_detail.h adds its own from 128 up). The
// GLSL constants are generated from these (glslConstants), so the shader and the upload cannot
// disagree.
constexpr uint32_t kFlagTwoSided = 1u, kFlagBack = 2u, kFlagCurved = 4u, kFlagDiffuseValue = 8u, kFlagEmissive = 16u,
                   kFlagTwoSidedEmission = 32u, kFlagSunMasks = 64u;

/// One chart record as the shaders read it (std430: eight 16-byte rows).
struct ChartGpu {
  float origin[4];        ///< xyz: Chart::origin; w: 1 / tixelSize (ChartShading::inverseTixelSize)
  float axisU[4];         ///< xyz: Chart::axisU; w: the material's diffuse lobe record (word, as float bits; diffuseFactor)
  float axisV[4], normal[4];
  uint32_t grid[4];       ///< resU, resV, dirRes, firstValue
  uint32_t info[4];       ///< valuesPerTixel, kind (ChartKind), flags, firstTixel (its sun masks)
  float emission[4];      ///< ChartShading::emission
  float albedoOverPi[4];  ///< ChartShading::albedoOverPi; with kFlagTexturedAlbedo the base albedo (texturedAlbedoBase)
};
static_assert(sizeof(ChartGpu) == 128);

/// A triangle as the shading pass reads it: its three vertices (indices into the positions)
/// and its chart (LightField::triangleChart, the front record).
struct TriangleGpu {
  uint32_t v[3], chart;
};

/// The visibility pass's resolution, per axis, relative to a width × height image's with
/// several samples per pixel: a jittered ray takes the triangle of the 3×3 id texels around
/// its film point where they agree (idsHit), else it is cast through the BVH; finer texels
/// agree on more of the image (fewer rays cast) and leave a thinner sliver able to pass
/// between their centres unseen. As fine as 16× while the id and depth targets stay
/// within kMaxIdTexels (8 bytes each: 256 MiB): 16× up to 256×192 pixels, 10× at 640×480,
/// 4× at 1920×1080, never below 1×.
constexpr uint64_t kMaxIdTexels = uint64_t(1) << 25;
int multiSampleIdScale(int width, int height) {
  const double scale = std::sqrt(double(kMaxIdTexels) / (double(width) * double(height)));
  return std::clamp(int(scale), 1, 16);
}

// Shader storage bindings.
constexpr GLuint kValuesBinding = 0, kChartsBinding = 1, kPositionsBinding = 2, kTrianglesBinding = 3,
                 kQueriesBinding = 4, kResultsBinding = 5, kNormalsBinding = 6, kSunMasksBinding = 7,
                 kEnvironmentBinding = 8, kRayQueueBinding = 9, kSurfaceDetailBinding = 12;
// Texture units: the visibility pass's ids, the resolve pass's hits; image units: the hits, the radiance.
constexpr GLuint kIdsUnit = 0, kHitsUnit = 1, kHitsImageUnit = 0, kRadianceImageUnit = 1;

std::string glslConstants() {
  return fmt::format(
      "const uint kDiffuse = {}u, kGlossy = {}u, kSpecular = {}u;\n"
      "const uint kFlagTwoSided = {}u, kFlagBack = {}u, kFlagCurved = {}u, kFlagDiffuseValue = {}u, kFlagEmissive = {}u, "
      "kFlagTwoSidedEmission = {}u, kFlagSunMasks = {}u;\nconst int kMaxSunMaskLights = {}, kSunMaskSide = {};\n"
      "#define VALUES_BINDING {}\n#define CHARTS_BINDING {}\n#define POSITIONS_BINDING {}\n#define TRIANGLES_BINDING {}\n"
      "#define QUERIES_BINDING {}\n#define RESULTS_BINDING {}\n#define NORMALS_BINDING {}\n#define SUN_MASKS_BINDING {}\n"
      "#define ENVIRONMENT_BINDING {}\n#define IDS_UNIT {}\n#define HITS_UNIT {}\n#define HITS_IMAGE_UNIT {}\n"
      "#define RAY_QUEUE_BINDING {}\n#define RADIANCE_IMAGE_UNIT {}\n",
      unsigned(ChartKind::Diffuse), unsigned(ChartKind::Glossy), unsigned(ChartKind::Specular), kFlagTwoSided, kFlagBack,
      kFlagCurved, kFlagDiffuseValue, kFlagEmissive, kFlagTwoSidedEmission, kFlagSunMasks, kMaxSunMaskLights, kSunMaskSide,
      kValuesBinding, kChartsBinding, kPositionsBinding, kTrianglesBinding, kQueriesBinding, kResultsBinding, kNormalsBinding,
      kSunMasksBinding, kEnvironmentBinding, kIdsUnit, kHitsUnit, kHitsImageUnit, kRayQueueBinding, kRadianceImageUnit);
}

// The lookup of lightfield/lookup.h in GLSL, statement for statement (the names are the C++
// functions'): linearTap, paraboloidTexelCoordinate (paraboloid.h), directionToParaboloid
// (paraboloid.cpp), interpolateLanes, bilinearOverTixels (diffuseValueOverTixels),
// continuousFrameAround (toLocalAround), facingChart / viewedChart (lightfield.h) and
// exitantRadianceLanes for the charts gpuUnsupportedFeature lets through (no textures, sun
// masks or tilted irradiances; Blinn-Phong's k = 1), with sunVisibility and sunIrradianceLanes
// for the sun masks.
// GpuRenderer::lookup runs it against the C++ on random inputs (gpu_test).
constexpr const char* kLookupGlsl = R"glsl(
struct ChartRecord {
  vec4 origin;  // w: 1 / tixel size
  vec4 axisU, axisV, normal;
  uvec4 grid;   // resU, resV, dirRes, firstValue
  uvec4 info;   // valuesPerTixel, kind, flags
  vec4 emission;
  vec4 albedoOverPi;
};
layout(std430, binding = VALUES_BINDING) readonly buffer Values { vec4 values[]; };
layout(std430, binding = CHARTS_BINDING) readonly buffer Charts { ChartRecord charts[]; };
// LightField::sunMasks, one uint per mask; SunLights: direction towards each light, irradiance.
layout(std430, binding = SUN_MASKS_BINDING) readonly buffer SunMasks { uint sunMasks[]; };
uniform uint sunCount;
uniform vec3 sunTowards[kMaxSunMaskLights], sunIrradiance[kMaxSunMaskLights];

struct LinearTap { uint i0, i1; float f; };
LinearTap linearTap(float x, uint count) {
  uint last = count - 1u;
  float positive = x > 0.0 ? x : 0.0;  // NaN -> 0
  float lastF = float(last);
  float clamped = positive < lastF ? positive : lastF;
  LinearTap tap;
  tap.i0 = uint(clamped);
  uint next = tap.i0 + (clamped > 0.0 ? 1u : 0u);
  tap.i1 = next < last ? next : last;
  tap.f = clamped - float(tap.i0);
  return tap;
}
float paraboloidTexelCoordinate(float x, uint resolution) { return (x + 1.0) * 0.5 * float(resolution) - 0.5; }
vec2 directionToParaboloid(vec3 d) {
  if (d.z >= 0.0) {
    float inv = 1.0 / (1.0 + d.z);
    return vec2(d.x * inv, d.y * inv);
  }
  float r = sqrt(d.x * d.x + d.y * d.y);
  if (r == 0.0) return vec2(0.0);
  return vec2(d.x / r, d.y / r);
}
uint valueIndex(ChartRecord c, uint i, uint j, uint s, uint t) {
  return c.grid.w + (j * c.grid.x + i) * c.info.x + t * c.grid.z + s;
}
vec3 interpolateLanes(ChartRecord c, vec2 grid, vec2 st) {
  LinearTap tu = linearTap(grid.x, c.grid.x), tv = linearTap(grid.y, c.grid.y);
  uint is[2] = uint[2](tu.i0, tu.i1), js[2] = uint[2](tv.i0, tv.i1);
  float wu[2] = float[2](1.0 - tu.f, tu.f), wv[2] = float[2](1.0 - tv.f, tv.f);
  if (c.grid.z == 1u) {
    vec3 lower = wu[0] * wv[0] * values[valueIndex(c, is[0], js[0], 0u, 0u)].rgb +
                 wu[1] * wv[0] * values[valueIndex(c, is[1], js[0], 0u, 0u)].rgb;
    vec3 upper = wu[0] * wv[1] * values[valueIndex(c, is[0], js[1], 0u, 0u)].rgb +
                 wu[1] * wv[1] * values[valueIndex(c, is[1], js[1], 0u, 0u)].rgb;
    return lower + upper;
  }
  LinearTap ta = linearTap(paraboloidTexelCoordinate(st.x, c.grid.z), c.grid.z);
  LinearTap tb = linearTap(paraboloidTexelCoordinate(st.y, c.grid.z), c.grid.z);
  uint as[2] = uint[2](ta.i0, ta.i1), bs[2] = uint[2](tb.i0, tb.i1);
  float wa[2] = float[2](1.0 - ta.f, ta.f), wb[2] = float[2](1.0 - tb.f, tb.f);
  vec3 sum = vec3(0.0);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) {
      float wPos = wu[x] * wv[y];
      if (wPos == 0.0) continue;
      vec3 inner = vec3(0.0);
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a) inner += wa[a] * wb[b] * values[valueIndex(c, is[x], js[y], as[a], bs[b])].rgb;
      sum += wPos * inner;
    }
  return sum;
}
// The glossy charts' diffuse irradiance, bilinear over the tixels (after each tixel's map).
// bilinearOverTixels of the value `offset` after each tixel's first (its map: the diffuse
// irradiance at dirRes², a tilted irradiance after it).
vec3 tixelValueOverTixels(ChartRecord c, vec2 grid, uint offset) {
  LinearTap tu = linearTap(grid.x, c.grid.x), tv = linearTap(grid.y, c.grid.y);
  vec3 lower = (1.0 - tu.f) * (1.0 - tv.f) * values[valueIndex(c, tu.i0, tv.i0, 0u, 0u) + offset].rgb +
               tu.f * (1.0 - tv.f) * values[valueIndex(c, tu.i1, tv.i0, 0u, 0u) + offset].rgb;
  vec3 upper = (1.0 - tu.f) * tv.f * values[valueIndex(c, tu.i0, tv.i1, 0u, 0u) + offset].rgb +
               tu.f * tv.f * values[valueIndex(c, tu.i1, tv.i1, 0u, 0u) + offset].rgb;
  return lower + upper;
}
vec3 diffuseValueOverTixels(ChartRecord c, vec2 grid) { return tixelValueOverTixels(c, grid, c.grid.z * c.grid.z); }
// sunVisibility (lightfield.h): light l's mask bilinear between the four nearest sub-samples.
void sunAxis(float g, uint res, out uint s0, out uint s1, out float f) {
  uint side = uint(kSunMaskSide);
  float last = float(res * side - 1u);
  float unclamped = float(kSunMaskSide) * (g + 0.5) - 0.5;
  float s = unclamped > 0.0 ? min(unclamped, last) : 0.0;  // NaN -> 0
  s0 = uint(s);
  s1 = min(s0 + 1u, res * side - 1u);
  f = s - float(s0);
}
float sunBit(ChartRecord c, uint light, uint su, uint sv) {
  uint side = uint(kSunMaskSide);
  uint tixel = (sv / side) * c.grid.x + su / side;
  uint b = (sv % side) * side + su % side;
  return float((sunMasks[(c.info.w + tixel) * sunCount + light] >> b) & 1u);
}
float sunVisibility(ChartRecord c, uint light, vec2 grid) {
  uint u0, u1, v0, v1;
  float fu, fv;
  sunAxis(grid.x, c.grid.x, u0, u1, fu);
  sunAxis(grid.y, c.grid.y, v0, v1, fv);
  uint side = uint(kSunMaskSide);
  if (u0 / side == u1 / side && v0 / side == v1 / side) {
    uint mask = sunMasks[(c.info.w + (v0 / side) * c.grid.x + u0 / side) * sunCount + light];
    if (mask == 0xffffu) return 1.0;
    if (mask == 0u) return 0.0;
  }
  return (1.0 - fv) * ((1.0 - fu) * sunBit(c, light, u0, v0) + fu * sunBit(c, light, u1, v0)) +
         fv * ((1.0 - fu) * sunBit(c, light, u0, v1) + fu * sunBit(c, light, u1, v1));
}
// sunIrradianceLanes (lookup.h): the masked lights above the surface's normal n, on its
// mapped normal n' (n itself without a normal map).
vec3 sunIrradianceAt(ChartRecord c, vec2 grid, vec3 normal, vec3 mappedNormal) {
  vec3 sum = vec3(0.0);
  for (uint l = 0u; l < sunCount; ++l) {
    if (!(dot(normal, sunTowards[l]) > 0.0)) continue;
    float cosTheta = dot(mappedNormal, sunTowards[l]);
    if (!(cosTheta > 0.0)) continue;
    float lit = sunVisibility(c, l, grid);
    if (lit > 0.0) sum += sunIrradiance[l] * (cosTheta * lit);
  }
  return sum;
}
// continuousFrameAround (lightfield.h) on a curved chart, the chart frame on a planar one,
// and Frame::fromNormal (core/math.h) where axisU is too close to the normal.
vec3 toLocalAround(ChartRecord c, vec3 n, vec3 w) {
  if ((c.info.z & kFlagCurved) == 0u) return vec3(dot(w, c.axisU.xyz), dot(w, c.axisV.xyz), dot(w, c.normal.xyz));
  vec3 u = c.axisU.xyz - dot(c.axisU.xyz, n) * n;
  float len = length(u);
  if (len > 1e-3) {
    vec3 unitU = u / len;
    return vec3(dot(w, unitU), dot(w, cross(n, unitU)), dot(w, n));
  }
  float sign = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (sign + n.z);
  float b = n.x * n.y * a;
  vec3 s = vec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
  vec3 t = vec3(b, sign + n.y * n.y * a, -n.y);
  return vec3(dot(w, s), dot(w, t), dot(w, n));
}
// mappedNormalIrradiance (lookup.h) with tiltWeights (lightfield.h): the irradiance about the
// mapped normal (localMapped: in the tilt frame) from the irradiance about the chart normal
// and the tilted irradiances, bilinear over the tixels; clamped at 0.
vec3 mappedNormalIrradiance(ChartRecord c, vec2 grid, vec3 irradiance, vec3 localMapped) {
  float share = (1.0 - localMapped.z) * (1.0 / (1.0 - kNormalTiltCosine));
  float gradient = 2.0 / (3.0 * kNormalTiltSine);
  vec3 total = (1.0 - share) * irradiance;
  uint first = c.grid.z * c.grid.z + ((c.info.z & kFlagDiffuseValue) != 0u ? 1u : 0u);
  for (uint k = 0u; k < kTiltedNormals; ++k) {
    float w = share * (1.0 / float(kTiltedNormals)) + gradient * (kTiltAcross[k].x * localMapped.x + kTiltAcross[k].y * localMapped.y);
    total += w * tixelValueOverTixels(c, grid, first + k);
  }
  return max(total, vec3(0.0));
}
// normalMappedLookupDirection (lookup.cpp).
vec3 normalMappedLookupDirection(vec3 mapNormal, vec3 shadingNormal, vec3 wo) {
  if (!(dot(wo, mapNormal) > 0.0)) return wo;
  vec3 mirrored = 2.0 * dot(wo, shadingNormal) * shadingNormal - wo;
  vec3 d = 2.0 * dot(mirrored, mapNormal) * mapNormal - mirrored;
  return dot(d, mapNormal) > 0.0 ? normalize(d) : wo;
}
// The radiance towards the viewer (unit towardsViewer) at world point p of the surface whose
// triangle maps to chart record `chart` (triangleChart's front record): normalAtHit is
// chartNormalAt's normal there (the record's side), shadingNormal interpolatedNormal's (the
// front's; a curved glossy chart's map is read around it, chartShadingNormalAt). viewedChart,
// then exitantRadianceLanes. detail: the albedo modulation, emission texel and mapped normal at
// the hit (surfaceDetailAt), read on charts whose albedo or emission is textured or whose
// material is normal-mapped.
// viewedChart: the record seen, kNoRecord behind a one-sided curved record.
const uint kNoRecord = 0xffffffffu;
uint viewedRecord(uint chart, vec3 towardsViewer, vec3 normalAtHit) {
  uint flags = charts[chart].info.z;
  float side = dot(towardsViewer, normalAtHit);
  if ((flags & kFlagCurved) != 0u && (flags & kFlagTwoSided) == 0u && side < 0.0) return kNoRecord;
  return (flags & kFlagTwoSided) != 0u && (flags & kFlagBack) == 0u && side < 0.0 ? chart + 1u : chart;
}
vec3 lookupRadiance(uint chart, vec3 p, vec3 towardsViewer, vec3 normalAtHit, vec3 shadingNormal, SurfaceDetail detail) {
  uint record = viewedRecord(chart, towardsViewer, normalAtHit);
  if (record == kNoRecord) return vec3(0.0);
  ChartRecord c = charts[record];
  uint flags = c.info.z;
  if (c.info.y == kSpecular) return vec3(0.0);
  vec3 d = p - c.origin.xyz;
  vec2 grid = vec2(dot(d, c.axisU.xyz) * c.origin.w - 0.5, dot(d, c.axisV.xyz) * c.origin.w - 0.5);
  float cosTheta = (flags & kFlagCurved) != 0u ? 1.0 : dot(towardsViewer, c.normal.xyz);
  bool emits = cosTheta > 0.0 || (flags & kFlagTwoSidedEmission) != 0u;
  vec3 emission = (flags & kFlagEmissive) != 0u && emits ? c.emission.rgb : vec3(0.0);
  if ((flags & kFlagTexturedEmission) != 0u) emission *= detail.emission;
  if (!(cosTheta >= 0.0)) return emission;
  // lookupNormalAt: the chart normal, or on a curved chart the interpolated one (chartShadingNormalAt);
  // lookupInputs' mapped normal, turned to the record's side.
  vec3 lookupNormal = (flags & kFlagBack) != 0u ? -shadingNormal : shadingNormal;
  bool normalMapped = (flags & kFlagNormalMapped) != 0u;
  vec3 mappedNormal = !normalMapped ? lookupNormal : (flags & kFlagBack) != 0u ? -detail.normal : detail.normal;
  if (c.info.y == kDiffuse) {
    vec3 irradiance = interpolateLanes(c, grid, vec2(0.0));
    if ((flags & kFlagDirectionalIrradiance) != 0u) {
      // The Lambertian lobe reflects only towards viewers above the mapped normal.
      if (!(dot(towardsViewer, mappedNormal) > 0.0)) return emission;
      irradiance = mappedNormalIrradiance(c, grid, irradiance, toLocalAround(c, lookupNormal, mappedNormal));
    }
    if ((flags & kFlagSunMasks) != 0u) irradiance += sunIrradianceAt(c, grid, lookupNormal, mappedNormal);
    // diffuseAlbedoAt: the base albedo × the modulation, over π.
    vec3 albedoOverPi = (flags & kFlagTexturedAlbedo) != 0u ? c.albedoOverPi.rgb * detail.albedo * kInvPi : c.albedoOverPi.rgb;
    return emission + albedoOverPi * irradiance;
  }
  // A normal-mapped glossy chart: nothing reflected towards viewers below the mapped normal, and
  // the map read in the direction the normal map bends the view to.
  vec3 lookupDirection = towardsViewer;
  if (normalMapped) {
    if (!(dot(towardsViewer, mappedNormal) > 0.0)) return (flags & kFlagEmissive) != 0u && emits ? c.emission.rgb : vec3(0.0);
    lookupDirection = normalMappedLookupDirection(lookupNormal, mappedNormal, towardsViewer);
  }
  vec3 local = toLocalAround(c, lookupNormal, lookupDirection);
  vec3 mapped = interpolateLanes(c, grid, directionToParaboloid(local));
  if ((flags & kFlagDiffuseValue) == 0u) return mapped;
  vec3 diffuseIrradiance = diffuseValueOverTixels(c, grid);
  if ((flags & kFlagDirectionalIrradiance) != 0u)
    diffuseIrradiance = mappedNormalIrradiance(c, grid, diffuseIrradiance, toLocalAround(c, lookupNormal, mappedNormal));
  // diffuseDirectionalFactor at μo (against the mapped normal on a normal-mapped chart).
  float cosViewer = normalMapped ? dot(towardsViewer, mappedNormal) : local.z;
  // glossyDiffuseReflectanceAt: with a metallic-roughness texture the point's own model's ρ and k.
  // (Only with a material record: a query without surface detail, as the lookup program's, has
  // none — and NVIDIA's compiler, driver 580, crashes linking a program that inlines the lobe at
  // the constant kNone record, so the test keeps the call out of that program altogether.)
  if ((flags & kFlagMetallicRoughness) != 0u && detail.material != kNone) {
    GgxLobe l = metallicRoughnessLobe(detail.material, detail.albedo, detail.metallicRoughness);
    return mapped + l.diffuse * ggxDiffuseFactor(l.alpha, l.diffuseF0, l.diffuseF90, cosViewer) * kInvPi * diffuseIrradiance;
  }
  vec3 k = diffuseFactor(floatBitsToUint(c.axisU.w), cosViewer);
  // glossyDiffuseAlbedoAt: the model's diffuse albedo × the modulation.
  vec3 albedoOverPi = (flags & kFlagTexturedAlbedo) != 0u ? c.albedoOverPi.rgb * detail.albedo * kInvPi : c.albedoOverPi.rgb;
  return mapped + albedoOverPi * k * diffuseIrradiance;
}
)glsl";

// Pass 1: the triangles' ids at the pixel centres, nearest first (reversed Z: depth = near / z).
constexpr const char* kVisibilityVertex = R"glsl(
layout(location = 0) in vec3 position;
uniform vec3 eye, forward, right, up;
uniform float tanHalfFovY, aspect, near;
void main() {
  vec3 v = position - eye;
  float z = dot(v, forward);
  // Film y grows downwards and so do the GL rows here (row 0 = the image's top row).
  gl_Position = vec4(dot(v, right) / (tanHalfFovY * aspect), -dot(v, up) / tanHalfFovY, near, z);
}
)glsl";
// The geometry as the fragment stages and the BVH traversal (gpu_bvh.h) read it.
constexpr const char* kGeometryGlsl = R"glsl(
layout(std430, binding = POSITIONS_BINDING) readonly buffer Positions { vec4 positions[]; };
layout(std430, binding = TRIANGLES_BINDING) readonly buffer Triangles { uvec4 triangles[]; };
layout(std430, binding = NORMALS_BINDING) readonly buffer Normals { vec4 normals[]; };  // w = 0: none
)glsl";
// The fragment stages' view of the scene beside its geometry: the camera and film size, and the
// ray through a film point (Camera::generateRay's pinhole).
constexpr const char* kFrameGlsl = R"glsl(
uniform vec3 eye, forward, right, up;
uniform float tanHalfFovY, aspect;
uniform float apertureRadius, focusDistance;  // Camera's thin lens (scene units; 0: a pinhole)
uniform ivec2 size;
uniform int idScale;  // the ids are at idScale × the image's resolution
uniform bool anyMasked;  // some material is alpha-masked (maskedMaterial)
// PLENOPTIC_GPU_VISIBILITY=rays: no visibility pass; every camera ray is cast through the BVH.
uniform bool castAllRays;
// An id texel the markers pass marked: a vertex lies there, nearer than the surface rasterised
// (cameraHit casts the rays around it through the BVH).
const uint kMarkedTexel = 0xffffffffu;
// The vector from the eye to film point `film` (pixel units) on the image plane at unit distance.
vec3 cameraToFilm(vec2 film) {
  float sx = (2.0 * film.x / float(size.x) - 1.0) * tanHalfFovY * aspect;
  float sy = (1.0 - 2.0 * film.y / float(size.y)) * tanHalfFovY;
  return forward + sx * right + sy * up;
}
// sampleConcentricDisk (core/sampling.h): u ∈ [0,1)² to the unit disk (Shirley–Chiu).
vec2 sampleConcentricDisk(vec2 u) {
  vec2 o = 2.0 * u - vec2(1.0);
  if (o.x == 0.0 && o.y == 0.0) return vec2(0.0);
  const float pi = 3.14159265358979;
  float r, theta;
  if (abs(o.x) > abs(o.y)) {
    r = o.x;
    theta = (pi / 4.0) * (o.y / o.x);
  } else {
    r = o.y;
    theta = (pi / 2.0) - (pi / 4.0) * (o.x / o.y);
  }
  return r * vec2(cos(theta), sin(theta));
}
uniform bool vignetting;
// Camera::generateRay through film point `film` (pixel units) and lens point `lens` ∈ [0,1)²
// (unused by a pinhole): the ray's origin and unit direction, and the camera weight (cos⁴ of
// the chief ray with vignetting, else 1).
float cameraRay(vec2 film, vec2 lens, out vec3 origin, out vec3 direction) {
  vec3 toFilm = cameraToFilm(film);
  float invLength = 1.0 / length(toFilm);
  float weight = 1.0;
  if (vignetting) weight = invLength * invLength * invLength * invLength;  // cos^4 of the chief ray
  origin = eye;
  direction = toFilm * invLength;
  if (apertureRadius > 0.0) {
    // Towards where the chief ray meets the plane of focus, from the lens point.
    vec3 focusPoint = eye + toFilm * focusDistance;
    vec2 disk = apertureRadius * sampleConcentricDisk(lens);
    origin = eye + disk.x * right + disk.y * up;
    direction = normalize(focusPoint - origin);
  }
  return weight;
}
// The ray from the eye along unit `direction` against the triangle with vertices v
// (Möller–Trumbore, no bounds test): (t, b1, b2), the barycentrics of where it meets the plane.
vec3 rayTriangle(vec3 direction, uvec3 v) {
  vec3 p0 = positions[v.x].xyz, e1 = positions[v.y].xyz - p0, e2 = positions[v.z].xyz - p0;
  vec3 q = cross(direction, e2);
  float det = dot(e1, q);
  vec3 s = eye - p0;
  vec3 r = cross(s, e1);
  return vec3(dot(e2, r), dot(s, q), dot(direction, r)) / det;
}
// interpolatedNormal (scene.h) at barycentrics b of the triangle with vertices v and unit
// geometric normal `geometric`: the vertex normals interpolated, turned to its side.
vec3 interpolatedNormalAt(uvec3 v, vec2 b, vec3 geometric) {
  if (normals[v.x].w == 0.0) return geometric;
  float b1 = b.x, b2 = b.y;
  vec3 interpolated = (1.0 - b1 - b2) * normals[v.x].xyz + b1 * normals[v.y].xyz + b2 * normals[v.z].xyz;
  float len = length(interpolated);
  if (!(len > 1e-6 && !isinf(len) && !isnan(len))) return geometric;
  vec3 shading = interpolated / len;
  return dot(shading, geometric) < 0.0 ? -shading : shading;
}
)glsl";
// An alpha-masked triangle (anyMasked: the scene has some) is cut away where the ray through
// the texel centre meets it at a coverage below its cutoff (coverageAt), as the ray caster's
// hit filter does: the surface behind it is seen there.
constexpr const char* kVisibilityFragment = R"glsl(
out uint id;
void main() {
  uint triangle = uint(gl_PrimitiveID);
  if (anyMasked && maskedMaterial(triangle)) {
    uvec3 v = triangles[triangle].xyz;
    if (masked(triangle, v, rayTriangle(normalize(cameraToFilm(gl_FragCoord.xy / float(idScale))), v).yz)) discard;
  }
  id = triangle + 1u;
}
)glsl";

// Pass 1b, the markers: every vertex drawn as a one-texel point, depth-tested against pass 1's
// depth without writing it, marks the texel it falls in where it is nearer than the surface
// rasterised there. A triangle smaller than a texel may be left out of the ids by the
// rasteriser's snapping (or lie between texel centres) though the ray through a texel centre
// hits it; its vertices then mark the 3×3 around that centre, where cameraHit casts the rays.
constexpr const char* kMarkerFragment = R"glsl(
out uint id;
void main() { id = kMarkedTexel; }
)glsl";

// The camera rays' hits (the resolve pass; the multi-sample shading pass per sample), after
// kBvhGlsl: the id texels of the visibility pass and the BVH.
constexpr const char* kPrimaryHitGlsl = R"glsl(
layout(binding = IDS_UNIT) uniform usampler2D ids;
const uint kNoTriangle = 0xffffffffu;  // a hit's triangle on a miss
// The primary hit of the ray from the eye along unit `direction` through film point `film`
// (pixel units), as the ray caster answers it. The id texels answer where they can be trusted,
// the texel the film point falls in and its 8 neighbours holding no marked vertex
// (kMarkedTexel) and
//   - at most two ids (triangles, or nothing): an edge, a silhouette or the inside of one
//     triangle. The ray is tested against those triangles (Möller–Trumbore, edges inclusive,
//     not cut by an alpha mask) and takes the nearer hit; hitting neither beside nothing, it
//     misses;
//   - or more triangles, all around one vertex (a fan: a mesh vertex in view), of which the ray
//     hits exactly one, not cut by a mask.
// The film point lies within the square of those 9 texel centres; a nearer triangle missing
// from all of them would have a vertex in front there (marked), unless it is a sliver narrower
// than the texel spacing passing between them with its vertices elsewhere, or a triangle
// smaller than a texel whose vertices lie on the surfaces seen (between two triangles, or in a
// fan folded over itself at a silhouette) (gpu.h). Everywhere else — a marked texel, three
// surfaces or more not around one vertex (a corner, a strip of triangles smaller than a
// texel), nothing beside a fan, a ray that hits none of the triangles or two of a fan — the ray
// is cast through the BVH (gpu_bvh.h bvhIntersect) as the CPU renderers cast theirs through
// Embree.
const int kIdsMiss = 0, kIdsHit = 1, kIdsUnsure = 2;
// What the id texels say of that ray: kIdsMiss or kIdsHit (with t, triangle and b) where they
// can be trusted, else kIdsUnsure (the ray is to be cast through the BVH).
int idsHit(vec2 film, vec3 direction, out float t, out uint triangle, out vec2 b) {
  ivec2 texel = ivec2(floor(film * float(idScale)));
  ivec2 lastTexel = size * idScale - 1;
  const float far = 1.0 / 0.0;
  t = far;
  triangle = kNoTriangle;
  b = vec2(0.0);
  // The 3×3 texels' ids (0: nothing; a triangle's index + 1): the centre's, another where
  // there is one, and whether there are more.
  uint centre = texelFetch(ids, clamp(texel, ivec2(0), lastTexel), 0).r, other = centre;
  bool more = false;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      uint id = texelFetch(ids, clamp(texel + ivec2(dx, dy), ivec2(0), lastTexel), 0).r;
      if (id == kMarkedTexel) return kIdsUnsure;
      if (id == centre || id == other) continue;
      if (other == centre) other = id;
      else more = true;
    }
  if (!more) {
    uint seen[2] = uint[2](centre, other);
    for (int k = 0; k < (other == centre ? 1 : 2); ++k) {
      if (seen[k] == 0u) continue;
      vec2 hitB;
      float hitT = bvhTriangle(seen[k] - 1u, eye, direction, 0.0, t, hitB);
      if (hitT < t && !bvhCutAway(seen[k] - 1u, hitB)) {
        t = hitT;
        triangle = seen[k] - 1u;
        b = hitB;
      }
    }
    if (triangle != kNoTriangle) return kIdsHit;
    return centre == 0u || other == 0u ? kIdsMiss : kIdsUnsure;
  }
  // Three ids or more: all of them, distinct.
  uint seen[9];
  int count = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      uint id = texelFetch(ids, clamp(texel + ivec2(dx, dy), ivec2(0), lastTexel), 0).r;
      if (id == 0u) return kIdsUnsure;  // nothing beside a fan: a silhouette's corner
      bool known = false;
      for (int k = 0; k < count; ++k) known = known || seen[k] == id;
      if (!known) seen[count++] = id;
    }
  // A fan: some vertex of the first triangle is a vertex of every other one.
  uvec3 first = triangles[seen[0] - 1u].xyz;
  bvec3 aroundVertex = bvec3(true);
  for (int k = 1; k < count; ++k) {
    uvec3 v = triangles[seen[k] - 1u].xyz;
    aroundVertex = bvec3(aroundVertex.x && any(equal(v, uvec3(first.x))), aroundVertex.y && any(equal(v, uvec3(first.y))),
                         aroundVertex.z && any(equal(v, uvec3(first.z))));
  }
  if (!any(aroundVertex)) return kIdsUnsure;
  int hits = 0;
  for (int k = 0; k < count; ++k) {
    vec2 hitB;
    float hitT = bvhTriangle(seen[k] - 1u, eye, direction, 0.0, far, hitB);
    if (!(hitT < far)) continue;
    if (bvhCutAway(seen[k] - 1u, hitB)) return kIdsUnsure;  // what lies behind the mask's hole is not in the fan
    ++hits;
    t = hitT;
    triangle = seen[k] - 1u;
    b = hitB;
  }
  if (hits == 1) return kIdsHit;
  t = far;
  triangle = kNoTriangle;
  b = vec2(0.0);
  return kIdsUnsure;
}
// What the id texels say of the camera ray through film point `film` along unit `direction`:
// idsHit's answer for a pinhole; kIdsUnsure for a thin lens, whose rays start off the eye,
// where the id buffer (rasterised from the eye) says nothing, and where no ids were drawn
// (castAllRays).
int cameraIdsHit(vec2 film, vec3 direction, out float t, out uint triangle, out vec2 b) {
  if (apertureRadius > 0.0 || castAllRays) {
    t = 1.0 / 0.0;
    triangle = kNoTriangle;
    b = vec2(0.0);
    return kIdsUnsure;
  }
  return idsHit(film, direction, t, triangle, b);
}

// The camera ray's hit from `origin` along unit `direction` through film point `film`: the id
// texels' answer where they have one (cameraIdsHit), else the BVH's.
bool cameraHit(vec2 film, vec3 origin, vec3 direction, out float t, out uint triangle, out vec2 b) {
  int answer = cameraIdsHit(film, direction, t, triangle, b);
  if (answer != kIdsUnsure) return answer == kIdsHit;
  return bvhIntersect(origin, direction, 0.0, 1.0 / 0.0, t, triangle, b);
}
)glsl";

// Pass 2, one sample per pixel: the camera ray through each pixel's centre and its hit
// (cameraHit), stored as (t, triangle, b) bits for the shading pass — the ray casting apart
// from the lookup, each program smaller than the two in one, and each timed on its own. It
// runs as two dispatches: the first answers the pixels the id texels can (cameraIdsHit) and queues
// the others; the second, one thread per queued pixel, casts their rays through the BVH — so
// the threads of a group traverse the BVH together rather than wait for one pixel of theirs
// that does. The queue: a DispatchIndirectCommand (its x counting the 64-wide groups the
// queued pixels take), their count, then the pixels (y · width + x).
constexpr const char* kResolveCompute = R"glsl(
layout(binding = HITS_IMAGE_UNIT, rgba32ui) uniform writeonly uimage2D hits;
layout(std430, binding = RAY_QUEUE_BINDING) buffer RayQueue {
  uint queueGroups, queueGroupsY, queueGroupsZ, queueCount;
  uint queuedPixels[];
};
void storeHit(ivec2 pixel, bool hit, float t, uint triangle, vec2 b) {
  imageStore(hits, pixel, uvec4(floatBitsToUint(t), hit ? triangle : kNoTriangle, floatBitsToUint(b)));
}
#ifndef QUEUED_RAYS
layout(local_size_x = 8, local_size_y = 8) in;
void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (pixel.x >= size.x || pixel.y >= size.y) return;
  vec2 film = vec2(pixel) + 0.5;
  vec3 origin, direction;
  cameraRay(film, vec2(0.5), origin, direction);
  float t;
  uint triangle;
  vec2 b;
  int answer = cameraIdsHit(film, direction, t, triangle, b);
  if (answer != kIdsUnsure) {
    storeHit(pixel, answer == kIdsHit, t, triangle, b);
    return;
  }
  uint slot = atomicAdd(queueCount, 1u);
  queuedPixels[slot] = uint(pixel.y) * uint(size.x) + uint(pixel.x);
  if (slot % 64u == 0u) atomicAdd(queueGroups, 1u);
}
#else
layout(local_size_x = 64) in;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= queueCount) return;
  uint index = queuedPixels[i];
  ivec2 pixel = ivec2(index % uint(size.x), index / uint(size.x));
  vec3 origin, direction;
  cameraRay(vec2(pixel) + 0.5, vec2(0.5), origin, direction);
  float t;
  uint triangle;
  vec2 b;
  bool hit = bvhIntersect(origin, direction, 0.0, 1.0 / 0.0, t, triangle, b);
  storeHit(pixel, hit, t, triangle, b);
}
#endif
)glsl";

// Pass 3, a compute shader over the pixels (8×8 groups): per pixel, the camera ray through its
// centre (Camera::generateRay), its hit (the resolve pass's) and what is seen there (shadeHit);
// with several samples per pixel, each sample's ray, hit (cameraHit) and shading in turn. The
// radiance is stored in an RGBA32F image. (A compute shader rather than a fragment shader over
// a full-screen triangle: a GPU made for compute, as NVIDIA's Hopper, runs fragment shaders on
// a few of its multiprocessors only, compute shaders on all of them.)
constexpr const char* kShadingCompute = R"glsl(
layout(local_size_x = 8, local_size_y = 8) in;
uniform vec3 background;
uniform float coneSpread;  // textureConeSpread: a sample's ray cone is coneSpread × t wide at t
layout(binding = RADIANCE_IMAGE_UNIT, rgba32f) uniform writeonly image2D radiance;

// Environment::radiance (scene.h): the constant plus, where the scene has one, its map —
// EnvironmentMap::radiance (env/env.h): rotated about +y (envRotation = cos, sin), looked up
// bilinearly in the lat-long image (LatLongMap::lookup: u wraps, v clamps), scaled.
layout(std430, binding = ENVIRONMENT_BINDING) readonly buffer EnvironmentTexels { vec4 envTexels[]; };
uniform bool hasEnvironmentMap;
uniform ivec2 envSize;
uniform float envScale;
uniform vec2 envRotation;
vec3 envTexel(int x, int y) { return envTexels[y * envSize.x + x].rgb; }
vec3 environmentRadiance(vec3 d) {
  if (!hasEnvironmentMap) return background;
  vec3 m = vec3(envRotation.x * d.x - envRotation.y * d.z, d.y, envRotation.y * d.x + envRotation.x * d.z);
  // LatLongMap::uv, in float (the C++ takes atan2 and acos in double: GLSL has them in float only).
  const float pi = 3.14159265358979;
  float u = atan(m.z, m.x) / (2.0 * pi) + 0.5;
  if (u >= 1.0) u -= 1.0;
  if (u < 0.0) u += 1.0;
  u = min(u, 0.99999994);  // 0x1.fffffep-1
  float v = acos(clamp(m.y / length(m), -1.0, 1.0)) / pi;
  float fx = u * float(envSize.x) - 0.5, fy = v * float(envSize.y) - 0.5;
  float x0f = floor(fx), y0f = floor(fy);
  float ax = fx - x0f, ay = fy - y0f;
  int x0 = int(x0f) % envSize.x;
  if (x0 < 0) x0 += envSize.x;
  int x1 = (x0 + 1) % envSize.x;
  int y0 = clamp(int(y0f), 0, envSize.y - 1), y1 = clamp(int(y0f) + 1, 0, envSize.y - 1);
  vec3 top = (1.0 - ax) * envTexel(x0, y0) + ax * envTexel(x1, y0);
  vec3 bottom = (1.0 - ax) * envTexel(x0, y1) + ax * envTexel(x1, y1);
  return background + envScale * ((1.0 - ay) * top + ay * bottom);
}

#if defined(MULTISAMPLE) || defined(SPECULAR)
// mix64 and hashCombine (core/rng.h) in 64-bit integers (GL_ARB_gpu_shader_int64).
uint64_t mix64(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9UL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebUL;
  x ^= x >> 31;
  return x;
}
uint64_t hashCombine(uint64_t a, uint64_t b) { return mix64(a ^ (mix64(b) + 0x9e3779b97f4a7c15UL)); }
#endif
// reversedSobolPoint(index, 1) (core/sampler.h): the second Sobol dimension's columns
// v₀ = 2^31, v_k = v_{k−1} ⊕ (v_{k−1} >> 1), bit-reversed, XORed for the index's set bits — the
// film points' (MULTISAMPLE) and the split lobe samples' (gpu_specular.h rayHashU2).
uint reversedSobolSecond(uint index) {
  uint result = 0u, column = 0x80000000u;
  for (; index != 0u; index >>= 1) {
    if ((index & 1u) != 0u) result ^= bitfieldReverse(column);
    column ^= column >> 1;
  }
  return result;
}

// triangleNormal (scene.h: the unit geometric normal of `tri`, 0 for a degenerate one) and, on
// a curved or normal-mapped chart (`chartFlags`), interpolatedNormal at barycentrics b (the
// geometric normal elsewhere, where nothing reads it).
void triangleNormalsAt(uvec4 tri, vec2 b, uint chartFlags, out vec3 geometric, out vec3 interpolated) {
  vec3 p0 = positions[tri.x].xyz;
  vec3 n = cross(positions[tri.y].xyz - p0, positions[tri.z].xyz - p0);
  float length2 = dot(n, n);
  geometric = length2 > 0.0 ? n / sqrt(length2) : vec3(0.0);
  interpolated = (chartFlags & (kFlagCurved | kFlagNormalMapped)) != 0u ? interpolatedNormalAt(tri.xyz, b, geometric) : geometric;
}
// chartNormalAt's normal (the front record's side: the chart normal, on a curved chart the
// triangle's) and interpolatedNormal's (a curved glossy chart's map is read around it,
// chartShadingNormalAt) at barycentrics uv = (b1, b2) of triangle `tri`.
void hitNormals(uvec4 tri, vec2 uv, out vec3 normalAtHit, out vec3 shadingNormal) {
  ChartRecord c = charts[tri.w];
  normalAtHit = c.normal.xyz;
  shadingNormal = c.normal.xyz;
  if ((c.info.z & kFlagCurved) != 0u) triangleNormalsAt(tri, uv, c.info.z, normalAtHit, shadingNormal);
}
// surfaceDetailAt for a ray along `direction` hitting `triangle` at barycentrics b, its ray cone
// coneWidth wide there.
SurfaceDetail hitSurfaceDetail(uint triangle, vec2 b, vec3 direction, float coneWidth) {
  uvec4 tri = triangles[triangle];
  uvec4 info = charts[tri.w].info;
  vec3 geometric, interpolated;
  triangleNormalsAt(tri, b, info.z, geometric, interpolated);
#ifndef PIXEL_DETAIL
  // No chart record has a flag surfaceDetailAt reads: its first answer, for every pixel. (The
  // code left out makes the program smaller: a GPU runs more of its threads at once, and a
  // software rasteriser, which runs both sides of a branch, far less of it.)
  return noSurfaceDetail(interpolated);
#else
  return surfaceDetailAt(triangle, tri.xyz, positions[tri.x].xyz, positions[tri.y].xyz, positions[tri.z].xyz, b, info,
                         direction, coneWidth, geometric, interpolated);
#endif
}

#ifdef SPECULAR
uniform uint mirrorDepth;  // effectiveMirrorDepth
// gpu_specular.h (its chunk follows this shader's main).
vec3 specularChain(vec3 origin, vec3 direction, float t, uint triangle, vec2 uv, uint mirrorDepth);
#endif
#ifdef HIGHLIGHTS
// gpu_highlights.h (its chunk follows this shader's main).
vec3 punctualHighlights(uint record, uint triangle, vec2 uv, vec3 towardsViewer);
#endif

// The radiance along the camera ray from `origin` along unit `direction` that hits (`hit`)
// triangle `triangle` at distance t and barycentrics b, or misses: the environment, or the
// surface there — its lookup, a mirror's or glass's chain, the punctual highlights.
vec3 shadeHit(vec3 origin, vec3 direction, bool hit, float t, uint triangle, vec2 b) {
  if (!hit) return environmentRadiance(direction);
  uvec4 tri = triangles[triangle];
  vec3 p = origin + t * direction;
  vec3 normalAtHit, shadingNormal;
  hitNormals(tri, b, normalAtHit, shadingNormal);
#if defined(SPECULAR) || defined(HIGHLIGHTS)
  uint record = viewedRecord(tri.w, -direction, normalAtHit);
#endif
#ifdef SPECULAR
  if (record != kNoRecord && charts[record].info.y == kSpecular) return specularChain(origin, direction, t, triangle, b, mirrorDepth);
#endif
  SurfaceDetail detail = hitSurfaceDetail(triangle, b, direction, coneSpread * t);
  vec3 radiance = lookupRadiance(tri.w, p, -direction, normalAtHit, shadingNormal, detail);
#ifdef HIGHLIGHTS
  if (record != kNoRecord) radiance += punctualHighlights(record, triangle, b, -direction);
#endif
  return radiance;
}

#ifdef MULTISAMPLE
// The camera weight times the radiance along the camera ray through film point `film` (pixel
// units) and lens point `lens` ∈ [0,1)²: cameraRay, cameraHit, shadeHit.
vec3 sampleRadiance(vec2 film, vec2 lens) {
  vec3 origin, direction;
  float weight = cameraRay(film, lens, origin, direction);
  float t;
  uint triangle;
  vec2 b;
  bool hit = cameraHit(film, origin, direction, t, triangle, b);
  return weight * shadeHit(origin, direction, hit, t, triangle, b);
}
#endif

#ifdef MULTISAMPLE
// pixelSample (lightfield/render_settings.h): the ZSobol film points of core/sampler.h
// (Sampler::sobol, dimension 0) in 64-bit integers (GL_ARB_gpu_shader_int64), line for line;
// the layout's bit counts come from ZSobolLayout on the CPU.
uniform uvec2 seed;  // (low, high) 32 bits: ZSobolLayout::seed
uniform int spp;
uniform int log2Spp;    // ZSobolLayout::log2Spp
uniform int indexBits;  // ZSobolLayout::indexBits
uint owenScrambleReversed(uint v, uint scrambleSeed) {
  v ^= v * 0x3d20adeau;
  v += scrambleSeed;
  v *= (scrambleSeed >> 16) | 1u;
  v ^= v * 0x05526c56u;
  v ^= v * 0x53a22864u;
  return v;
}
uint64_t mortonEncode2(uint x, uint y) {
  uint64_t m = 0UL;
  for (int bit = 0; bit < 16; ++bit)
    m |= (uint64_t((x >> bit) & 1u) << (2 * bit)) | (uint64_t((y >> bit) & 1u) << (2 * bit + 1));
  return m;
}
float fixedToUnit(uint v) { return float(v >> 8) * exp2(-24.0); }
// Sampler::get2D of dimension d for the global index mortonIndex: pixelSample's film point
// (d = 0) and lens point (d = 1).
vec2 zSobol2D(uint64_t mortonIndex, uint64_t layoutSeed, uint d) {
  uint64_t h = mix64(((uint64_t(d) << 32) | (mortonIndex >> 32)) ^ layoutSeed);  // dimensionHash(d)
  uint index = 0u;                                       // shuffledIndex(h)
  int bits = min(indexBits, 32);
  if (bits > 0) {
    int shift = 32 - bits;
    uint shuffleSeed = uint((h * 0x9e3779b97f4a7c15UL) >> 32);
    index = bitfieldReverse(owenScrambleReversed(bitfieldReverse(uint(mortonIndex) << shift), shuffleSeed)) >> shift;
  }
  return vec2(fixedToUnit(bitfieldReverse(owenScrambleReversed(index, uint(h >> 32)))),
              fixedToUnit(bitfieldReverse(owenScrambleReversed(reversedSobolSecond(index), uint(h)))));
}
void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (pixel.x >= size.x || pixel.y >= size.y) return;
  uint64_t seed64 = (uint64_t(seed.y) << 32) | uint64_t(seed.x);
  uint64_t pixelIndex = mortonEncode2(uint(pixel.x), uint(pixel.y)) << log2Spp;
  vec3 sum = vec3(0.0);
  for (int k = 0; k < spp; ++k) {
    uint64_t index = pixelIndex | uint64_t(k);
    vec2 lens = apertureRadius > 0.0 ? zSobol2D(index, seed64, 1u) : vec2(0.5);
    sum += sampleRadiance(vec2(pixel) + zSobol2D(index, seed64, 0u), lens);
  }
  imageStore(radiance, pixel, vec4(sum / float(spp), 1.0));
}
#else
// One sample, at the pixel and lens centres: the camera ray's hit is the resolve pass's.
layout(binding = HITS_UNIT) uniform usampler2D hits;
void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (pixel.x >= size.x || pixel.y >= size.y) return;
  vec3 origin, direction;
  float weight = cameraRay(vec2(pixel) + 0.5, vec2(0.5), origin, direction);
  uvec4 h = texelFetch(hits, pixel, 0);
  imageStore(radiance, pixel,
             vec4(weight * shadeHit(origin, direction, h.y != kNoTriangle, uintBitsToFloat(h.x), h.y, uintBitsToFloat(h.zw)), 1.0));
}
#endif
)glsl";

// What every query program (runQueries) begins with: 64-wide groups and the query count.
constexpr const char* kQueryComputeHead = R"glsl(
layout(local_size_x = 64) in;
uniform uint count;
)glsl";

// The lookup on queries (GpuRenderer::lookup).
constexpr const char* kLookupCompute = R"glsl(
struct Query { vec4 position; vec4 towardsViewer; };  // position.w: the chart, as uint bits
layout(std430, binding = QUERIES_BINDING) readonly buffer Queries { Query queries[]; };
layout(std430, binding = RESULTS_BINDING) writeonly buffer Results { vec4 results[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  uint chart = floatBitsToUint(queries[i].position.w);
  vec3 normal = charts[chart].normal.xyz;
  results[i] = vec4(lookupRadiance(chart, queries[i].position.xyz, queries[i].towardsViewer.xyz, normal, normal,
                                   noSurfaceDetail(normal)), 0.0);
}
)glsl";

// The BVH traversal on rays (GpuRenderer::intersect).
constexpr const char* kIntersectCompute = R"glsl(
struct TraceRay { vec4 origin; vec4 direction; };  // origin.w: tMin, direction.w: tMax
layout(std430, binding = QUERIES_BINDING) readonly buffer Rays { TraceRay rays[]; };
// Per ray: (t, triangle as uint bits, u, v), then (occluded, 0, 0, 0).
layout(std430, binding = RESULTS_BINDING) writeonly buffer Hits { vec4 hits[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  float t;
  uint triangle;
  vec2 uv;
  TraceRay r = rays[i];
  bvhIntersect(r.origin.xyz, r.direction.xyz, r.origin.w, r.direction.w, t, triangle, uv);
  hits[2u * i] = vec4(t, uintBitsToFloat(triangle), uv);
  hits[2u * i + 1u] = vec4(bvhOccluded(r.origin.xyz, r.direction.xyz, r.origin.w, r.direction.w) ? 1.0 : 0.0, 0.0, 0.0, 0.0);
}
)glsl";

// The light sampler on queries (GpuRenderer::sampleLights).
constexpr const char* kLightsCompute = R"glsl(
// position | u.x, u.y | triangle | distance | cosLight, origin | tMax, direction | 0
struct LightQuery { vec4 position; vec4 pdfArguments; vec4 origin; vec4 direction; };
layout(std430, binding = QUERIES_BINDING) readonly buffer Queries { LightQuery queries[]; };
// Per query: (wi, sampled + 2·delta + 4·infinite), (incident, pdf), (target, emitterPdf),
// (sphere radiance, sphere pdf), (environment pdf, sphere found, 0, 0).
layout(std430, binding = RESULTS_BINDING) writeonly buffer Results { vec4 results[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  LightQuery q = queries[i];
  LightSampleGpu s;
  bool sampled = lightSample(q.position.xyz, vec2(q.position.w, q.pdfArguments.x), s);
  float flags = (sampled ? 1.0 : 0.0) + (s.delta ? 2.0 : 0.0) + (s.infinite ? 4.0 : 0.0);
  results[5u * i] = vec4(s.wi, flags);
  results[5u * i + 1u] = vec4(s.incident, s.pdf);
  results[5u * i + 2u] = vec4(s.target, emitterPdf(floatBitsToUint(q.pdfArguments.y), q.pdfArguments.z, q.pdfArguments.w));
  vec3 radiance;
  float pdf;
  bool sphere = sphereLightAlong(q.origin.xyz, q.direction.xyz, 0.0, q.origin.w, q.position.xyz, radiance, pdf);
  results[5u * i + 3u] = vec4(radiance, pdf);
  results[5u * i + 4u] = vec4(environmentLightPdf(q.direction.xyz), sphere ? 1.0 : 0.0, 0.0, 0.0);
}
)glsl";

// The mirror-like lobe on queries (GpuRenderer::sampleLobes).
constexpr const char* kLobesCompute = R"glsl(
// Per query three rows: wo | material (uint bits), wi | 0, u | 0, 0.
layout(std430, binding = QUERIES_BINDING) readonly buffer Queries { vec4 lobeQueries[]; };
// Per query: (wi, sampled), (weight, pdf), (pdf of the query's wi, 0, 0, 0).
layout(std430, binding = RESULTS_BINDING) writeonly buffer Results { vec4 results[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  vec4 a = lobeQueries[3u * i], b = lobeQueries[3u * i + 1u], c = lobeQueries[3u * i + 2u];
  HighlightModel m = highlightModels[floatBitsToUint(a.w)];
  vec3 wi, weight;
  float pdf;
  bool sampled = sampleMirrorLikeLobe(m, a.xyz, c.xy, wi, weight, pdf);
  results[3u * i] = vec4(wi, sampled ? 1.0 : 0.0);
  results[3u * i + 1u] = vec4(weight, pdf);
  results[3u * i + 2u] = vec4(mirrorLikeLobePdf(m, a.xyz, b.xyz), 0.0, 0.0, 0.0);
}
)glsl";

const char* glErrorName(GLenum error) {
  switch (error) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return "an unknown GL error";
  }
}

/// Throws pl::Error naming the GL error raised since the last check, if any, and `what`.
void checkGl(const char* what) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) fail("GPU renderer: {}: {}", what, glErrorName(error));
}

/// Where a shader's or program's `status` (GL_COMPILE_STATUS, GL_LINK_STATUS) is false, its
/// info log (getIv/getLog: glGetShaderiv/glGetShaderInfoLog or the program pair); else nothing.
template <typename GetIv, typename GetLog>
std::optional<std::string> failureLog(GLuint object, GLenum status, GetIv getIv, GetLog getLog) {
  GLint ok = 0;
  getIv(object, status, &ok);
  if (ok) return std::nullopt;
  GLint length = 0;
  getIv(object, GL_INFO_LOG_LENGTH, &length);
  std::string log(size_t(std::max(length, 1)), '\0');
  getLog(object, length, nullptr, log.data());
  return std::string(log.c_str());
}

/// With PLENOPTIC_GPU_SHADER_DUMP=DIR, each shader's full text is written to DIR/NAME.STAGE
/// before it is compiled (vert, frag, comp): what to attach to a driver bug report when a
/// driver's compiler fails or crashes on one (docs/user-guide.md, "The GPU renderer").
void dumpShaderSource(GLenum type, const std::string& source, const char* name) {
  const char* dir = std::getenv("PLENOPTIC_GPU_SHADER_DUMP");
  if (dir == nullptr || *dir == '\0') return;
  const char* stage = type == GL_VERTEX_SHADER ? "vert" : type == GL_FRAGMENT_SHADER ? "frag" : "comp";
  std::string fileName = name;
  std::replace(fileName.begin(), fileName.end(), ' ', '_');
  std::ofstream(fmt::format("{}/{}.{}", dir, fileName, stage)) << source;
}

GLuint compileShader(GLenum type, const std::string& source, const char* name) {
  dumpShaderSource(type, source, name);
  const GLuint shader = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  if (const auto log = failureLog(shader, GL_COMPILE_STATUS, glGetShaderiv, glGetShaderInfoLog)) {
    glDeleteShader(shader);
    fail("GPU renderer: the {} shader does not compile: {}", name, *log);
  }
  return shader;
}

/// Links `shaders` (compiled, deleted here) into `program`; throws pl::Error with the driver's
/// log when it does not link.
GLuint linkShaders(GLuint program, const std::vector<GLuint>& shaders, const char* name) {
  for (GLuint shader : shaders) glAttachShader(program, shader);
  glLinkProgram(program);
  for (GLuint shader : shaders) glDeleteShader(shader);
  if (const auto log = failureLog(program, GL_LINK_STATUS, glGetProgramiv, glGetProgramInfoLog)) {
    glDeleteProgram(program);
    fail("GPU renderer: the {} program does not link: {}", name, *log);
  }
  return program;
}

/// A program of the given stages, each source prefixed by the version line, `header`
/// (extensions, defines), the generated constants and, where `lookup`, the lookup functions.
/// Fragment stages (and compute stages where `computeFrame`) read the geometry and the camera.
GLuint linkProgram(std::initializer_list<std::pair<GLenum, std::string>> stages, const char* name, bool lookup,
                   const std::string& header = "", bool computeFrame = false) {
  const std::string prefix = "#version 450 core\n" + header + glslConstants();
  // The surface detail (its buffer and functions) for the fragment and compute stages, the
  // triangles and the camera for the fragment stages.
  const std::string detail = gpu::surfaceDetailGlsl(kSurfaceDetailBinding);
  const GLuint program = glCreateProgram();
  std::vector<GLuint> shaders;
  for (const auto& [type, source] : stages) {
    const bool frame = type == GL_FRAGMENT_SHADER || (type == GL_COMPUTE_SHADER && computeFrame);
    const std::string text = type == GL_VERTEX_SHADER ? prefix + source
                                                      : prefix + (frame ? std::string(kGeometryGlsl) + kFrameGlsl : "") + detail +
                                                            (lookup ? kLookupGlsl : "") + source;
    shaders.push_back(compileShader(type, text, name));
  }
  return linkShaders(program, shaders, name);
}

/// GL_RENDERER and GL_VERSION of the current context (GpuRenderer::deviceName).
std::string currentDeviceName() {
  return fmt::format("{}, OpenGL {}", reinterpret_cast<const char*>(glGetString(GL_RENDERER)),
                     reinterpret_cast<const char*>(glGetString(GL_VERSION)));
}

/// Runs compute program `program` (64-wide groups, uniform `count`) on `count` queries, `input`
/// bound at kQueriesBinding, and returns the resultFloats floats per query it writes at
/// kResultsBinding (GpuRenderer::lookup, GpuRenderer::intersect). `what` names it in errors.
std::vector<float> runQueries(GLuint program, const std::vector<float>& input, size_t count, size_t resultFloats,
                              const char* what) {
  GLuint buffers[2];
  glCreateBuffers(2, buffers);
  const size_t resultBytes = count * resultFloats * sizeof(float);
  glNamedBufferStorage(buffers[0], GLsizeiptr(std::max<size_t>(input.size() * sizeof(float), 16)), input.empty() ? nullptr : input.data(), 0);
  glNamedBufferStorage(buffers[1], GLsizeiptr(std::max<size_t>(resultBytes, 16)), nullptr, GL_MAP_READ_BIT);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kQueriesBinding, buffers[0]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kResultsBinding, buffers[1]);
  glUseProgram(program);
  glProgramUniform1ui(program, glGetUniformLocation(program, "count"), GLuint(count));
  glDispatchCompute(GLuint((count + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<float> output(count * resultFloats);
  if (count > 0) glGetNamedBufferSubData(buffers[1], 0, GLsizeiptr(resultBytes), output.data());
  glDeleteBuffers(2, buffers);
  checkGl(what);
  return output;
}

void setCameraUniforms(GLuint program, const Camera& camera) {
  auto vec3 = [&](const char* name, const Vec3& v) { glProgramUniform3f(program, glGetUniformLocation(program, name), v.x, v.y, v.z); };
  vec3("eye", camera.eye());
  vec3("forward", camera.forward());
  vec3("right", camera.right());
  vec3("up", camera.up());
  glProgramUniform1f(program, glGetUniformLocation(program, "tanHalfFovY"), camera.tanHalfFovY());
  glProgramUniform1f(program, glGetUniformLocation(program, "aspect"), camera.aspect());
  glProgramUniform1f(program, glGetUniformLocation(program, "apertureRadius"), camera.apertureRadius());
  glProgramUniform1f(program, glGetUniformLocation(program, "focusDistance"), camera.focusDistance());
}

}  // namespace

std::string gpuUnsupportedFeature(const LightField& lf) {
  if (std::string specular = gpuUnsupportedSpecular(lf); !specular.empty()) return specular;
  if (std::string lobe = gpuUnsupportedMirrorLike(lf); !lobe.empty()) return lobe;
  if (hasMirrorLikeCharts(lf))  // the emitters sampled at mirror-like lobes (MirrorLikeLights)
    if (std::string lights = gpuUnsupportedLights(LightSampler(lf.scene)); !lights.empty()) return lights;
  const SunLights sun = sunLightsOf(lf);
  for (uint32_t i = 0; i < lf.charts.size(); ++i)
    if (std::string detail = gpu::surfaceDetailUnsupported(lf, lf.charts[i], chartShading(lf, i, sun)); !detail.empty())
      return detail;
  if (lf.values.size() >= std::numeric_limits<uint32_t>::max() || lf.sunMasks.size() >= std::numeric_limits<uint32_t>::max())
    return "more than 2^32 light-field values";
  return {};
}

namespace {

/// How the camera rays find their first hits, from the environment variable
/// PLENOPTIC_GPU_VISIBILITY: "raster" (unset: the default) rasterises the triangle ids and casts
/// through the BVH only the rays they cannot answer; "rays" draws no ids and casts every camera
/// ray through the BVH — the same hits (the ids only shortcut the ray casting), for measuring
/// a GPU whose rasteriser is the smaller part of it (NVIDIA's Hopper: docs/benchmarks.md).
bool castAllCameraRays() {
  const char* value = std::getenv("PLENOPTIC_GPU_VISIBILITY");
  const std::string mode = value != nullptr ? value : "";
  if (mode.empty() || mode == "raster") return false;
  if (mode == "rays") return true;
  fail("GPU renderer: PLENOPTIC_GPU_VISIBILITY={} is not a visibility mode (use raster or rays)", mode);
}

}  // namespace

/// The renderer's OpenGL context: its own headless one (GpuContext::Headless), or the caller's
/// (GpuContext::Current), which the caller keeps current: then there is nothing to make current.
struct RendererContext {
  std::optional<gpu::EglContext> own;
  explicit RendererContext(GpuContext context) {
    if (context == GpuContext::Headless) {
      own.emplace();
      return;
    }
    // The caller's: at least OpenGL 4.5, a core profile (every shader says #version 450 core).
    const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    if (version == nullptr) fail("GPU renderer: no OpenGL context is current");
    GLint profile = 0;
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    if (epoxy_gl_version() < 45 || (profile & GL_CONTEXT_CORE_PROFILE_BIT) == 0)
      fail("GPU renderer: the current OpenGL context is {} ({} profile), not 4.5 core", version,
           (profile & GL_CONTEXT_CORE_PROFILE_BIT) != 0 ? "core" : "compatibility");
  }
  void makeCurrent() const {
    if (own) own->makeCurrent();
  }
};

/// The ray queue's header (kResolveCompute): groups x, y, z to dispatch, and the count.
constexpr uint64_t kRayQueueHeaderBytes = 16;

struct GpuRenderer::State {
  RendererContext context;
  // values, charts, positions, triangles, indices, normals, sun masks, environment map, surface detail
  static constexpr GLsizei kBufferCount = 9;
  GLuint buffers[kBufferCount] = {};
  GLuint vertexArray = 0;
  GLuint visibilityProgram = 0, markerProgram = 0, shadingProgram = 0, lookupProgram = 0;
  /// The resolve pass's two programs: the id texels' answers and the queue, the queued rays.
  GLuint resolveProgram = 0, queuedRaysProgram = 0;
  /// The BVH (gpu_bvh.h: nodes, order), the materials of the specular chains and shadow rays
  /// (gpu_specular.h: per material, per triangle) and the highlights' lights and models
  /// (gpu_highlights.h); the BVH is built with the first program that traces rays.
  GLuint rayBuffers[6] = {};
  bool bvhUploaded = false;
  GLuint intersectProgram = 0;  ///< GpuRenderer::intersect's, made on its first call
  GLuint lightTable = 0;        ///< the light sampler's table (gpu_lights.h)
  GLuint lobeLightTable = 0;    ///< the scene's light sampler's table, for mirror-like lobes (LOBE_LIGHTS)
  GLuint lightsProgram = 0;     ///< GpuRenderer::sampleLights's, made on its first call
  GLuint lobeModels = 0;        ///< GpuRenderer::sampleLobes's models (highlightModels) without highlights
  GLuint lobesProgram = 0;      ///< GpuRenderer::sampleLobes's, made on its first call
  bool specular = false;        ///< the light field has specular charts: the shading passes trace their chains
  bool highlights = false;      ///< gpuHighlightsActive: the shading passes add punctual highlights
  /// The shading pass with several jittered samples per pixel; 0 where the driver lacks
  /// GL_ARB_gpu_shader_int64 (the sample positions' 64-bit hash).
  GLuint multisampleProgram = 0;
  /// GL_TIMESTAMP queries at the end of a render()'s visibility, resolve and shading passes
  /// (its start is the GL's time when it begins), and the GPU times between them in the last
  /// render() (lastGpuPasses).
  static constexpr int kPassEnds = 3;
  GLuint passEndQueries[kPassEnds] = {};
  GpuPassMilliseconds lastPasses;
  /// The last draw(): its targets hold a frame (frameDrawn, until they are re-made), its GL
  /// start time, whether its statistics (lastPasses, lastBvhRayShare) are still to be read from
  /// the queries (collectFrameStats) and whether it was one sample per pixel.
  bool frameDrawn = false, statsPending = false, oneSample = false;
  GLint64 frameStart = 0;
  /// PLENOPTIC_GPU_VISIBILITY=rays (castAllCameraRays): no visibility pass, every camera ray
  /// cast through the BVH.
  bool castAllRays = false;
  /// The last render()'s camera rays the resolve pass cast through the BVH (its queue's
  /// count), over its pixels; empty after a frame of several samples (lastBvhRayShare).
  std::optional<double> lastBvhRayShare;
  /// The frame's targets: the triangle ids and depth of the visibility pass, the camera rays'
  /// hits and the queue of rays to cast of the resolve pass (one sample per pixel), the
  /// radiance image of the shading pass (read back through readbackFramebuffer).
  GLuint idTexture = 0, depthBuffer = 0, hitsTexture = 0, rayQueue = 0, radianceTexture = 0, visibilityFramebuffer = 0,
         readbackFramebuffer = 0;
  /// The display pass (encodeDisplay; made on its first call): its programs and DisplayEncoder's
  /// sRGB table, and the frame's words and statistics — its radiance subsample, or the log
  /// sum's partial sums, in the same buffer (re-made with the targets). displayQueriesProgram is
  /// displayWords's and logLuminanceTerms's.
  GLuint displayStatisticsProgram = 0, displayLogSumProgram = 0, displayEncodeProgram = 0, displayQueriesProgram = 0,
         srgbTable = 0;
  GLuint displayWords = 0, displayStatistics = 0;
  bool displayEncoded = false;  ///< displayWords holds an encodeDisplay's words (present)
  /// The present pass (present; made on its first call): its program, the textures it shows —
  /// the frame's words and the overlay's, made at their sizes — and an offscreen target
  /// (presentOffscreen).
  GLuint presentProgram = 0, presentFrame = 0, presentOverlay = 0;
  int presentFrameSize[2] = {0, 0}, presentOverlaySize[2] = {0, 0};
  /// The sum of the frames accumulate() added since its last restart (made on its first call,
  /// re-made with the targets), and how many.
  GLuint accumulateProgram = 0, accumulationTexture = 0;
  int accumulated = 0;
  int width = 0, height = 0;
  int idScale = 1;  ///< the visibility targets are idScale·width × idScale·height
  GLsizei indexCount = 0, vertexCount = 0;
  float near = 1e-6f;
  uint64_t bufferBytes = 0;
  Rgb background{0.0f};

  explicit State(GpuContext c) : context(c) {}
  ~State() {
    context.makeCurrent();
    glDeleteBuffers(kBufferCount, buffers);
    glDeleteBuffers(6, rayBuffers);
    glDeleteProgram(intersectProgram);
    glDeleteProgram(lightsProgram);
    glDeleteBuffers(1, &lightTable);
    glDeleteBuffers(1, &lobeLightTable);
    glDeleteProgram(lobesProgram);
    glDeleteBuffers(1, &lobeModels);
    glDeleteVertexArrays(1, &vertexArray);
    glDeleteProgram(visibilityProgram);
    glDeleteProgram(markerProgram);
    glDeleteProgram(resolveProgram);
    glDeleteProgram(queuedRaysProgram);
    glDeleteProgram(shadingProgram);
    glDeleteProgram(lookupProgram);
    glDeleteProgram(multisampleProgram);
    glDeleteProgram(displayStatisticsProgram);
    glDeleteProgram(displayLogSumProgram);
    glDeleteProgram(displayEncodeProgram);
    glDeleteProgram(displayQueriesProgram);
    glDeleteProgram(accumulateProgram);
    glDeleteProgram(presentProgram);
    glDeleteTextures(1, &presentFrame);
    glDeleteTextures(1, &presentOverlay);
    glDeleteBuffers(1, &srgbTable);
    glDeleteQueries(kPassEnds, passEndQueries);
    releaseTargets();
  }
  void releaseTargets() {
    glDeleteFramebuffers(1, &visibilityFramebuffer);
    glDeleteFramebuffers(1, &readbackFramebuffer);
    glDeleteTextures(1, &idTexture);
    glDeleteTextures(1, &hitsTexture);
    glDeleteBuffers(1, &rayQueue);
    glDeleteTextures(1, &radianceTexture);
    glDeleteRenderbuffers(1, &depthBuffer);
    glDeleteBuffers(1, &displayWords);
    glDeleteBuffers(1, &displayStatistics);
    glDeleteTextures(1, &accumulationTexture);
    accumulationTexture = 0;
    accumulated = 0;
    visibilityFramebuffer = readbackFramebuffer = idTexture = hitsTexture = rayQueue = radianceTexture = depthBuffer = 0;
    displayWords = displayStatistics = 0;
    displayEncoded = false;
    width = height = 0;
    frameDrawn = false;
  }
  /// The frame's targets: hits, ray queue and radiance at width × height, triangle ids and
  /// depth at scale·width × scale·height (re-made only when a size changes).
  void ensureTargets(int w, int h, int scale) {
    if (w == width && h == height && scale == idScale) return;
    if (uint64_t(w) * uint64_t(h) > maxImagePixels())
      fail("GPU renderer: a {}x{} image's queue of rays to cast takes {}, more than this driver's largest storage "
           "buffer ({}, GL_MAX_SHADER_STORAGE_BLOCK_SIZE): render it smaller or with --renderer cpu",
           w, h, gpu::formatBytes(kRayQueueHeaderBytes + 4 * uint64_t(w) * uint64_t(h)),
           gpu::formatBytes(kRayQueueHeaderBytes + 4 * maxImagePixels()));
    releaseTargets();
    glCreateTextures(GL_TEXTURE_2D, 1, &idTexture);
    glTextureStorage2D(idTexture, 1, GL_R32UI, w * scale, h * scale);
    // (An integer texture with the default linear filters is incomplete and reads as 0.)
    glTextureParameteri(idTexture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(idTexture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glCreateRenderbuffers(1, &depthBuffer);
    glNamedRenderbufferStorage(depthBuffer, GL_DEPTH_COMPONENT32F, w * scale, h * scale);
    // The hits: (t, triangle, b1, b2) as bits, read back exactly (texelFetch, no filtering).
    glCreateTextures(GL_TEXTURE_2D, 1, &hitsTexture);
    glTextureStorage2D(hitsTexture, 1, GL_RGBA32UI, w, h);
    glTextureParameteri(hitsTexture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(hitsTexture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glCreateBuffers(1, &rayQueue);
    glNamedBufferStorage(rayQueue, GLsizeiptr(kRayQueueHeaderBytes + 4 * uint64_t(w) * uint64_t(h)), nullptr,
                         GL_DYNAMIC_STORAGE_BIT);
    glCreateTextures(GL_TEXTURE_2D, 1, &radianceTexture);
    glTextureStorage2D(radianceTexture, 1, GL_RGBA32F, w, h);
    glCreateFramebuffers(1, &visibilityFramebuffer);
    glNamedFramebufferTexture(visibilityFramebuffer, GL_COLOR_ATTACHMENT0, idTexture, 0);
    glNamedFramebufferRenderbuffer(visibilityFramebuffer, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depthBuffer);
    glCreateFramebuffers(1, &readbackFramebuffer);
    glNamedFramebufferTexture(readbackFramebuffer, GL_COLOR_ATTACHMENT0, radianceTexture, 0);
    for (GLuint fb : {visibilityFramebuffer, readbackFramebuffer})
      if (glCheckNamedFramebufferStatus(fb, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        fail("GPU renderer: a {}x{} framebuffer is incomplete", w, h);
    checkGl("creating the frame's targets");
    width = w;
    height = h;
    idScale = scale;
  }
  /// Builds the BVH over the scene's triangles (the order of `triangles` above) and uploads it.
  void uploadBvh(const Scene& scene) {
    if (bvhUploaded) return;
    std::vector<Vec3> points;
    std::vector<UVec3> tris;
    flattenSceneTriangles(scene, points, tris);
    const GpuBvh bvh = buildGpuBvh(points, tris);
    glCreateBuffers(2, rayBuffers);
    glNamedBufferStorage(rayBuffers[0], GLsizeiptr(bvh.nodes.size() * sizeof(BvhNode)), bvh.nodes.data(), 0);
    glNamedBufferStorage(rayBuffers[1], GLsizeiptr(std::max<size_t>(bvh.triangles.size() * sizeof(BvhTriangle), 16)),
                         bvh.triangles.empty() ? nullptr : bvh.triangles.data(), 0);
    bufferBytes += bvh.nodes.size() * sizeof(BvhNode) + std::max<size_t>(bvh.triangles.size() * sizeof(BvhTriangle), 16);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBvhNodesBinding, rayBuffers[0]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBvhTrianglesBinding, rayBuffers[1]);
    checkGl("uploading the BVH (out of GPU memory?)");
    bvhUploaded = true;
  }
  /// Pass 1, queued (not waited for): the triangle ids at idScale × the camera's resolution,
  /// then the vertex markers.
  void queueVisibility(const Camera& camera, int scale) {
    ensureTargets(camera.width(), camera.height(), scale);
    setCameraUniforms(visibilityProgram, camera);
    glProgramUniform2i(visibilityProgram, glGetUniformLocation(visibilityProgram, "size"), camera.width(), camera.height());
    glProgramUniform1i(visibilityProgram, glGetUniformLocation(visibilityProgram, "idScale"), scale);
    glBindFramebuffer(GL_FRAMEBUFFER, visibilityFramebuffer);
    glViewport(0, 0, camera.width() * scale, camera.height() * scale);
    const GLuint noTriangle = 0;
    glClearNamedFramebufferuiv(visibilityFramebuffer, GL_COLOR, 0, &noTriangle);
    const float farthest = 0.0f;
    glClearNamedFramebufferfv(visibilityFramebuffer, GL_DEPTH, 0, &farthest);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDisable(GL_CULL_FACE);
    glUseProgram(visibilityProgram);
    glBindVertexArray(vertexArray);
    glDrawElements(GL_TRIANGLES, indexCount, GL_UNSIGNED_INT, nullptr);
    // The markers (kMarkerFragment): the vertices as one-texel points, nearer than the surface.
    setCameraUniforms(markerProgram, camera);
    glDepthMask(GL_FALSE);
    glUseProgram(markerProgram);
    glDrawArrays(GL_POINTS, 0, vertexCount);
    glDepthMask(GL_TRUE);
    checkGl("the visibility pass");
  }
  /// The most pixels an image may have: its ray queue within the largest storage block.
  uint64_t maxImagePixels() const {
    GLint64 maxBlock = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxBlock);
    return maxBlock > int64_t(kRayQueueHeaderBytes) ? (uint64_t(maxBlock) - kRayQueueHeaderBytes) / 4
                                                     : std::numeric_limits<uint64_t>::max();
  }
  uint64_t targetBytes() const {
    return kRayQueueHeaderBytes + uint64_t(width) * uint64_t(height) * (16 + 16 + 4 + uint64_t(idScale) * uint64_t(idScale) * (4 + 4)) +
           (displayWords != 0 ? displayBytes(width, height) : 0) + (srgbTable != 0 ? srgbTableBytes() : 0) +
           (accumulationTexture != 0 ? 16 * uint64_t(width) * uint64_t(height) : 0) +
           4 * (uint64_t(presentFrameSize[0]) * uint64_t(presentFrameSize[1]) +
                uint64_t(presentOverlaySize[0]) * uint64_t(presentOverlaySize[1]));
  }
  /// The display pass's frame buffers: 4 bytes per pixel of words, 16 per subsample pixel (the
  /// log sum's partial sums, 8 bytes per run of subsample pixels, fit in the same buffer).
  static uint64_t displayBytes(int w, int h) {
    return 4 * uint64_t(w) * uint64_t(h) +
           16 * uint64_t(DisplayEncoder::statisticsSize(w)) * uint64_t(DisplayEncoder::statisticsSize(h));
  }
  static uint64_t srgbTableBytes() { return 4 * uint64_t(DisplayEncoder::kSrgbTableSize); }
  /// The display pass's sRGB table (DisplayEncoder's, one uint per entry), uploaded once.
  void ensureSrgbTable() {
    if (srgbTable != 0) return;
    const DisplayEncoder encoder;
    const std::vector<uint8_t>& table = encoder.srgbTable();
    const std::vector<GLuint> words(table.begin(), table.end());
    glCreateBuffers(1, &srgbTable);
    glNamedBufferStorage(srgbTable, GLsizeiptr(words.size() * sizeof(GLuint)), words.data(), 0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gpu::kSrgbTableBinding, srgbTable);
  }
  /// The statistics and encode programs and the sRGB table, made when missing.
  void ensureDisplayPrograms() {
    ensureSrgbTable();
    const std::string constants = gpu::displayGlslConstants(kRadianceImageUnit);
    if (displayStatisticsProgram == 0)
      displayStatisticsProgram =
          linkProgram({{GL_COMPUTE_SHADER, gpu::kDisplayStatisticsCompute}}, "display statistics", false, constants);
    if (displayLogSumProgram == 0)
      displayLogSumProgram =
          linkProgram({{GL_COMPUTE_SHADER, std::string(gpu::kDisplayGlsl) + gpu::kDisplayLogSumCompute}}, "display log sum",
                      false, constants);
    if (displayEncodeProgram == 0)
      displayEncodeProgram = linkProgram({{GL_COMPUTE_SHADER, std::string(gpu::kDisplayGlsl) + gpu::kDisplayEncodeCompute}},
                                         "display", false, constants);
    if (accumulateProgram == 0)
      accumulateProgram = linkProgram({{GL_COMPUTE_SHADER, gpu::kAccumulateCompute}}, "accumulate", false, constants);
  }
  /// ensureDisplayPrograms, and the frame's display buffers, made when missing.
  void ensureDisplay() {
    ensureDisplayPrograms();
    if (displayWords == 0) {
      const int sw = DisplayEncoder::statisticsSize(width), sh = DisplayEncoder::statisticsSize(height);
      glCreateBuffers(1, &displayWords);
      glNamedBufferStorage(displayWords, GLsizeiptr(4 * uint64_t(width) * uint64_t(height)), nullptr, 0);
      glCreateBuffers(1, &displayStatistics);
      glNamedBufferStorage(displayStatistics, GLsizeiptr(16 * uint64_t(sw) * uint64_t(sh)), nullptr, 0);
      checkGl("creating the display pass's buffers (out of GPU memory?)");
    }
  }
  /// The last draw()'s pass times and BVH ray share from its queries (they wait for the frame),
  /// once.
  void collectFrameStats() {
    if (!statsPending) return;
    statsPending = false;
    GLuint64 stamps[1 + kPassEnds] = {GLuint64(std::max<GLint64>(frameStart, 0))};
    for (int i = 0; i < kPassEnds; ++i) glGetQueryObjectui64v(passEndQueries[i], GL_QUERY_RESULT, &stamps[1 + i]);
    auto milliseconds = [&](int from, int to) { return stamps[to] > stamps[from] ? double(stamps[to] - stamps[from]) * 1e-6 : 0.0; };
    lastPasses = {milliseconds(0, 1), milliseconds(1, 2), milliseconds(2, 3)};
    lastBvhRayShare.reset();
    if (oneSample) {
      GLuint queued = 0;  // the queue's count (kResolveCompute), after its header's three group counts
      glGetNamedBufferSubData(rayQueue, 3 * sizeof(GLuint), sizeof(queued), &queued);
      lastBvhRayShare = double(queued) / (double(width) * double(height));
    }
  }
  void requireFrame(const char* what) const {
    if (!frameDrawn) fail("GPU renderer: {} without a frame drawn (GpuRenderer::draw first)", what);
  }
};

GpuRenderer::GpuRenderer(const LightField& lightField, GpuContext context) : lightField_(lightField) {
  if (const std::string missing = gpuUnsupportedFeature(lightField); !missing.empty())
    fail("GPU renderer: this light field has {}, which the GPU renderer does not draw yet (render it with --renderer cpu)",
         missing);
  state_ = std::make_unique<State>(context);
  State& s = *state_;
  s.castAllRays = castAllCameraRays();
  const Scene& scene = lightField.scene;
  s.background = scene.environment.constant;

  // The light field: values as RGBA (the fast renderer's padded copy), chart records.
  std::vector<float> values(lightField.values.size() * 4, 0.0f);
  for (size_t i = 0; i < lightField.values.size(); ++i) std::memcpy(&values[4 * i], &lightField.values[i], sizeof(Rgb));
  const SunLights sun = sunLightsOf(lightField);
  const gpu::SurfaceDetailBuffer detail = gpu::surfaceDetailBuffer(lightField);
  std::vector<ChartGpu> charts(lightField.charts.size());
  // Some chart record has a flag surfaceDetailAt reads per pixel (else it returns no detail
  // for every pixel, and the shading passes are compiled without it: PIXEL_DETAIL).
  constexpr uint32_t kPixelDetailFlags =
      gpu::kFlagTexturedAlbedo | gpu::kFlagTexturedEmission | gpu::kFlagNormalMapped | gpu::kFlagMetallicRoughness;
  bool pixelDetail = false;
  for (uint32_t i = 0; i < charts.size(); ++i) {
    const Chart& c = lightField.charts[i];
    const ChartShading shading = chartShading(lightField, i, sun);
    ChartGpu& g = charts[i];
    g = ChartGpu{{c.origin.x, c.origin.y, c.origin.z, shading.inverseTixelSize},
                 {c.axisU.x, c.axisU.y, c.axisU.z, 0.0f},
                 {c.axisV.x, c.axisV.y, c.axisV.z, 0.0f},
                 {c.normal.x, c.normal.y, c.normal.z, 0.0f},
                 {c.resU, c.resV, c.dirRes, uint32_t(c.firstValue)},
                 {uint32_t(c.valuesPerTixel()), uint32_t(c.kind),
                  (c.sides == 2 ? kFlagTwoSided : 0u) | (c.isBack ? kFlagBack : 0u) | (c.curved ? kFlagCurved : 0u) |
                      (c.diffuseValue ? kFlagDiffuseValue : 0u) | (shading.emissive ? kFlagEmissive : 0u) |
                      (shading.twoSidedEmission ? kFlagTwoSidedEmission : 0u) |
                      (shading.sunMasks != nullptr ? kFlagSunMasks : 0u) |
                      (shading.needsUv && shading.texturedAlbedo ? gpu::kFlagTexturedAlbedo : 0u) |
                      (shading.texturedEmission ? gpu::kFlagTexturedEmission : 0u) |
                      (shading.normalMapped ? gpu::kFlagNormalMapped : 0u) |
                      (c.directionalIrradiance ? gpu::kFlagDirectionalIrradiance : 0u) |
                      (shading.needsUv && c.diffuseValue && scene.materials[c.material].metallicRoughness.texture >= 0
                           ? gpu::kFlagMetallicRoughness
                           : 0u),
                  uint32_t(c.firstTixel)},
                 {},
                 {}};
    std::memcpy(g.emission, shading.emission.v, sizeof(g.emission));
    std::memcpy(g.albedoOverPi, shading.albedoOverPi.v, sizeof(g.albedoOverPi));
    std::memcpy(&g.axisU[3], &detail.diffuseLobe[c.material], sizeof(float));
    if (shading.needsUv && shading.texturedAlbedo) {
      const Rgb base = gpu::texturedAlbedoBase(scene, c);
      std::memcpy(g.albedoOverPi, &base, sizeof(Rgb));
    }
    pixelDetail = pixelDetail || (g.info[2] & kPixelDetailFlags) != 0;
  }
  // The geometry: every mesh's positions in one array, triangles with global vertex indices
  // (so gl_PrimitiveID of the one draw call is the triangle's index here) and their charts.
  std::vector<float> positions, normals;
  std::vector<TriangleGpu> triangles;
  std::vector<uint32_t> indices;
  Vec3 lower(std::numeric_limits<float>::max()), upper(-std::numeric_limits<float>::max());
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    const uint32_t first = uint32_t(positions.size() / 4);
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      const Vec3& p = mesh.positions[v];
      positions.insert(positions.end(), {p.x, p.y, p.z, 1.0f});
      const Vec3 n = mesh.normals.empty() ? Vec3(0.0f) : mesh.normals[v];
      normals.insert(normals.end(), {n.x, n.y, n.z, mesh.normals.empty() ? 0.0f : 1.0f});
      lower = glm::min(lower, p);
      upper = glm::max(upper, p);
    }
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const UVec3 tri = mesh.triangles[t];
      triangles.push_back({{first + tri[0], first + tri[1], first + tri[2]}, lightField.triangleChart[m][t]});
      indices.insert(indices.end(), {first + tri[0], first + tri[1], first + tri[2]});
    }
  }
  // The near plane: a millionth of the scene's diagonal (depth is near / z in a float buffer,
  // so its precision does not depend on it; only what is nearer than it is cut away).
  if (!positions.empty()) s.near = std::max(1e-6f * glm::length(upper - lower), std::numeric_limits<float>::min());
  s.indexCount = GLsizei(indices.size());
  s.vertexCount = GLsizei(positions.size() / 4);

  const std::vector<uint32_t> sunMasks(lightField.sunMasks.begin(), lightField.sunMasks.end());
  // The environment map's lat-long texels as RGBA.
  const EnvironmentMap* environmentMap = scene.environment.map.get();
  std::vector<float> envTexels;
  if (environmentMap != nullptr) {
    const Image& image = environmentMap->map().image;
    envTexels.resize(image.pixels.size() * 4, 0.0f);
    for (size_t i = 0; i < image.pixels.size(); ++i) std::memcpy(&envTexels[4 * i], &image.pixels[i], sizeof(Rgb));
  }
  // The buffers, in State::buffers' order, and what each holds (for the memory check's
  // message). A zero-sized buffer cannot be bound to a storage block: 16 bytes stand in.
  struct Upload {
    const char* what;
    const void* data;
    size_t bytes;
  };
  const Upload uploads[State::kBufferCount] = {
      {"values", values.data(), values.size() * sizeof(float)},
      {"chart records", charts.data(), charts.size() * sizeof(ChartGpu)},
      {"vertex positions", positions.data(), positions.size() * sizeof(float)},
      {"triangles", triangles.data(), triangles.size() * sizeof(TriangleGpu)},
      {"vertex indices", indices.data(), indices.size() * sizeof(uint32_t)},
      {"vertex normals", normals.data(), normals.size() * sizeof(float)},
      {"sun masks", sunMasks.data(), sunMasks.size() * sizeof(uint32_t)},
      {"environment map", envTexels.data(), envTexels.size() * sizeof(float)},
      {"textures, uvs and vertex colours", detail.words.data(), detail.words.size() * sizeof(uint32_t)}};
  std::vector<std::pair<std::string, uint64_t>> sizes;
  for (const Upload& u : uploads) sizes.emplace_back(u.what, std::max<size_t>(u.bytes, 16));
  // The BVH the primary rays beside edges and the traced rays are cast through (at most 2n − 1
  // nodes over n triangles, and their order); mirrors, glass and punctual highlights add the
  // triangles' materials and the materials and lights they read.
  s.specular = hasSpecularCharts(lightField);
  // Mirror-like lobes: sampled with the highlights' model records, their delta lights'
  // highlights added whatever the setting (PunctualHighlights), their emitters sampled from the
  // scene's light sampler (MirrorLikeLights) when it has any.
  const bool mirrorLike = hasMirrorLikeCharts(lightField);
  const bool glossyHighlights = gpuHighlightsActive(lightField);
  s.highlights = glossyHighlights || mirrorLike;
  std::vector<uint32_t> lobeLightTable;
  if (mirrorLike) {
    const LightSampler sampler(scene);
    if (sampler.emissiveTriangleCount() > 0 || sampler.hasEnvironment() || sampler.hasSphereLights())
      lobeLightTable = gpuLightTable(sampler);
  }
  const bool lobeLights = !lobeLightTable.empty();
  const bool traces = s.specular || s.highlights;
  const uint64_t triangleCount = triangles.size();
  sizes.emplace_back("BVH (bound)", std::max<uint64_t>((2 * triangleCount) * sizeof(BvhNode) + sizeof(BvhTriangle) * triangleCount, 16));
  if (traces) {
    sizes.emplace_back("materials of the traced rays", std::max<uint64_t>(scene.materials.size() * sizeof(SpecularMaterialGpu) +
                                                                               4 * triangleCount, 16));
  }
  if (lobeLights) sizes.emplace_back("light sampler (mirror-like lobes)", lobeLightTable.size() * sizeof(uint32_t));
  gpu::checkGpuMemory(sizes);
  auto upload = [&](GLuint buffer, const void* data, size_t bytes) {
    glNamedBufferStorage(buffer, GLsizeiptr(std::max<size_t>(bytes, 16)), bytes > 0 ? data : nullptr, GL_DYNAMIC_STORAGE_BIT);
    s.bufferBytes += std::max<size_t>(bytes, 16);
  };
  glCreateBuffers(State::kBufferCount, s.buffers);
  for (GLsizei i = 0; i < State::kBufferCount; ++i) upload(s.buffers[i], uploads[i].data, uploads[i].bytes);
  checkGl("uploading the light field (out of GPU memory?)");
  // Mirrors and glass, punctual highlights: the BVH their rays are traced through, the
  // materials they follow or pass (thin glass), the highlights' lights and models.
  if (s.specular && !epoxy_has_gl_extension("GL_ARB_gpu_shader_int64"))
    fail("GPU renderer: this light field has mirrors or glass, which need GL_ARB_gpu_shader_int64 (this driver, {}, "
         "lacks it; render it with --renderer cpu)",
         currentDeviceName());
  s.uploadBvh(scene);
  if (traces) {
    const std::vector<SpecularMaterialGpu> materials = specularMaterials(scene);
    std::vector<uint32_t> triangleMaterials;
    for (const Mesh& mesh : scene.meshes) triangleMaterials.insert(triangleMaterials.end(), mesh.materials.begin(), mesh.materials.end());
    glCreateBuffers(2, s.rayBuffers + 2);
    upload(s.rayBuffers[2], materials.data(), materials.size() * sizeof(SpecularMaterialGpu));
    upload(s.rayBuffers[3], triangleMaterials.data(), triangleMaterials.size() * sizeof(uint32_t));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kSpecularMaterialsBinding, s.rayBuffers[2]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTriangleMaterialsBinding, s.rayBuffers[3]);
    checkGl("uploading the materials of mirrors and glass");
  }
  const std::vector<HighlightLightGpu> highlightLightRecords = s.highlights ? highlightLights(scene) : std::vector<HighlightLightGpu>{};
  if (s.highlights) {
    const std::vector<HighlightModelGpu> models = highlightModels(scene);
    glCreateBuffers(2, s.rayBuffers + 4);
    upload(s.rayBuffers[4], highlightLightRecords.data(), highlightLightRecords.size() * sizeof(HighlightLightGpu));
    upload(s.rayBuffers[5], models.data(), models.size() * sizeof(HighlightModelGpu));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kHighlightLightsBinding, s.rayBuffers[4]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kHighlightModelsBinding, s.rayBuffers[5]);
    checkGl("uploading the punctual lights");
  }
  if (lobeLights) {
    glCreateBuffers(1, &s.lobeLightTable);
    upload(s.lobeLightTable, lobeLightTable.data(), lobeLightTable.size() * sizeof(uint32_t));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kLightTableBinding, s.lobeLightTable);
    checkGl("uploading the light sampler");
  }

  glCreateVertexArrays(1, &s.vertexArray);
  glVertexArrayVertexBuffer(s.vertexArray, 0, s.buffers[2], 0, 4 * sizeof(float));
  glVertexArrayElementBuffer(s.vertexArray, s.buffers[4]);
  glEnableVertexArrayAttrib(s.vertexArray, 0);
  glVertexArrayAttribFormat(s.vertexArray, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(s.vertexArray, 0, 0);

  s.visibilityProgram =
      linkProgram({{GL_VERTEX_SHADER, kVisibilityVertex}, {GL_FRAGMENT_SHADER, kVisibilityFragment}}, "visibility", false);
  s.markerProgram = linkProgram({{GL_VERTEX_SHADER, kVisibilityVertex}, {GL_FRAGMENT_SHADER, kMarkerFragment}}, "markers", false);
  // With specular charts or highlights the shading passes carry the BVH traversal, the
  // highlights and the chains after their main.
  const std::string int64 = "#extension GL_ARB_gpu_shader_int64 : require\n";
  const bool anyMasked = std::any_of(scene.materials.begin(), scene.materials.end(), [](const Material& m) { return m.isMasked(); });
  // The traversal cuts masks and a chain's end reads surface detail only where the scene has
  // some: the code inlined in the loops makes the program far longer to compile (llvmpipe:
  // tens of seconds).
  const std::string raysHeader = (s.specular ? int64 + "#define SPECULAR\n" : "") +
                                     (s.highlights ? "#define HIGHLIGHTS\n" + highlightGlslConstants() : "") +
                                     bvhGlslConstants() + (traces ? specularGlslConstants() : "") +
                                     (anyMasked ? "#define BVH_ALPHA_MASKS\n" : "") +
                                     (pixelDetail ? "#define PIXEL_DETAIL\n" : "") +
                                     (gpu::tracedSurfaceDetail(lightField) ? "#define TRACED_DETAIL\n" : "") +
                                     (mirrorLike ? "#define MIRROR_LIKE\n" : "") +
                                     (lobeLights ? "#define LOBE_LIGHTS\n" + lightGlslConstants() : "");
  const std::string shading = std::string(kBvhGlsl) + kPrimaryHitGlsl + kShadingCompute + (traces ? kSurfaceGlsl : "") + (s.highlights ? kHighlightsGlsl : "") +
                              (lobeLights ? kLightsGlsl : "") + (mirrorLike ? kMirrorLikeGlsl : "") +
                              (s.specular ? kSpecularGlsl : "");
  s.shadingProgram = linkProgram({{GL_COMPUTE_SHADER, shading}}, "shading", true, raysHeader, true);
  // The resolve pass casts rays only: the BVH, cut by alpha masks where the scene has some.
  const std::string resolve = std::string(kBvhGlsl) + kPrimaryHitGlsl + kResolveCompute;
  const std::string resolveHeader = bvhGlslConstants() + (anyMasked ? "#define BVH_ALPHA_MASKS\n" : "");
  s.resolveProgram = linkProgram({{GL_COMPUTE_SHADER, resolve}}, "resolve", false, resolveHeader, true);
  s.queuedRaysProgram =
      linkProgram({{GL_COMPUTE_SHADER, resolve}}, "resolve queued rays", false, resolveHeader + "#define QUEUED_RAYS\n", true);
  s.lookupProgram = linkProgram({{GL_COMPUTE_SHADER, std::string(kQueryComputeHead) + kLookupCompute}}, "lookup", true);
  if (epoxy_has_gl_extension("GL_ARB_gpu_shader_int64"))
    s.multisampleProgram = linkProgram({{GL_COMPUTE_SHADER, shading}}, "multi-sample shading", true,
                                       (s.specular ? raysHeader : int64 + raysHeader) + "#define MULTISAMPLE\n", true);
  for (GLuint program : {s.visibilityProgram, s.markerProgram})
    glProgramUniform1f(program, glGetUniformLocation(program, "near"), s.near);
  for (GLuint program : {s.visibilityProgram, s.resolveProgram, s.queuedRaysProgram, s.shadingProgram, s.multisampleProgram})
    if (program != 0) glProgramUniform1i(program, glGetUniformLocation(program, "anyMasked"), anyMasked ? 1 : 0);
  for (GLuint program : {s.shadingProgram, s.multisampleProgram}) {
    if (program == 0) continue;
    if (s.highlights) {
      glProgramUniform1ui(program, glGetUniformLocation(program, "highlightLightCount"), GLuint(highlightLightRecords.size()));
      glProgramUniform1i(program, glGetUniformLocation(program, "glossyHighlights"), glossyHighlights ? 1 : 0);
      glProgramUniform1i(program, glGetUniformLocation(program, "shadowsPassThinGlass"), scene.hasThinGlass() ? 1 : 0);
    }
    glProgramUniform3f(program, glGetUniformLocation(program, "background"), s.background.x, s.background.y,
                       s.background.z);
    glProgramUniform1i(program, glGetUniformLocation(program, "hasEnvironmentMap"), environmentMap != nullptr ? 1 : 0);
    if (environmentMap != nullptr) {
      // The map's rotation as EnvironmentMap::toMap applies it: toMap(+x) = (cos, 0, sin).
      const Vec3 rotatedX = environmentMap->toMap(Vec3(1.0f, 0.0f, 0.0f));
      glProgramUniform2i(program, glGetUniformLocation(program, "envSize"), environmentMap->map().width(),
                         environmentMap->map().height());
      glProgramUniform1f(program, glGetUniformLocation(program, "envScale"), environmentMap->scale());
      glProgramUniform2f(program, glGetUniformLocation(program, "envRotation"), rotatedX.x, rotatedX.z);
    }
  }
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kValuesBinding, s.buffers[0]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kChartsBinding, s.buffers[1]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kPositionsBinding, s.buffers[2]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTrianglesBinding, s.buffers[3]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kNormalsBinding, s.buffers[5]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kSunMasksBinding, s.buffers[6]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kEnvironmentBinding, s.buffers[7]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kSurfaceDetailBinding, s.buffers[8]);
  for (GLuint program : {s.shadingProgram, s.lookupProgram, s.multisampleProgram}) {
    if (program == 0) continue;
    glProgramUniform1ui(program, glGetUniformLocation(program, "sunCount"), sun.count);
    for (uint32_t l = 0; l < sun.count; ++l) {
      const std::string index = fmt::format("[{}]", l);
      const Vec3& towards = sun.towardsLight[l];
      const float* irradiance = sun.irradiance[l].v;
      glProgramUniform3f(program, glGetUniformLocation(program, ("sunTowards" + index).c_str()), towards.x, towards.y, towards.z);
      glProgramUniform3f(program, glGetUniformLocation(program, ("sunIrradiance" + index).c_str()), irradiance[0],
                         irradiance[1], irradiance[2]);
    }
  }
  // Reversed Z: depth = near / z ∈ (0, 1], nearer is larger.
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  checkGl("setting up the shaders");
}

GpuRenderer::~GpuRenderer() = default;

void GpuRenderer::drawVisibility(const Camera& camera, int idScale) {
  State& s = *state_;
  s.context.makeCurrent();
  s.queueVisibility(camera, idScale);
  glFinish();
}

std::string GpuRenderer::unsupportedSetting(const RenderSettings& settings, const Camera& camera) const {
  if (effectiveSamplesPerPixel(settings, camera.isThinLens()) > 1 && state_->multisampleProgram == 0)
    return "more than one sample per pixel on this driver (it lacks GL_ARB_gpu_shader_int64)";
  return {};
}

void GpuRenderer::checkSettings(const RenderSettings& settings, const Camera& camera) const {
  checkRenderSettings(settings);
  if (const std::string missing = unsupportedSetting(settings, camera); !missing.empty())
    fail("GPU renderer: {} not supported yet (render with --renderer cpu)", missing);
}

void GpuRenderer::render(const Camera& camera, const RenderSettings& settings, Image& image) {
  draw(camera, settings);
  readRadiance(image);
}

void GpuRenderer::draw(const Camera& camera, const RenderSettings& settings) {
  checkSettings(settings, camera);
  // One sample: the pixel centre, its ray cast by the resolve pass; several: pixelSample's film
  // points, whose triangles are looked for in a visibility pass at a finer resolution
  // (multiSampleIdScale) by the shading pass itself. A thin lens's rays are all cast through the
  // BVH: no visibility pass.
  const int spp = effectiveSamplesPerPixel(settings, camera.isThinLens());
  const bool noIds = camera.isThinLens() || state_->castAllRays;
  const int idScale = spp > 1 && !noIds ? multiSampleIdScale(camera.width(), camera.height()) : 1;
  State& s = *state_;
  s.context.makeCurrent();
  if (s.passEndQueries[0] == 0) glCreateQueries(GL_TIMESTAMP, State::kPassEnds, s.passEndQueries);
  // The frame's start: the GL's time now, the GPU idle (the last frame was read back). Each
  // pass's end is a timestamp query, flushed at once: Mesa's llvmpipe stamps a query when it
  // runs the commands queued with it, so a query left queued behind a compute pass's
  // would be stamped with the next pass's.
  GLint64 frameStart = 0;
  glGetInteger64v(GL_TIMESTAMP, &frameStart);
  if (noIds) {
    s.ensureTargets(camera.width(), camera.height(), idScale);
  } else {
    s.queueVisibility(camera, idScale);
  }
  glQueryCounter(s.passEndQueries[0], GL_TIMESTAMP);
  glFlush();
  auto setFrameUniforms = [&](GLuint program) {
    setCameraUniforms(program, camera);
    glProgramUniform2i(program, glGetUniformLocation(program, "size"), camera.width(), camera.height());
    glProgramUniform1i(program, glGetUniformLocation(program, "idScale"), idScale);
    glProgramUniform1i(program, glGetUniformLocation(program, "vignetting"), camera.vignetting() ? 1 : 0);
    glProgramUniform1i(program, glGetUniformLocation(program, "castAllRays"), s.castAllRays ? 1 : 0);
  };
  glBindTextureUnit(kIdsUnit, s.idTexture);
  if (spp == 1) {
    // The id texels' answers, the other pixels queued; then the queued pixels' rays.
    const GLuint emptyQueue[4] = {0, 1, 1, 0};
    glNamedBufferSubData(s.rayQueue, 0, sizeof(emptyQueue), emptyQueue);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRayQueueBinding, s.rayQueue);
    glBindImageTexture(kHitsImageUnit, s.hitsTexture, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32UI);
    setFrameUniforms(s.resolveProgram);
    glUseProgram(s.resolveProgram);
    glDispatchCompute(GLuint((camera.width() + 7) / 8), GLuint((camera.height() + 7) / 8), 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    setFrameUniforms(s.queuedRaysProgram);
    glUseProgram(s.queuedRaysProgram);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, s.rayQueue);
    glDispatchComputeIndirect(0);
    // The shading pass fetches the hits the dispatches stored.
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    glBindTextureUnit(kHitsUnit, s.hitsTexture);
  }
  glQueryCounter(s.passEndQueries[1], GL_TIMESTAMP);
  glFlush();
  const GLuint program = spp > 1 ? s.multisampleProgram : s.shadingProgram;
  setFrameUniforms(program);
  if (s.specular)
    glProgramUniform1ui(program, glGetUniformLocation(program, "mirrorDepth"),
                        effectiveMirrorDepth(settings, lightField_.settings.mirrorDepth));
  glProgramUniform1f(program, glGetUniformLocation(program, "coneSpread"),
                     textureConeSpread(settings, camera.pixelSpread(), spp));
  if (spp > 1) {
    const ZSobolLayout samples(camera.width(), camera.height(), spp, settings.seed);  // pixelSample
    glProgramUniform1i(program, glGetUniformLocation(program, "spp"), spp);
    glProgramUniform1i(program, glGetUniformLocation(program, "log2Spp"), samples.log2Spp());
    glProgramUniform1i(program, glGetUniformLocation(program, "indexBits"), samples.indexBits());
    glProgramUniform2ui(program, glGetUniformLocation(program, "seed"), GLuint(settings.seed & 0xffffffffu),
                        GLuint(settings.seed >> 32));
  }
  glBindImageTexture(kRadianceImageUnit, s.radianceTexture, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glUseProgram(program);
  glDispatchCompute(GLuint((camera.width() + 7) / 8), GLuint((camera.height() + 7) / 8), 1);
  glQueryCounter(s.passEndQueries[2], GL_TIMESTAMP);
  glFlush();
  checkGl("the shading pass");
  s.frameDrawn = s.statsPending = true;
  s.oneSample = spp == 1;
  s.frameStart = frameStart;
}

void GpuRenderer::readRadiance(Image& image) {
  State& s = *state_;
  s.context.makeCurrent();
  s.requireFrame("reading the radiance back");
  // The read-back reads the radiance image through the framebuffer it is attached to.
  glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, s.readbackFramebuffer);
  if (image.width != s.width || image.height != s.height) image = Image(s.width, s.height);
  // GL row y is image row y (the projection flips film y): read straight into the pixels.
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadnPixels(0, 0, s.width, s.height, GL_RGB, GL_FLOAT, GLsizei(image.pixels.size() * sizeof(Rgb)), image.pixels.data());
  s.collectFrameStats();  // (the read-back waited for the shading pass: every timestamp is there)
  checkGl("reading the frame back");
}

void GpuRenderer::encodeDisplay(DisplayEncoder& encoder, float exposureScale, const ToneMapSettings& settings,
                                uint32_t* pixels, int pitchBytes, bool average) {
  State& s = *state_;
  s.context.makeCurrent();
  s.requireFrame("encoding the display");
  if (average && s.accumulated == 0) fail("GPU renderer: encoding the average of no accumulated frames");
  s.ensureDisplay();
  const int w = s.width, h = s.height;
  const int sw = DisplayEncoder::statisticsSize(w), sh = DisplayEncoder::statisticsSize(h);
  // Both programs read the radiance image the shading pass stored, or the accumulated sum, and
  // weigh it as the viewer averages its batches (1 / their count, computed here as there).
  const float weight = average ? 1.0f / float(s.accumulated) : 1.0f;
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  glBindImageTexture(kRadianceImageUnit, average ? s.accumulationTexture : s.radianceTexture, 0, GL_FALSE, 0, GL_READ_ONLY,
                     GL_RGBA32F);
  for (GLuint program : {s.displayStatisticsProgram, s.displayLogSumProgram, s.displayEncodeProgram}) {
    glProgramUniform1f(program, glGetUniformLocation(program, "weight"), weight);
    glProgramUniform2i(program, glGetUniformLocation(program, "size"), w, h);
  }
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gpu::kDisplayStatisticsBinding, s.displayStatistics);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gpu::kDisplayWordsBinding, s.displayWords);
  // The curve's statistics (gpu_display.h): what the settings need, and no more, read back.
  const ToneMapCurve* curve = nullptr;
  switch (toneMapStatistics(settings)) {
    case ToneMapStatistics::None:
      curve = &encoder.resolveCurve(0.0f, settings);
      break;
    case ToneMapStatistics::LogAverage: {
      glProgramUniform1f(s.displayLogSumProgram, glGetUniformLocation(s.displayLogSumProgram, "exposureScale"),
                         exposureScale);
      glUseProgram(s.displayLogSumProgram);
      const int runs = gpu::logSumRuns(w, h);
      glDispatchCompute(GLuint((runs + 63) / 64), 1, 1);
      glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
      std::vector<gpu::LogSum> sums(static_cast<size_t>(runs));
      glGetNamedBufferSubData(s.displayStatistics, 0, GLsizeiptr(sums.size() * sizeof(gpu::LogSum)), sums.data());
      // Eq. 1 as logAverageLuminance sums it: the runs' sums added in double.
      double sum = 0.0;
      uint64_t count = 0;
      for (const gpu::LogSum& run : sums) {
        sum += double(run.sum);
        count += run.count;
      }
      curve = &encoder.resolveCurve(count ? float(std::exp(sum / double(count))) : 0.0f, settings);
      break;
    }
    case ToneMapStatistics::Percentiles: {
      glUseProgram(s.displayStatisticsProgram);
      glDispatchCompute(GLuint((sw + 7) / 8), GLuint((sh + 7) / 8), 1);
      glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
      std::vector<float> statistics(4 * size_t(sw) * size_t(sh));
      glGetNamedBufferSubData(s.displayStatistics, 0, GLsizeiptr(statistics.size() * sizeof(float)), statistics.data());
      Image subsample(sw, sh);
      for (size_t i = 0; i < subsample.pixels.size(); ++i)
        subsample.pixels[i] = Rgb(statistics[4 * i], statistics[4 * i + 1], statistics[4 * i + 2]);
      curve = &encoder.resolveCurve(subsample, exposureScale, settings);
      break;
    }
  }
  const GLuint program = s.displayEncodeProgram;
  gpu::setToneCurveUniforms(program, *curve);
  glProgramUniform1f(program, glGetUniformLocation(program, "exposureScale"), exposureScale);
  glUseProgram(program);
  glDispatchCompute(GLuint((w + 7) / 8), GLuint((h + 7) / 8), 1);
  s.displayEncoded = true;
  const size_t rowBytes = 4 * size_t(w);
  if (pixels == nullptr) {
    // (Left on the GPU for present().)
  } else if (size_t(pitchBytes) == rowBytes) {
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(s.displayWords, 0, GLsizeiptr(rowBytes * size_t(h)), pixels);
  } else {
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    for (int y = 0; y < h; ++y)
      glGetNamedBufferSubData(s.displayWords, GLintptr(rowBytes * size_t(y)), GLsizeiptr(rowBytes),
                              reinterpret_cast<uint8_t*>(pixels) + size_t(y) * size_t(pitchBytes));
  }
  s.collectFrameStats();
  checkGl("the display pass");
}

namespace {

/// `texture` made (again) as an RGBA8 texture of `width` × `height` where it has another size,
/// with `filter` for both minification and magnification, clamped at its edges.
void ensurePresentTexture(GLuint& texture, int (&size)[2], int width, int height, GLenum filter) {
  if (texture != 0 && size[0] == width && size[1] == height) return;
  glDeleteTextures(1, &texture);
  glCreateTextures(GL_TEXTURE_2D, 1, &texture);
  glTextureStorage2D(texture, 1, GL_RGBA8, width, height);
  glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GLint(filter));
  glTextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GLint(filter));
  glTextureParameteri(texture, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  size[0] = width;
  size[1] = height;
}

/// Uploads `pixels` into `texture` (its size): the 0xAARRGGBB words are the bytes B, G, R, A
/// in memory (a little-endian machine, as SDL's ARGB8888), which GL_BGRA reads as they are.
void uploadDisplayPixels(GLuint texture, const DisplayPixels& pixels) {
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, pixels.pitchBytes / 4);
  glTextureSubImage2D(texture, 0, 0, 0, pixels.width, pixels.height, GL_BGRA, GL_UNSIGNED_BYTE, pixels.words);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
}

/// The 8-bit pixels of `framebuffer`'s colour buffer `buffer` as 0xAARRGGBB words, top row
/// first (GL's rows count from the bottom).
std::vector<uint32_t> readWords(GLuint framebuffer, GLenum buffer, int width, int height) {
  std::vector<uint32_t> words(size_t(width) * size_t(height));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glReadBuffer(buffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadnPixels(0, 0, width, height, GL_BGRA, GL_UNSIGNED_BYTE, GLsizei(words.size() * 4), words.data());
  for (int y = 0; y < height / 2; ++y)
    std::swap_ranges(words.begin() + ptrdiff_t(y) * width, words.begin() + ptrdiff_t(y + 1) * width,
                     words.begin() + ptrdiff_t(height - 1 - y) * width);
  return words;
}

void checkDisplayPixels(const DisplayPixels& pixels, const char* what) {
  if (pixels.width < 1 || pixels.height < 1 || pixels.pitchBytes < 4 * pixels.width || pixels.pitchBytes % 4 != 0)
    fail("GPU renderer: presenting a {} of {}x{} pixels with {} bytes per row", what, pixels.width, pixels.height,
         pixels.pitchBytes);
}

}  // namespace

void GpuRenderer::present(const DisplayPixels& frame, const DisplayPixels& overlay, int windowWidth, int windowHeight) {
  state_->context.makeCurrent();
  presentInto(0, frame, overlay, windowWidth, windowHeight);
}

void GpuRenderer::presentInto(uint32_t framebuffer, const DisplayPixels& frame, const DisplayPixels& overlay,
                              int windowWidth, int windowHeight) {
  State& s = *state_;
  if (windowWidth < 1 || windowHeight < 1) fail("GPU renderer: presenting into a {}x{} window", windowWidth, windowHeight);
  if (s.presentProgram == 0) {
    const std::string prefix = "#version 450 core\n" + gpu::displayGlslConstants(kRadianceImageUnit);
    const GLuint vertex = compileShader(GL_VERTEX_SHADER, prefix + gpu::kPresentVertex, "present");
    GLuint fragment = 0;
    try {
      fragment = compileShader(GL_FRAGMENT_SHADER, prefix + gpu::kPresentFragment, "present");
    } catch (...) {
      glDeleteShader(vertex);
      throw;
    }
    s.presentProgram = linkShaders(glCreateProgram(), {vertex, fragment}, "present");
  }
  // The frame: the display pass's words, read where they are when the frame is the window's
  // size, else copied on the GPU (buffer → texture) to be stretched; or the caller's, uploaded.
  const bool wordsInBuffer = frame.words == nullptr && s.width == windowWidth && s.height == windowHeight;
  if (frame.words == nullptr) {
    if (!s.displayEncoded) fail("GPU renderer: presenting the frame before encodeDisplay encoded it");
    if (wordsInBuffer) {
      glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, gpu::kDisplayWordsBinding, s.displayWords);
    } else {
      ensurePresentTexture(s.presentFrame, s.presentFrameSize, s.width, s.height, GL_LINEAR);
      glMemoryBarrier(GL_PIXEL_BUFFER_BARRIER_BIT);
      glBindBuffer(GL_PIXEL_UNPACK_BUFFER, s.displayWords);
      uploadDisplayPixels(s.presentFrame, {nullptr, s.width, s.height, 4 * s.width});
      glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    }
  } else {
    checkDisplayPixels(frame, "frame");
    ensurePresentTexture(s.presentFrame, s.presentFrameSize, frame.width, frame.height, GL_LINEAR);
    uploadDisplayPixels(s.presentFrame, frame);
  }
  const bool hasOverlay = overlay.words != nullptr;
  if (hasOverlay) {
    checkDisplayPixels(overlay, "overlay");
    ensurePresentTexture(s.presentOverlay, s.presentOverlaySize, overlay.width, overlay.height, GL_NEAREST);
    uploadDisplayPixels(s.presentOverlay, overlay);
  }
  const GLuint program = s.presentProgram;
  glProgramUniform2i(program, glGetUniformLocation(program, "windowSize"), windowWidth, windowHeight);
  glProgramUniform1i(program, glGetUniformLocation(program, "wordsInBuffer"), wordsInBuffer ? 1 : 0);
  glProgramUniform2i(program, glGetUniformLocation(program, "frameSize"), s.presentFrameSize[0], s.presentFrameSize[1]);
  glProgramUniform2i(program, glGetUniformLocation(program, "overlaySize"), hasOverlay ? overlay.width : 0,
                     hasOverlay ? overlay.height : 0);
  glBindTextureUnit(gpu::kPresentFrameUnit, s.presentFrame);
  glBindTextureUnit(gpu::kPresentOverlayUnit, s.presentOverlay);
  // Into `framebuffer` (0: the window's back buffer): the words are sRGB already, written as
  // they are.
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer);
  glViewport(0, 0, windowWidth, windowHeight);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_FRAMEBUFFER_SRGB);
  glUseProgram(program);
  glBindVertexArray(s.vertexArray);  // (the triangle reads no attributes; core GL wants a vertex array bound)
  glDrawArrays(GL_TRIANGLES, 0, 3);
  checkGl("presenting the frame");
}

std::vector<uint32_t> GpuRenderer::presentOffscreen(const DisplayPixels& frame, const DisplayPixels& overlay,
                                                    int windowWidth, int windowHeight) {
  State& s = *state_;
  s.context.makeCurrent();
  if (windowWidth < 1 || windowHeight < 1) fail("GPU renderer: presenting into a {}x{} window", windowWidth, windowHeight);
  GLuint texture = 0, framebuffer = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &texture);
  glTextureStorage2D(texture, 1, GL_RGBA8, windowWidth, windowHeight);
  glCreateFramebuffers(1, &framebuffer);
  glNamedFramebufferTexture(framebuffer, GL_COLOR_ATTACHMENT0, texture, 0);
  std::vector<uint32_t> words;
  try {
    presentInto(framebuffer, frame, overlay, windowWidth, windowHeight);
    words = readWords(framebuffer, GL_COLOR_ATTACHMENT0, windowWidth, windowHeight);
  } catch (...) {
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteTextures(1, &texture);
    throw;
  }
  glDeleteFramebuffers(1, &framebuffer);  // (a bound framebuffer deleted binds 0)
  glDeleteTextures(1, &texture);
  checkGl("reading the presented picture back");
  return words;
}

std::vector<uint32_t> GpuRenderer::readPresented(int windowWidth, int windowHeight) {
  state_->context.makeCurrent();
  if (windowWidth < 1 || windowHeight < 1) fail("GPU renderer: reading a {}x{} window", windowWidth, windowHeight);
  std::vector<uint32_t> words = readWords(0, GL_BACK, windowWidth, windowHeight);
  checkGl("reading the window back");
  return words;
}

void GpuRenderer::accumulate(bool restart) {
  State& s = *state_;
  s.context.makeCurrent();
  s.requireFrame("accumulating");
  s.ensureDisplayPrograms();
  if (s.accumulationTexture == 0) {  // (made with the targets' size: accumulated is 0 then)
    glCreateTextures(GL_TEXTURE_2D, 1, &s.accumulationTexture);
    glTextureStorage2D(s.accumulationTexture, 1, GL_RGBA32F, s.width, s.height);
    checkGl("creating the accumulation image (out of GPU memory?)");
  }
  restart = restart || s.accumulated == 0;
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  glBindImageTexture(kRadianceImageUnit, s.radianceTexture, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
  glBindImageTexture(gpu::kAccumulationImageUnit, s.accumulationTexture, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  const GLuint program = s.accumulateProgram;
  glProgramUniform2i(program, glGetUniformLocation(program, "size"), s.width, s.height);
  glProgramUniform1i(program, glGetUniformLocation(program, "restart"), restart ? 1 : 0);
  glUseProgram(program);
  glDispatchCompute(GLuint((s.width + 7) / 8), GLuint((s.height + 7) / 8), 1);
  s.accumulated = restart ? 1 : s.accumulated + 1;
  checkGl("accumulating the frame");
}

int GpuRenderer::accumulatedFrames() const { return state_->accumulated; }

void GpuRenderer::readAverage(Image& image) {
  State& s = *state_;
  s.context.makeCurrent();
  if (s.accumulated == 0) fail("GPU renderer: reading the average of no accumulated frames");
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
  std::vector<float> sum(4 * size_t(s.width) * size_t(s.height));
  glGetTextureImage(s.accumulationTexture, 0, GL_RGBA, GL_FLOAT, GLsizei(sum.size() * sizeof(float)), sum.data());
  if (image.width != s.width || image.height != s.height) image = Image(s.width, s.height);
  const float weight = 1.0f / float(s.accumulated);  // as encodeDisplay's average
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = Rgb(sum[4 * i], sum[4 * i + 1], sum[4 * i + 2]) * weight;
  checkGl("reading the average back");
}

void GpuRenderer::prepareDisplay() {
  state_->context.makeCurrent();
  state_->ensureDisplayPrograms();
  checkGl("preparing the display pass");
}

std::vector<uint32_t> GpuRenderer::displayQueries(const ToneMapCurve& curve, const std::vector<Rgb>& exposed) {
  State& s = *state_;
  s.context.makeCurrent();
  s.ensureSrgbTable();
  if (s.displayQueriesProgram == 0)
    s.displayQueriesProgram =
        linkProgram({{GL_COMPUTE_SHADER, std::string(kQueryComputeHead) + gpu::kDisplayGlsl + gpu::kDisplayQueriesCompute}},
                    "display queries", false, gpu::displayGlslConstants(kRadianceImageUnit));
  gpu::setToneCurveUniforms(s.displayQueriesProgram, curve);
  std::vector<float> input;
  input.reserve(exposed.size() * 4);
  for (const Rgb& c : exposed) input.insert(input.end(), {c.r, c.g, c.b, 0.0f});
  const std::vector<float> output = runQueries(s.displayQueriesProgram, input, exposed.size(), 2, "the display queries");
  std::vector<uint32_t> results(output.size());
  std::memcpy(results.data(), output.data(), results.size() * sizeof(uint32_t));
  return results;
}

std::vector<uint32_t> GpuRenderer::displayWords(const ToneMapCurve& curve, const std::vector<Rgb>& exposed) {
  const std::vector<uint32_t> results = displayQueries(curve, exposed);
  std::vector<uint32_t> words(exposed.size());
  for (size_t i = 0; i < words.size(); ++i) words[i] = results[2 * i];
  return words;
}

std::vector<float> GpuRenderer::logLuminanceTerms(const std::vector<Rgb>& exposed) {
  const std::vector<uint32_t> results = displayQueries(ToneMapCurve{}, exposed);
  std::vector<float> terms(exposed.size());
  for (size_t i = 0; i < terms.size(); ++i) std::memcpy(&terms[i], &results[2 * i + 1], sizeof(float));
  return terms;
}

uint64_t GpuRenderer::maxImagePixels() const {
  state_->context.makeCurrent();
  return state_->maxImagePixels();
}

GpuPassMilliseconds GpuRenderer::lastGpuPasses() const { return state_->lastPasses; }

std::optional<double> GpuRenderer::lastBvhRayShare() const { return state_->lastBvhRayShare; }

std::vector<Rgb> GpuRenderer::lookup(const std::vector<LookupQuery>& queries) {
  State& s = *state_;
  s.context.makeCurrent();
  std::vector<float> input;
  input.reserve(queries.size() * 8);
  for (const LookupQuery& q : queries) {
    float chart;
    std::memcpy(&chart, &q.chart, sizeof(float));
    input.insert(input.end(), {q.position.x, q.position.y, q.position.z, chart, q.towardsViewer.x, q.towardsViewer.y,
                               q.towardsViewer.z, 0.0f});
  }
  const size_t count = queries.size();
  const std::vector<float> output = runQueries(s.lookupProgram, input, count, 4, "the lookup queries");
  std::vector<Rgb> result(count);
  for (size_t i = 0; i < count; ++i) result[i] = Rgb(output[4 * i], output[4 * i + 1], output[4 * i + 2]);
  return result;
}

std::vector<BvhHit> GpuRenderer::intersect(const std::vector<Ray>& rays, std::vector<uint8_t>* occluded) {
  State& s = *state_;
  s.context.makeCurrent();
  s.uploadBvh(lightField_.scene);
  if (s.intersectProgram == 0)
    s.intersectProgram =
        linkProgram({{GL_COMPUTE_SHADER, std::string(kQueryComputeHead) + kGeometryGlsl + kBvhGlsl + kIntersectCompute}},
                    "intersect", false, bvhGlslConstants());
  std::vector<float> input;
  input.reserve(rays.size() * 8);
  for (const Ray& r : rays)
    input.insert(input.end(), {r.origin.x, r.origin.y, r.origin.z, r.tMin, r.direction.x, r.direction.y, r.direction.z, r.tMax});
  const size_t count = rays.size();
  const std::vector<float> output = runQueries(s.intersectProgram, input, count, 8, "the ray queries");
  std::vector<BvhHit> hits(count);
  if (occluded != nullptr) occluded->assign(count, 0);
  for (size_t i = 0; i < count; ++i) {
    hits[i].t = output[8 * i];
    std::memcpy(&hits[i].triangle, &output[8 * i + 1], sizeof(uint32_t));
    hits[i].barycentrics = Vec2(output[8 * i + 2], output[8 * i + 3]);
    if (occluded != nullptr) (*occluded)[i] = output[8 * i + 4] != 0.0f ? 1 : 0;
  }
  return hits;
}

std::vector<GpuRenderer::LightAnswer> GpuRenderer::sampleLights(const LightSampler& sampler,
                                                                 const std::vector<LightQuery>& queries) {
  if (const std::string unsupported = gpuUnsupportedLights(sampler); !unsupported.empty())
    fail("GPU renderer: the light sampler does not sample {}", unsupported);
  State& s = *state_;
  s.context.makeCurrent();
  const std::vector<uint32_t> table = gpuLightTable(sampler);
  glDeleteBuffers(1, &s.lightTable);
  glCreateBuffers(1, &s.lightTable);
  glNamedBufferStorage(s.lightTable, GLsizeiptr(table.size() * sizeof(uint32_t)), table.data(), 0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kLightTableBinding, s.lightTable);
  if (s.lightsProgram == 0)
    s.lightsProgram = linkProgram(
        {{GL_COMPUTE_SHADER, std::string(kQueryComputeHead) + kGeometryGlsl + kSurfaceGlsl + kLightsGlsl + kLightsCompute}},
        "light sampler", false, specularGlslConstants() + lightGlslConstants());
  std::vector<float> input;
  input.reserve(queries.size() * 16);
  for (const LightQuery& q : queries) {
    float triangle;
    std::memcpy(&triangle, &q.triangle, sizeof(float));
    input.insert(input.end(), {q.position.x, q.position.y, q.position.z, q.u.x, q.u.y, triangle, q.distance, q.cosLight,
                               q.origin.x, q.origin.y, q.origin.z, q.tMax, q.direction.x, q.direction.y, q.direction.z, 0.0f});
  }
  const size_t count = queries.size();
  const std::vector<float> output = runQueries(s.lightsProgram, input, count, 20, "the light sampler queries");
  if (s.lobeLightTable != 0) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kLightTableBinding, s.lobeLightTable);
  std::vector<LightAnswer> answers(count);
  for (size_t i = 0; i < count; ++i) {
    const float* r = &output[20 * i];
    LightAnswer& a = answers[i];
    const int flags = int(r[3]);
    a.sampled = (flags & 1) != 0;
    a.sample.delta = (flags & 2) != 0;
    a.sample.infinite = (flags & 4) != 0;
    a.sample.wi = Vec3(r[0], r[1], r[2]);
    a.sample.incident = Rgb(r[4], r[5], r[6]);
    a.sample.pdf = r[7];
    a.sample.target = Vec3(r[8], r[9], r[10]);
    a.emitterPdf = r[11];
    a.crossing.radiance = Rgb(r[12], r[13], r[14]);
    a.crossing.pdf = r[15];
    a.environmentPdf = r[16];
    a.sphere = r[17] != 0.0f;
  }
  return answers;
}

std::vector<GpuRenderer::LobeAnswer> GpuRenderer::sampleLobes(const std::vector<LobeQuery>& queries) {
  State& s = *state_;
  s.context.makeCurrent();
  if (s.lobesProgram == 0) {
    // The highlights' model records: the renderer's own where it has highlights, else a copy.
    if (!s.highlights) {
      const std::vector<HighlightModelGpu> models = highlightModels(lightField_.scene);
      glCreateBuffers(1, &s.lobeModels);
      glNamedBufferStorage(s.lobeModels, GLsizeiptr(std::max<size_t>(models.size() * sizeof(HighlightModelGpu), 16)),
                           models.empty() ? nullptr : models.data(), 0);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kHighlightModelsBinding, s.lobeModels);
    }
    s.lobesProgram = linkProgram({{GL_COMPUTE_SHADER, std::string(kQueryComputeHead) + kGeometryGlsl + kBvhGlsl + kSurfaceGlsl +
                                                          kHighlightsGlsl + kMirrorLikeGlsl + kLobesCompute}},
                                 "mirror-like lobe", true,
                                 highlightGlslConstants() + bvhGlslConstants() + specularGlslConstants());
  }
  std::vector<float> input;
  input.reserve(queries.size() * 12);
  for (const LobeQuery& q : queries) {
    float material;
    std::memcpy(&material, &q.material, sizeof(float));
    input.insert(input.end(), {q.wo.x, q.wo.y, q.wo.z, material, q.wi.x, q.wi.y, q.wi.z, 0.0f, q.u.x, q.u.y, 0.0f, 0.0f});
  }
  const size_t count = queries.size();
  const std::vector<float> output = runQueries(s.lobesProgram, input, count, 12, "the lobe queries");
  std::vector<LobeAnswer> answers(count);
  for (size_t i = 0; i < count; ++i) {
    const float* r = &output[12 * i];
    answers[i].sampled = r[3] != 0.0f;
    answers[i].sample.wi = Vec3(r[0], r[1], r[2]);
    answers[i].sample.weight = Rgb(r[4], r[5], r[6]);
    answers[i].sample.pdf = r[7];
    answers[i].wiPdf = r[8];
  }
  return answers;
}

std::string GpuRenderer::deviceName() const {
  state_->context.makeCurrent();
  return currentDeviceName();
}

uint64_t GpuRenderer::gpuBytes() const { return state_->bufferBytes + state_->targetBytes(); }

uint64_t GpuRenderer::lightFieldGpuBytes() const { return state_->bufferBytes; }

bool gpuAvailable(std::string* why) {
  const GpuProbe probe = probeGpu();
  if (why != nullptr) *why = probe.error;
  return probe.available;
}

GpuProbe probeGpu() {
  GpuProbe probe;
  try {
    const gpu::EglContext context;
    probe.available = true;
    probe.device = currentDeviceName();
    probe.software = isSoftwareRasteriser(reinterpret_cast<const char*>(glGetString(GL_RENDERER)));
  } catch (const Error& e) {
    probe.error = e.what();
  }
  return probe;
}

bool isSoftwareRasteriser(const std::string& glRenderer) {
  std::string name = glRenderer;
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  for (const char* software : {"llvmpipe", "softpipe", "software rasterizer"})
    if (name.find(software) != std::string::npos) return true;
  return false;
}

}  // namespace pl
