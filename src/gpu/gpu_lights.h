#pragma once
// The light sampler on the GPU: light/light.h LightSampler's tables uploaded as it holds them
// and its sampling and densities in GLSL, for next-event estimation at mirror-like lobes
// (lookup.h MirrorLikeLights) in the GPU renderer.
//
// One storage buffer of 16-byte rows (uvec4; floats as their bits) holds the sampler's tables:
//   row 0          the counts and first rows of the tables below (LightTableHeader)
//   row 1          the environment's constant radiance (rgb; black when it is no light), the
//                  first row of the entry of triangle table (w)
//   entries        one row each, in selection order (the environment last, when it is one): kind (kLight*), index into its table,
//                  the selection probability (Distribution1D::probability)
//   cdf            the selection's cumulative sums (Distribution1D::cdf) as doubles, two a row
//   triangles      five rows per emissive triangle: p0 | area, edge1 | two-sided, edge2 |
//                  the scene triangle's index, normal | textured, radiance
//   scene lights   two rows each: position | radius, intensity (a sphere light's; zero for a
//                  delta light, which the GLSL only reports as chosen)
//   entry of triangle   LightSampler::entryOfTriangle, four a row (−1 as 0xffffffff)
// So the GLSL chooses the same entry as the C++ for the same number (the binary search of
// Distribution1D::sample on the same doubles: GLSL doubles are core since OpenGL 4.0) and
// stretches it the same way.
//
// What the GLSL samples (kLightsGlsl lightSample): emissive triangles (uniform by area, Le by
// the emission sidedness rule, an emission texture's texel where the shading pass has surface
// detail: TRACED_DETAIL), sphere lights (uniform over the cone they subtend), a constant
// environment (uniform over the sphere); a delta light (point, spot, directional) is reported
// as chosen, with no direction, for the callers that count it 0 (NextEvent::MisExceptDelta).
// An environment map is not sampled here (gpuUnsupportedLights names it); neither is the
// nextEventOnly selection.
#include <cstdint>
#include <string>
#include <vector>

#include "light/light.h"

namespace pl {

/// Kinds of the table's entries (GLSL constants of lightGlslConstants).
inline constexpr uint32_t kLightTriangle = 0, kLightSphere = 1, kLightDelta = 2, kLightEnvironment = 3;

/// Row 0 of the table.
struct LightTableHeader {
  uint32_t entryCount = 0, cdfRow = 0, triangleRow = 0, sceneLightRow = 0;
};

/// What of `sampler`'s lights the GLSL does not sample (see above), as a phrase; empty if none.
std::string gpuUnsupportedLights(const LightSampler& sampler);

/// The table of `sampler` as uint32 words, four a row (see above).
std::vector<uint32_t> gpuLightTable(const LightSampler& sampler);

/// The storage-buffer binding of the table.
inline constexpr uint32_t kLightTableBinding = 24;

/// GLSL constants of the kinds and the binding (prefixed to kLightsGlsl's programs).
std::string lightGlslConstants();

/// GLSL: the block LightTable (LIGHT_TABLE_BINDING) and
///   bool lightSample(vec3 position, vec2 u, out LightSampleGpu s) — LightSampler::sample
///     (without nextEventOnly); s.delta for a delta light, whose other fields are unset;
///   float emitterPdf(uint triangle, float distance, float cosLight) — LightSampler::emitterPdf
///     with `triangle` the scene's triangle index (mesh by mesh);
///   float environmentLightPdf(vec3 direction) — LightSampler::environmentPdf;
///   bool sphereLightAlong(vec3 origin, vec3 direction, float tMin, float tMax, vec3 receiver,
///     out vec3 radiance, out float pdf) — LightSampler::sphereLightAlong;
///   float powerHeuristic(float a, float b) — core/sampling.h's.
/// Needs kSurfaceGlsl (offsetRayOrigin, frameFromNormal) before it, and with TRACED_DETAIL the
/// surface detail's emissionTexelAt.
extern const char* const kLightsGlsl;

}  // namespace pl
