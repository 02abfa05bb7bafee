#pragma once
// Mirrors and smooth glass in the GPU renderer: lookup.h followSpecular and the fast
// renderer's reflection wavefront (realtime.h step 3) in GLSL, the rays traced through the
// GPU BVH (gpu_bvh.h).
//
// At a camera ray's hit on a specular chart record (what viewedChart gives) the shading pass
// follows the chain as the CPU renderers do: the surface's own emission, then up to the
// renderer's mirror depth (effectiveMirrorDepth) reflected or refracted rays, each traced to
// its closest hit, where the light field is looked up (a diffuse or glossy record), the chain
// goes on (another specular record), nothing is seen (a one-sided curved record from behind)
// or the environment is (a miss). Each step is followSpecular's: the surface frame of
// surfaceAt (geometric normal from the winding, interpolated shading normal, the point from
// the barycentrics), the sidedness rules of scatteringFrame and usableSide, the mirror's delta
// sample (Schlick Fresnel where the material asks for it), smooth glass's branch (Fresnel F
// for solid glass, R′/(R′+T′) by luminance for thin sheets) drawn with specularBranchU's hash
// of the arriving ray's bits, Beer–Lambert inside, the offset origin of offsetRayOrigin and
// Russian roulette from kSpecularRouletteStep with specularRouletteU. The hash is the C++ one
// (hashCombine over the ray's six float bit patterns) in 64-bit GLSL integers, so it needs
// GL_ARB_gpu_shader_int64.
//
// Mirror-like glossy lobes (specular records of a Blinn-Phong or GGX model, MIRROR_LIKE): the
// lobe sampled with specularLobeU (gpu_mirror_like.h), kFirstHitLobeSamples stratified samples
// at a camera ray's first hit, and (LOBE_LIGHTS, where the scene has emitters to sample) the
// emitters' next-event estimation at each mirror-like hit with the chain's MIS state
// (lookup.h MirrorLikeLights, LobeChain; the light sampler of gpu_lights.h); their delta
// lights' highlights come from punctualHighlights (gpu_highlights.h).
// What it does not follow (gpuUnsupportedSpecular names it): glTF layered materials on a
// mirror or glass (materialModelAt would make the model anew per point). A normal map on a mirror or
// glass bends surfaceAt's shading normal and an emission texture modulates its emission
// (TRACED_DETAIL, gpu_surface_detail.h tracedSurfaceDetail); the lookup at the chain's end
// reads the surface detail there (hitSurfaceDetail, the ray cone coneSpread × the chain's
// summed length; none where no chart reads any: gpu_renderer.cpp PIXEL_DETAIL).
#include <cstdint>
#include <string>
#include <vector>

#include "lightfield/lightfield.h"

namespace pl {

/// Whether the light field has specular chart records (mirrors, glass, mirror-like lobes).
bool hasSpecularCharts(const LightField& lf);

/// The first specular feature of `lf` the GPU renderer does not draw (see above), as a phrase
/// for gpuUnsupportedFeature; empty when it draws all its specular charts.
std::string gpuUnsupportedSpecular(const LightField& lf);

/// One material as kSpecularGlsl reads it (std430: four 16-byte rows).
struct SpecularMaterialGpu {
  float colour[4];      ///< rgb: the mirror's reflectance or the glass's transmittance; w: kind (uint bits)
  float dielectric[4];  ///< x: index of refraction; y: thin sheet (1/0); z: Schlick Fresnel (1/0)
  float absorption[4];  ///< rgb: σa per scene unit (interiorAbsorption)
  float emission[4];    ///< rgb: Material::emission; w: two-sided emission (1/0)
};
static_assert(sizeof(SpecularMaterialGpu) == 64);

/// Kinds of SpecularMaterialGpu (GLSL constants of specularGlslConstants).
inline constexpr uint32_t kSpecularOther = 0, kSpecularMirror = 1, kSpecularGlass = 2;

/// Per material of the scene, in its order.
std::vector<SpecularMaterialGpu> specularMaterials(const Scene& scene);

/// The storage-buffer bindings of the materials and the triangles' materials.
inline constexpr uint32_t kSpecularMaterialsBinding = 18, kTriangleMaterialsBinding = 19;

/// GLSL constants of the kinds, the roulette step and the bindings (prefixed to
/// kSpecularGlsl's programs).
std::string specularGlslConstants();

/// GLSL shared by the chains and the punctual highlights (gpu_highlights.h): the blocks
/// SpecularMaterials (SPECULAR_MATERIALS_BINDING, per material) and TriangleMaterials
/// (TRIANGLE_MATERIALS_BINDING, per triangle), surfaceAt, frameFromNormal (Frame::fromNormal),
/// offsetRayOrigin, fresnelDielectric and thinSheetReflectanceTransmittance. Needs the shading
/// pass's geometry blocks and the surface detail (gpu_surface_detail.h) before it.
extern const char* const kSurfaceGlsl;

/// GLSL: vec3 specularChain(vec3 origin, vec3 direction, float t, uint triangle, vec2 uv,
/// uint mirrorDepth) — the radiance along a camera ray whose closest hit is (t, triangle, uv)
/// on a specular record, without the camera weight. Needs kBvhGlsl, kSurfaceGlsl, hitNormals,
/// hitSurfaceDetail and the uniform coneSpread, lookupRadiance, environmentRadiance,
/// punctualHighlights (gpu_highlights.h), the 64-bit hash (hashCombine), reversedSobolSecond
/// and, with MIRROR_LIKE, kHighlightsGlsl and kMirrorLikeGlsl, with LOBE_LIGHTS kLightsGlsl,
/// before it.
extern const char* const kSpecularGlsl;

}  // namespace pl
