#pragma once
// The GPU renderer's surface detail (internal to src/gpu): what the shading pass reads per
// pixel besides the light field — albedo textures with their mip levels, vertex colours,
// emission textures, alpha masks, normal maps, metallic-roughness textures and the diffuse
// factor k(μ) of GGX-like models —
// uploaded as one storage buffer of 32-bit words, with the GLSL that reads it (the C++ of scene/texture.h, scene/scene.h uvAt/vertexColorAt/coverageAt/
// surfaceAt/normalMapped and lightfield/lookup.h albedoTextureLod, statement for statement).
//
// The buffer (uint detail[]): a header of 8 words — the offsets (in words) of the textures,
// levels, materials, vertices, triangles, GGX and sheen tables below — then
//   textures:  8 words each — first level (into the level table), level count (level 0 and its
//              mips), sampling flags (wrap u | wrap v << 2 | nearest << 4 | mipmaps << 5 |
//              default sampling << 6), the mean texel (3 floats), 2 unused;
//   levels:    4 words each — width, height, first texel word, palette word (kNoWord: the
//              texels are 3 floats each; else they are the CPU's packed texels as they are,
//              Texture::packed's 4×4 blocks of palette indices r | g << 8 | b << 16, one word
//              each, and the palette its ≤ 256 floats);
//   materials: 73 words each — albedo, emission, alpha and normal textures (kNoWord: none), alpha
//              factor and cutoff, normal scale, vertex alphas (1: Material::vertexAlpha), then
//              the albedo, emission, alpha and normal TextureMappings (8 words each: uv set,
//              whether default, linear[0][0], [0][1], [1][0], [1][1], offset); the diffuse
//              part's lobe (ggxLobeParameters: α, diffuseF0 (3), diffuseF90, then a glTF
//              model's layers — clear coat weight and α, sheen colour (3) and roughness, 1/√Ḡ
//              (3); k(μ) from the tables below); the metallic-roughness texture (kNoWord: none), the factors
//              materialModelAt multiplies (base colour (3), metallic, roughness), whether the
//              model is glTF's layered one, the dielectric member's Fresnel ends (3 + 1), and
//              its TextureMapping;
//   vertices:  9 words each (all meshes' vertices in the renderer's order) — uv set 0 (2
//              floats), uv set 1 (2), vertex colour (3), flags (has uvs | has uvs1 << 1 | has
//              colours << 2 | has alphas << 3), vertex alpha (the coverage factor, coverageAt);
//   triangles: 1 word each — the triangle's material;
//   GGX:       the GGX lobe-albedo tables (bsdf.h ggxAlbedoTables: the μ nodes, E₀, E₅, Ē₀, Ē₅),
//              from which k(μ) = (1 − E(μ)) / √(1 − Ē) of a diffuse part is computed as the
//              CPU computes it, per material or per pixel (metallic-roughness textures);
//   sheen:     the sheen's albedo table (ggx_lobe.h sheenAlbedoTables: the μ nodes, E_s, the
//              scales), for the diffuse part under a sheen and the sheen's highlights;
//   texels:    the levels' texels and palettes.
// Textures are uploaded only where a chart the GPU draws or a traced ray's hit
// (tracedSurfaceDetail) reads them, vertices and triangles only where some chart, mask or
// traced hit needs a uv: a scene without either costs the header, 292
// bytes per material, 7.8 KiB of GGX tables and 2.2 KiB of the sheen's.
#include <cstdint>
#include <string>
#include <vector>

#include "lightfield/lightfield.h"
#include "lightfield/lookup.h"

namespace pl::gpu {

/// Chart record flags (the shaders' ChartRecord info.z) that the surface detail adds to
/// gpu_renderer.cpp's: the diffuse albedo varies (albedoOverPi then holds the material's base
/// albedo, times the modulation per pixel), the emission is textured, the chart is
/// normal-mapped (ChartShading::normalMapped: the lookup takes the mapped normal), it keeps
/// tilted irradiances (Chart::directionalIrradiance), its diffuse part (Chart::diffuseValue) takes
/// the model of each point of a metallic-roughness texture (lookup.h glossyDiffuseReflectanceAt).
inline constexpr uint32_t kFlagTexturedAlbedo = 128u, kFlagTexturedEmission = 256u, kFlagNormalMapped = 512u,
                          kFlagDirectionalIrradiance = 1024u, kFlagMetallicRoughness = 2048u;

/// The first surface-detail feature of chart record `chart` the GPU renderer does not draw, as
/// a phrase for gpuUnsupportedFeature; empty when it draws it.
std::string surfaceDetailUnsupported(const LightField& lf, const Chart& chart, const ChartShading& shading);

/// Whether the rays the GPU traces for `lf` (mirror and glass chains, the shadow rays of
/// punctual highlights) meet surfaces whose surfaceAt reads a texture: a normal map (the
/// shading normal a mirror reflects about, a highlight is evaluated around, a thin sheet's
/// straight transmittance takes its cosine from) or an emission texture (a mirror's or glass's
/// own emission, emissionModulation). The buffer then holds every material's normal and
/// emission textures and the uvs of every vertex, and the shading passes are compiled with
/// TRACED_DETAIL (gpu_specular.h surfaceAt and followSpecular read them).
bool tracedSurfaceDetail(const LightField& lf);

/// The base albedo the shader multiplies by the per-pixel modulation on a chart whose albedo
/// varies (kFlagTexturedAlbedo): the Lambertian albedo of a diffuse chart (diffuseAlbedoAt's
/// rule), the model's diffuse albedo of a glossy one with Ẽ (glossyDiffuseAlbedoAt's).
Rgb texturedAlbedoBase(const Scene& scene, const Chart& chart);

/// The surface-detail buffer of `lf` (layout above), and per material the word offset of its
/// diffuse part's lobe record (α, diffuseF0, diffuseF90: the shader's k(μ)), kNoWord where k is
/// 1 (Lambert, Blinn-Phong) or no glossy chart with a diffuse part needs it.
struct SurfaceDetailBuffer {
  std::vector<uint32_t> words;
  std::vector<uint32_t> diffuseLobe;
};
SurfaceDetailBuffer surfaceDetailBuffer(const LightField& lf);
/// The word that stands for "none" in the buffer.
inline constexpr uint32_t kNoWord = 0xffffffffu;

/// The GLSL constants and functions (the buffer at binding `binding`): sampleTexture,
/// sampleTextureLod, surfaceDetailAt (the albedo modulation, emission texel and mapped normal
/// of a hit), ggxLobeAlbedo, ggxDiffuseFactor and diffuseFactor (k(μ) from the GGX tables),
/// ggxUpperAlbedo, sheenAlbedo, pbrLayersAt and layeredDiffuseFactor (a glTF clear coat's and
/// sheen's albedos and k(μ) of the diffuse part under them),
/// metallicRoughnessLobe (a textured material's model at a point), mappedNormalAt and emissionTexelAt (surfaceAt's normal map and
/// emissionModulation for one material record, materialRecord) and masked (the alpha mask).
/// Needs glslConstants' chart kinds.
std::string surfaceDetailGlsl(unsigned binding);

}  // namespace pl::gpu
