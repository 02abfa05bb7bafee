// The GPU renderer's surface detail (gpu_surface_detail.h): the buffer and its GLSL.
#include "gpu/gpu_surface_detail.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <limits>
#include <optional>
#include <variant>

#include "bsdf/bsdf.h"
#include "bsdf/ggx_lobe.h"
#include "gpu/gpu_highlights.h"
#include "gpu/gpu_specular.h"

namespace pl::gpu {
namespace {

constexpr uint32_t kNone = kNoWord;
constexpr uint32_t kHeaderWords = 8, kTextureWords = 8, kLevelWords = 4, kMappingWords = 8, kVertexWords = 9;
// Material record (gpu_surface_detail.h): albedo, emission, alpha and normal textures, alpha
// factor, cutoff, normal scale, vertex alphas (1: some mesh of the material has them), then the
// albedo, emission, alpha and normal mappings, the diffuse part's lobe (kDiffuseLobeWords), the
// metallic-roughness record (kMetallicRoughnessWords) and its mapping.
constexpr uint32_t kDiffuseLobeWords = 14, kMetallicRoughnessWords = 11;
constexpr uint32_t kMaterialAlbedoMapping = 8, kMaterialEmissionMapping = kMaterialAlbedoMapping + kMappingWords,
                   kMaterialAlphaMapping = kMaterialEmissionMapping + kMappingWords,
                   kMaterialNormalMapping = kMaterialAlphaMapping + kMappingWords,
                   kMaterialDiffuseLobe = kMaterialNormalMapping + kMappingWords,
                   kMaterialMetallicRoughness = kMaterialDiffuseLobe + kDiffuseLobeWords,
                   kMaterialMetallicRoughnessMapping = kMaterialMetallicRoughness + kMetallicRoughnessWords,
                   kMaterialWords = kMaterialMetallicRoughnessMapping + kMappingWords;
// Texture sampling flags.
constexpr uint32_t kNearestBit = 16u, kMipmapsBit = 32u, kDefaultSamplingBit = 64u;

uint32_t bits(float f) { return std::bit_cast<uint32_t>(f); }

/// What the GPU reads of each texture: nothing, level 0 (emission textures, alpha masks: read
/// at full resolution, Texture::sample) or every level (albedo textures: sampleLod).
enum class TextureUse : uint8_t { None, Level0, AllLevels };

/// Whether diffuseDirectionalFactor (bsdf.h) of `model` is not simply 1 above the horizon: the
/// GGX-like models', whose k(μ) follows the lobe's albedo.
bool variesWithAngle(const Bsdf& model) {
  return std::holds_alternative<GgxBsdf>(model) || std::holds_alternative<GltfPbrBsdf>(model);
}

void appendMapping(std::vector<uint32_t>& words, const TextureMapping& m) {
  words.insert(words.end(), {uint32_t(m.uvSet), m.isDefault() ? 1u : 0u, bits(m.linear[0][0]), bits(m.linear[0][1]),
                             bits(m.linear[1][0]), bits(m.linear[1][1]), bits(m.offset.x), bits(m.offset.y)});
}

/// The metallic-roughness record of material `m` (kMetallicRoughnessWords, then its mapping):
/// the texture (kNone: none), the factors materialModelAt multiplies the texel and the albedo
/// modulation by — base colour (3), metallic, roughness — whether the model is glTF's layered
/// one (gltfPbrFromInputs at every metalness) or gltfMetallicRoughnessModel's, and the
/// dielectric member's Fresnel ends (3 + 1), which depend on neither the texel nor the
/// modulation: gltfPbrFromInputs' of the material's own inputs (a layered model made without
/// a point: PbrLayerMaps' factors and mean texels), of the defaults otherwise.
void appendMetallicRoughness(std::vector<uint32_t>& words, const Material& m, const Scene& scene) {
  const MetallicRoughnessMap& mr = m.metallicRoughness;
  const bool layered = m.layers.layered;
  Rgb base = mr.baseColor;
  float metallic = mr.metallic, roughness = mr.roughness;
  GltfPbrBsdf dielectric = gltfPbrFromInputs(GltfPbrInputs{});
  if (layered) {
    base = m.layers.factors.baseColor, metallic = m.layers.factors.metallic, roughness = m.layers.factors.roughness;
    if (mr.texture >= 0) dielectric = std::get<GltfPbrBsdf>(materialModelAt(scene, m, AlbedoPoint{}));
  }
  words.insert(words.end(), {mr.texture >= 0 ? uint32_t(mr.texture) : kNone, bits(base.r), bits(base.g), bits(base.b),
                             bits(metallic), bits(roughness), layered ? 1u : 0u, bits(dielectric.dielectricF0.r),
                             bits(dielectric.dielectricF0.g), bits(dielectric.dielectricF0.b),
                             bits(dielectric.dielectricF90)});
  appendMapping(words, mr.mapping);
}

}  // namespace

std::string surfaceDetailUnsupported(const LightField& lf, const Chart& chart, const ChartShading& shading) {
  const Material& material = lf.scene.materials[chart.material];
  const Bsdf& model = material.bsdf;
  // k(μ) of a clear coat's or sheen's diffuse base is normalised by a mean over μ (1/√Ḡ,
  // ggxLobeParameters' diffuseNorm) made once per material: with a metallic-roughness texture
  // each point's model (its diffuse part's k, its highlights) would need its own.
  if (chart.kind == ChartKind::Glossy && material.metallicRoughness.texture >= 0)
    if (const std::optional<GgxLobeParameters> lobe = ggxLobeParameters(model);
        lobe && lobe->layered() && ((chart.diffuseValue && shading.needsUv) || gpuHighlightsActive(lf)))
      return "glTF materials with a clear coat or sheen and a metallic-roughness texture";
  // diffuseAlbedoAt multiplies a Lambertian or subsurface albedo by the modulation (albedo()
  // of either is its albedo); another model's directional albedo at normal incidence is not
  // linear in it. (Only those two models make diffuse charts: bake/parameterisation.h.)
  if (shading.texturedAlbedo && chart.kind == ChartKind::Diffuse && !std::holds_alternative<LambertBsdf>(model) &&
      !std::holds_alternative<SubsurfaceBsdf>(model))
    return "albedo textures on diffuse charts of a model other than Lambert or subsurface";
  return {};
}

bool tracedSurfaceDetail(const LightField& lf) {
  if (!hasSpecularCharts(lf) && !gpuHighlightsActive(lf)) return false;
  return std::any_of(lf.scene.materials.begin(), lf.scene.materials.end(),
                     [](const Material& m) { return m.normalTexture >= 0 || m.emissionTexture >= 0; });
}

Rgb texturedAlbedoBase(const Scene& scene, const Chart& chart) {
  const Bsdf& model = scene.materials[chart.material].bsdf;
  if (const auto* lambert = std::get_if<LambertBsdf>(&model); lambert != nullptr && chart.kind == ChartKind::Diffuse)
    return lambert->albedo;
  return diffuseAlbedo(model);
}

SurfaceDetailBuffer surfaceDetailBuffer(const LightField& lf) {
  const Scene& scene = lf.scene;
  // Which textures the shader reads, and whether any lookup or mask needs a hit's uv.
  std::vector<TextureUse> use(scene.textures.size(), TextureUse::None);
  auto need = [&](int texture, TextureUse u) {
    if (texture >= 0 && use[size_t(texture)] < u) use[size_t(texture)] = u;
  };
  bool needsUv = false;
  std::vector<bool> needsFactor(scene.materials.size(), false);
  const SunLights sun = sunLightsOf(lf);
  for (uint32_t i = 0; i < lf.charts.size(); ++i) {
    const ChartShading shading = chartShading(lf, i, sun);
    const Material& m = scene.materials[lf.charts[i].material];
    needsUv = needsUv || shading.needsUv;
    const Bsdf& model = m.bsdf;
    if (lf.charts[i].diffuseValue && variesWithAngle(model)) needsFactor[lf.charts[i].material] = true;
    if (shading.needsUv && shading.texturedAlbedo) need(m.albedoTexture, TextureUse::AllLevels);
    if (shading.needsUv && lf.charts[i].diffuseValue) need(m.metallicRoughness.texture, TextureUse::Level0);
    if (shading.texturedEmission) need(m.emissionTexture, TextureUse::Level0);
    if (shading.normalMapped) {
      needsUv = true;
      need(m.normalTexture, TextureUse::Level0);
    }
  }
  if (tracedSurfaceDetail(lf)) {
    needsUv = true;
    for (const Material& m : scene.materials) {
      need(m.normalTexture, TextureUse::Level0);
      need(m.emissionTexture, TextureUse::Level0);
    }
  }
  // A highlight on a metallic-roughness-textured material takes the point's model: the albedo
  // and metallic-roughness textures at full resolution and the uvs (gpu_highlights.h).
  if (gpuHighlightsActive(lf))
    for (const Material& m : scene.materials)
      if (m.metallicRoughness.texture >= 0) {
        needsUv = true;
        need(m.albedoTexture, TextureUse::Level0);
        need(m.metallicRoughness.texture, TextureUse::Level0);
      }
  for (const Material& m : scene.materials)
    if (m.isMasked()) {
      needsUv = true;
      need(m.alphaTexture, TextureUse::Level0);
    }

  std::vector<uint32_t> words(kHeaderWords, 0u);
  // Textures and their level table; the texels go after the tables (their offsets are filled
  // in once the tables' sizes are known).
  struct LevelSource {
    const Image* image;
    const std::vector<Texture::PackedBlock>* packed;
    const std::vector<float>* palette;
  };
  std::vector<LevelSource> levels;
  std::vector<uint32_t> textureTable;
  for (size_t t = 0; t < scene.textures.size(); ++t) {
    const Texture& texture = scene.textures[t];
    const TextureSampling& s = texture.sampling;
    const uint32_t count = use[t] == TextureUse::None ? 0u : use[t] == TextureUse::Level0 ? 1u : uint32_t(1 + texture.mips.size());
    textureTable.insert(textureTable.end(),
                        {uint32_t(levels.size()), count,
                         uint32_t(s.wrapU) | uint32_t(s.wrapV) << 2 | (s.nearest ? kNearestBit : 0u) |
                             (s.mipmaps ? kMipmapsBit : 0u) | (s.isDefault() ? kDefaultSamplingBit : 0u),
                         bits(texture.average.r), bits(texture.average.g), bits(texture.average.b), 0u, 0u});
    if (count > 0) levels.push_back({&texture.image, &texture.packed, &texture.palette});
    for (uint32_t l = 1; l < count; ++l) {
      const Texture::Level& level = texture.mips[l - 1];
      levels.push_back({&level.image, &level.packed, &level.palette});
    }
  }
  words[0] = uint32_t(words.size());
  words.insert(words.end(), textureTable.begin(), textureTable.end());
  words[1] = uint32_t(words.size());
  const size_t levelTable = words.size();
  words.resize(words.size() + levels.size() * kLevelWords, 0u);
  // Materials.
  words[2] = uint32_t(words.size());
  std::vector<uint32_t> diffuseLobes(scene.materials.size(), kNone);
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    auto index = [](int texture) { return texture >= 0 ? uint32_t(texture) : kNone; };
    const uint32_t record = uint32_t(words.size());
    words.insert(words.end(), {index(m.albedoTexture), index(m.emissionTexture), index(m.alphaTexture),
                               index(m.normalTexture), bits(m.alphaFactor), bits(m.alphaCutoff), bits(m.normalScale),
                               m.vertexAlpha ? 1u : 0u});
    appendMapping(words, m.albedoMapping);
    appendMapping(words, m.emissionMapping);
    appendMapping(words, m.alphaMapping);
    appendMapping(words, m.normalMapping);
    // The diffuse part's lobe: α, the Fresnel ends of the lobe whose albedo it gives up, and
    // the layers above it (ggxLobeParameters).
    const std::optional<GgxLobeParameters> lobe = ggxLobeParameters(m.bsdf);
    if (needsFactor[i] && lobe) diffuseLobes[i] = record + kMaterialDiffuseLobe;
    const GgxLobeParameters l = lobe.value_or(GgxLobeParameters{});
    words.insert(words.end(), {bits(l.alpha), bits(l.diffuseF0.r), bits(l.diffuseF0.g), bits(l.diffuseF0.b), bits(l.diffuseF90),
                               bits(l.clearcoat), bits(l.clearcoatAlpha), bits(l.sheenColor.r), bits(l.sheenColor.g),
                               bits(l.sheenColor.b), bits(l.sheenRoughness), bits(l.diffuseNorm.r), bits(l.diffuseNorm.g),
                               bits(l.diffuseNorm.b)});
    appendMetallicRoughness(words, m, scene);
  }
  // Vertices and triangles, in the renderer's order (meshes one after another).
  words[3] = uint32_t(words.size());
  if (needsUv) {
    for (const Mesh& mesh : scene.meshes) {
      const uint32_t flags = (mesh.uvs.empty() ? 0u : 1u) | (mesh.uvs1.empty() ? 0u : 2u) | (mesh.colors.empty() ? 0u : 4u) |
                             (mesh.alphas.empty() ? 0u : 8u);
      for (size_t v = 0; v < mesh.positions.size(); ++v) {
        const Vec2 uv0 = mesh.uvs.empty() ? Vec2(0.0f) : mesh.uvs[v], uv1 = mesh.uvs1.empty() ? Vec2(0.0f) : mesh.uvs1[v];
        const Rgb colour = mesh.colors.empty() ? Rgb(1.0f) : mesh.colors[v];
        const float alpha = mesh.alphas.empty() ? 1.0f : mesh.alphas[v];
        words.insert(words.end(), {bits(uv0.x), bits(uv0.y), bits(uv1.x), bits(uv1.y), bits(colour.r), bits(colour.g),
                                   bits(colour.b), flags, bits(alpha)});
      }
    }
  }
  words[4] = uint32_t(words.size());
  if (needsUv)
    for (const Mesh& mesh : scene.meshes) words.insert(words.end(), mesh.materials.begin(), mesh.materials.end());
  // The GGX lobe-albedo tables (ggxAlbedoTables): μ nodes, E₀, E₅, Ē₀, Ē₅.
  const GgxAlbedoTables& tables = ggxAlbedoTables();
  words[5] = uint32_t(words.size());
  for (const std::vector<float>* table : {&tables.mu, &tables.e0, &tables.e5, &tables.mean0, &tables.mean5})
    for (float v : *table) words.push_back(bits(v));
  // The sheen's albedo table (sheenAlbedoTables): μ nodes, E_s (scaled), the scales.
  const SheenAlbedoTables& sheen = sheenAlbedoTables();
  words[6] = uint32_t(words.size());
  for (const std::vector<float>* table : {&sheen.mu, &sheen.e, &sheen.scale})
    for (float v : *table) words.push_back(bits(v));
  // The texels: a level's packed texels (4×4 blocks of palette indices, Texture::PackedBlock)
  // and its palette where it has them, else 3 floats per texel.
  for (size_t l = 0; l < levels.size(); ++l) {
    const LevelSource& level = levels[l];
    uint32_t* record = &words[levelTable + l * kLevelWords];
    record[0] = uint32_t(level.image->width);
    record[1] = uint32_t(level.image->height);
    record[2] = uint32_t(words.size());
    record[3] = kNone;
    if (!level.packed->empty()) {
      for (const Texture::PackedBlock& block : *level.packed) words.insert(words.end(), block.texels, block.texels + 16);
      words[levelTable + l * kLevelWords + 3] = uint32_t(words.size());
      for (float v : *level.palette) words.push_back(bits(v));
    } else {
      for (const Rgb& texel : level.image->pixels) words.insert(words.end(), {bits(texel.r), bits(texel.g), bits(texel.b)});
    }
  }
  return {std::move(words), std::move(diffuseLobes)};
}

std::string surfaceDetailGlsl(unsigned binding) {
  return fmt::format(
             "#define SURFACE_DETAIL_BINDING {}\nconst uint kTextureWords = {}u, kLevelWords = {}u, kVertexWords = {}u, "
             "kMaterialWords = {}u, kMaterialAlbedoMapping = {}u, kMaterialEmissionMapping = {}u, kMaterialAlphaMapping = "
             "{}u, kMaterialNormalMapping = {}u;\nconst uint kRepeat = {}u, kClampToEdge = {}u, kMirroredRepeat = {}u, kNearestBit = {}u, kMipmapsBit = "
             "{}u, kDefaultSamplingBit = {}u;\nconst uint kFlagTexturedAlbedo = {}u, kFlagTexturedEmission = {}u;\n"
             "const float kInvPi = {:.9g};\nconst uint kFlagNormalMapped = {}u, kFlagDirectionalIrradiance = {}u;\n"
             "const uint kTiltedNormals = {}u;\nconst float kNormalTiltCosine = {:.9g}, kNormalTiltSine = {:.9g};\n"
             "const vec2 kTiltAcross[{}] = vec2[{}](vec2({:.9g}, {:.9g}), vec2({:.9g}, {:.9g}), vec2({:.9g}, {:.9g}));\n"
             "const uint kMaterialDiffuseLobe = {}u, kMaterialMetallicRoughness = {}u, kMaterialMetallicRoughnessMapping = {}u;\n"
             "const uint kFlagMetallicRoughness = {}u;\nconst int kGgxMuNodes = {}, kGgxRoughNodes = {};\n"
             "const float kGgxMinAlpha = {:.9g};\nconst int kSheenMuNodes = {}, kSheenRoughNodes = {};\n"
             "const float kSheenMinRoughness = {:.9g}, kClearcoatF0 = {:.9g};\n",
             binding, kTextureWords, kLevelWords, kVertexWords, kMaterialWords, kMaterialAlbedoMapping,
             kMaterialEmissionMapping, kMaterialAlphaMapping, kMaterialNormalMapping, unsigned(TextureWrap::Repeat),
             unsigned(TextureWrap::ClampToEdge), unsigned(TextureWrap::MirroredRepeat), kNearestBit, kMipmapsBit,
             kDefaultSamplingBit, kFlagTexturedAlbedo, kFlagTexturedEmission, kInvPi, kFlagNormalMapped,
             kFlagDirectionalIrradiance, kTiltedNormals, kNormalTiltCosine, kNormalTiltSine, kTiltedNormals, kTiltedNormals,
             kTiltAcross[0][0], kTiltAcross[0][1], kTiltAcross[1][0], kTiltAcross[1][1], kTiltAcross[2][0],
             kTiltAcross[2][1], kMaterialDiffuseLobe, kMaterialMetallicRoughness, kMaterialMetallicRoughnessMapping,
             kFlagMetallicRoughness, ggxAlbedoTables().muNodes, ggxAlbedoTables().roughNodes, kGgxMinAlpha,
             sheenAlbedoTables().muNodes, sheenAlbedoTables().roughNodes, kSheenMinRoughness, kClearcoatF0) +
         R"glsl(
layout(std430, binding = SURFACE_DETAIL_BINDING) readonly buffer SurfaceDetailWords { uint detail[]; };
const uint kNone = 0xffffffffu;
float detailFloat(uint i) { return uintBitsToFloat(detail[i]); }
vec3 detailRgb(uint i) { return vec3(detailFloat(i), detailFloat(i + 1u), detailFloat(i + 2u)); }

// repeatIndex and wrapIndex (texture.cpp): texel index i (a whole number) of an axis of n
// texels, wrapped. (GLSL's % is undefined for negative operands: the C++ remainder's
// negative case is written out.)
int repeatIndex(float i, int n) {
  if (i >= 0.0 && i < float(n)) return int(i);
  if (abs(i) < 1073741824.0) {
    int k = int(i);
    return k >= 0 ? k % n : n - 1 - ((-k - 1) % n);
  }
  float m = i - float(n) * floor(i / float(n));  // fmod's non-negative remainder, for huge coordinates
  int k = int(m);
  return k >= n ? 0 : max(k, 0);
}
int wrapIndex(float i, int n, uint wrap) {
  if (wrap == kClampToEdge) return i <= 0.0 ? 0 : i >= float(n - 1) ? n - 1 : int(i);
  if (wrap == kMirroredRepeat) {
    int m = repeatIndex(i, 2 * n);
    return m < n ? m : 2 * n - 1 - m;
  }
  return repeatIndex(i, n);
}

// BilinearFootprint: the 2×2 texels a bilinear read blends and their weights.
struct Footprint { int x0, x1, y0, y1; float fx, fy; };
ivec2 levelSize(uint level) {
  uint record = detail[1] + kLevelWords * level;
  return ivec2(int(detail[record]), int(detail[record + 1u]));
}
// sampledFootprint (texture.cpp; bilinearFootprint is its repeat, bilinear case): false for a
// non-finite uv.
bool sampledFootprint(ivec2 size, vec2 uv, uint wrapU, uint wrapV, bool nearest, out Footprint f) {
  float half_ = nearest ? 0.0 : 0.5;
  float x = uv.x * float(size.x) - half_;
  float y = (1.0 - uv.y) * float(size.y) - half_;
  f = Footprint(0, 0, 0, 0, 0.0, 0.0);
  if (isnan(x) || isinf(x) || isnan(y) || isinf(y)) return false;
  float x0f = floor(x), y0f = floor(y);
  f.fx = nearest ? 0.0 : x - x0f;
  f.fy = nearest ? 0.0 : y - y0f;
  float step_ = nearest ? 0.0 : 1.0;
  f.x0 = wrapIndex(x0f, size.x, wrapU);
  f.x1 = wrapIndex(x0f + step_, size.x, wrapU);
  f.y0 = wrapIndex(y0f, size.y, wrapV);
  f.y1 = wrapIndex(y0f + step_, size.y, wrapV);
  return true;
}
// reducedFootprint (texture.cpp): a uv already reduced to [0, 1)².
void reducedAxis(float x, int n, out int i0, out int i1, out float fraction) {
  int below = int(x + 1.0) - 1;  // floor(x) for x >= -1
  fraction = x - float(below);
  i0 = below < 0 ? n - 1 : below;
  i1 = below + 1 >= n ? 0 : below + 1;
}
Footprint reducedFootprint(ivec2 size, vec2 uv) {
  Footprint f;
  reducedAxis(uv.x * float(size.x) - 0.5, size.x, f.x0, f.x1, f.fx);
  reducedAxis((1.0 - uv.y) * float(size.y) - 0.5, size.y, f.y0, f.y1, f.fy);
  return f;
}
// Texel (x, y) of a level (row 0 = the image's top): its packed palette indices (packedTexel's
// 4×4 blocks) or its 3 floats.
vec3 levelTexel(uint level, int x, int y) {
  uint record = detail[1] + kLevelWords * level;
  uint width = detail[record], texels = detail[record + 2u], palette = detail[record + 3u];
  if (palette == kNone) return detailRgb(texels + 3u * (uint(y) * width + uint(x)));
  uint blocksPerRow = (width + 3u) / 4u;
  uint p = detail[texels + 16u * ((uint(y) >> 2) * blocksPerRow + (uint(x) >> 2)) + (uint(y) & 3u) * 4u + (uint(x) & 3u)];
  return vec3(detailFloat(palette + (p & 0xffu)), detailFloat(palette + ((p >> 8) & 0xffu)),
              detailFloat(palette + ((p >> 16) & 0xffu)));
}
// sampleLevel's blend.
vec3 bilinearLevel(uint level, Footprint f) {
  vec3 top = (1.0 - f.fx) * levelTexel(level, f.x0, f.y0) + f.fx * levelTexel(level, f.x1, f.y0);
  vec3 bottom = (1.0 - f.fx) * levelTexel(level, f.x0, f.y1) + f.fx * levelTexel(level, f.x1, f.y1);
  return (1.0 - f.fy) * top + f.fy * bottom;
}
// Texture::sample: level 0, bilinear (or nearest), wrapped as the texture's sampling says; its
// mean texel for a non-finite uv.
vec3 sampleTexture(uint texture, vec2 uv) {
  uint record = detail[0] + kTextureWords * texture;
  uint level0 = detail[record], flags = detail[record + 2u];
  Footprint f;
  if (!sampledFootprint(levelSize(level0), uv, flags & 3u, (flags >> 2) & 3u, (flags & kNearestBit) != 0u, f))
    return detailRgb(record + 3u);
  return bilinearLevel(level0, f);
}
// Texture::sampleLod: trilinear between levels floor(lod) and floor(lod) + 1; lod <= 0 or NaN
// is sampleTexture.
vec3 sampleTextureLod(uint texture, vec2 uv, float lod) {
  uint record = detail[0] + kTextureWords * texture;
  uint level0 = detail[record], levels = detail[record + 1u], flags = detail[record + 2u];
  if (!(lod > 0.0) || levels <= 1u || (flags & kMipmapsBit) == 0u) return sampleTexture(texture, uv);
  float clamped = min(lod, float(levels - 1u));
  uint fine = uint(clamped);
  float f = clamped - float(fine);
  vec3 a, b;
  if ((flags & kDefaultSamplingBit) == 0u) {
    Footprint footprint;
    if (!sampledFootprint(levelSize(level0 + fine), uv, flags & 3u, (flags >> 2) & 3u, false, footprint))
      return detailRgb(record + 3u);
    a = bilinearLevel(level0 + fine, footprint);
    if (f == 0.0) return a;
    sampledFootprint(levelSize(level0 + fine + 1u), uv, flags & 3u, (flags >> 2) & 3u, false, footprint);
    b = bilinearLevel(level0 + fine + 1u, footprint);
    return (1.0 - f) * a + f * b;
  }
  uv -= floor(uv);
  if (!(uv.x < 1.0)) uv.x = 0.0;
  if (!(uv.y < 1.0)) uv.y = 0.0;
  if (!(uv.x >= 0.0 && uv.y >= 0.0)) return detailRgb(record + 3u);
  a = bilinearLevel(level0 + fine, reducedFootprint(levelSize(level0 + fine), uv));
  if (f == 0.0) return a;
  b = bilinearLevel(level0 + fine + 1u, reducedFootprint(levelSize(level0 + fine + 1u), uv));
  return (1.0 - f) * a + f * b;
}

// uvAt with a TextureMapping (scene.h) at barycentrics b of the triangle with vertices v: the
// slot's uv set interpolated (the barycentrics for a mesh without it), then its transform.
vec2 vertexUv(uint vertex, uint set) {
  uint i = detail[3] + kVertexWords * vertex + 2u * set;
  return vec2(detailFloat(i), detailFloat(i + 1u));
}
bool hasUvSet(uint vertex, uint set) { return (detail[detail[3] + kVertexWords * vertex + 7u] & (set == 1u ? 2u : 1u)) != 0u; }
// TextureMapping::apply: linear · uv + offset (linear column-major, as glm's Mat2).
vec2 applyMapping(uint mapping, vec2 uv) {
  if (detail[mapping + 1u] != 0u) return uv;
  return vec2(detailFloat(mapping + 2u) * uv.x + detailFloat(mapping + 4u) * uv.y,
              detailFloat(mapping + 3u) * uv.x + detailFloat(mapping + 5u) * uv.y) +
         vec2(detailFloat(mapping + 6u), detailFloat(mapping + 7u));
}
vec2 mappedUv(uint mapping, uvec3 v, vec2 b) {
  uint set = detail[mapping];
  vec2 uv = b;
  if (hasUvSet(v.x, set)) {
    float b1 = b.x, b2 = b.y, b0 = 1.0 - b1 - b2;
    uv = b0 * vertexUv(v.x, set) + b1 * vertexUv(v.y, set) + b2 * vertexUv(v.z, set);
  }
  return applyMapping(mapping, uv);
}
// vertexColorAt (scene.h).
vec3 vertexColorAt(uvec3 v, vec2 b) {
  uint x = detail[3] + kVertexWords * v.x;
  if ((detail[x + 7u] & 4u) == 0u) return vec3(1.0);
  float b1 = b.x, b2 = b.y, b0 = 1.0 - b1 - b2;
  return b0 * detailRgb(x + 4u) + b1 * detailRgb(detail[3] + kVertexWords * v.y + 4u) +
         b2 * detailRgb(detail[3] + kVertexWords * v.z + 4u);
}
// approximateLog2 (core/math.h).
float approximateLog2(float x) {
  if (!(x > 0.0)) return -1.0 / 0.0;
  uint xBits = floatBitsToUint(x);
  float t = uintBitsToFloat((xBits & 0x007fffffu) | 0x3f800000u) - 1.0;
  return float(int(xBits >> 23) - 127) + t + 0.347 * t * (1.0 - t);
}
// albedoTextureLod (lookup.h): the mip level of a ray cone coneWidth wide arriving along
// `direction` at the triangle (vertices v at p0, p1, p2) through mapping `mapping`.
float albedoTextureLod(uint texture, uint mapping, uvec3 v, vec3 p0, vec3 p1, vec3 p2, vec3 direction, float coneWidth) {
  if (!(coneWidth > 0.0)) return 0.0;
  vec3 c = cross(p1 - p0, p2 - p0);
  float uvCross = 1.0;
  uint set = detail[mapping];
  if (hasUvSet(v.x, set)) {
    vec2 a = vertexUv(v.y, set) - vertexUv(v.x, set), b = vertexUv(v.z, set) - vertexUv(v.x, set);
    uvCross = abs(a.x * b.y - a.y * b.x);
  }
  if (detail[mapping + 1u] == 0u)
    uvCross *= abs(detailFloat(mapping + 2u) * detailFloat(mapping + 5u) - detailFloat(mapping + 4u) * detailFloat(mapping + 3u));
  float cosArea = abs(dot(direction, c));
  ivec2 size = levelSize(detail[detail[0] + kTextureWords * texture]);
  float texelsSquared = float(size.x) * float(size.y) * uvCross * (coneWidth * coneWidth) / cosArea;
  return 0.5 * approximateLog2(texelsSquared);
}

// normalMapped (scene.cpp): shading normal n perturbed by the normal-map texel in the tangent
// frame of the triangle p0 p1 p2 with (mapped) uvs uv0 uv1 uv2; n where there is no frame or
// the result would fall behind the geometric normal ng.
vec3 normalMapped(vec3 n, vec3 ng, vec3 p0, vec3 p1, vec3 p2, vec2 uv0, vec2 uv1, vec2 uv2, vec3 texel, float scale) {
  vec3 e1 = p1 - p0, e2 = p2 - p0;
  vec2 d1 = uv1 - uv0, d2 = uv2 - uv0;
  float det = d1.x * d2.y - d1.y * d2.x;
  if (!(abs(det) > 1e-12)) return n;
  vec3 dpdu = (e1 * d2.y - e2 * d1.y) / det;
  vec3 dpdv = (e2 * d1.x - e1 * d2.x) / det;
  vec3 t = dpdu - n * dot(n, dpdu);
  float tLength = length(t);
  if (!(tLength > 0.0) || isinf(tLength) || isnan(tLength)) return n;
  t /= tLength;
  vec3 b = dot(cross(n, t), dpdv) < 0.0 ? -cross(n, t) : cross(n, t);
  vec3 m = vec3(scale * (2.0 * texel.r - 1.0), scale * (2.0 * texel.g - 1.0), 2.0 * texel.b - 1.0);
  vec3 mapped = m.x * t + m.y * b + m.z * n;
  float len = length(mapped);
  if (!(len > 0.0) || isinf(len) || isnan(len)) return n;
  vec3 result = mapped / len;
  return dot(result, ng) > 0.01 ? result : n;
}

// surfaceAt's shading normal (scene.cpp) at barycentrics b of a triangle (vertices v at p0, p1,
// p2; unit geometric normal `geometric`, the interpolated normal `interpolated`) of material
// record m whose normal texture is uploaded: the normal map where its uv set exists, in the
// frame of the mapped vertex uvs; `interpolated` elsewhere.
vec3 mappedNormalAt(uint m, uvec3 v, vec3 p0, vec3 p1, vec3 p2, vec2 b, vec3 geometric, vec3 interpolated) {
  uint normalMapping = m + kMaterialNormalMapping, set = detail[normalMapping];
  if (detail[m + 3u] == kNone || !hasUvSet(v.x, set)) return interpolated;
  vec3 texel = sampleTexture(detail[m + 3u], mappedUv(normalMapping, v, b));
  return normalMapped(interpolated, geometric, p0, p1, p2, applyMapping(normalMapping, vertexUv(v.x, set)),
                      applyMapping(normalMapping, vertexUv(v.y, set)), applyMapping(normalMapping, vertexUv(v.z, set)),
                      texel, detailFloat(m + 6u));
}
// The material record of triangle `triangle` (needs the triangle table: a uv is needed).
uint materialRecord(uint triangle) { return detail[2] + kMaterialWords * detail[detail[4] + triangle]; }
// emissionModulation (scene.h) at barycentrics b of a triangle (vertices v) of material record
// m whose emission texture is uploaded: the texel at full resolution, 1 without a texture.
vec3 emissionTexelAt(uint m, uvec3 v, vec2 b) {
  return detail[m + 1u] == kNone ? vec3(1.0) : sampleTexture(detail[m + 1u], mappedUv(m + kMaterialEmissionMapping, v, b));
}

// The metallic-roughness texel (materialModelAt: Texture::sample, full resolution) at
// barycentrics b of a triangle (vertices v) of material record m, which has the texture.
vec3 metallicRoughnessTexelAt(uint m, uvec3 v, vec2 b) {
  return sampleTexture(detail[m + kMaterialMetallicRoughness], mappedUv(m + kMaterialMetallicRoughnessMapping, v, b));
}

// What a lookup needs of its hit besides the position and the normals it is read around: the
// albedo modulation (albedoModulation: the albedo texture at the cone's mip level × the vertex
// colour) on a kFlagTexturedAlbedo chart, the emission texel (emissionModulation) on a
// kFlagTexturedEmission one, 1 elsewhere; the mapped normal (surfaceAt's shading normal, on the
// front's side) on a kFlagNormalMapped chart.
// On a kFlagMetallicRoughness chart also the metallic-roughness texel (materialModelAt's, at
// full resolution) and the material record (metallicRoughnessLobe reads both); 1 and kNone
// elsewhere.
struct SurfaceDetail { vec3 albedo, emission, normal, metallicRoughness; uint material; };
SurfaceDetail noSurfaceDetail(vec3 normal) { return SurfaceDetail(vec3(1.0), vec3(1.0), normal, vec3(1.0), kNone); }
// albedoPointAt, albedoModulation and surfaceAt's shading normal for a hit at barycentrics b
// of triangle `triangle` (vertices v at p0, p1, p2; unit geometric normal `geometric`, the
// interpolated normal `interpolated`) of a chart record with info `chartInfo` (kind, flags),
// seen along `direction` with a ray cone coneWidth wide there (0: full resolution).
SurfaceDetail surfaceDetailAt(uint triangle, uvec3 v, vec3 p0, vec3 p1, vec3 p2, vec2 b, uvec4 chartInfo, vec3 direction,
                              float coneWidth, vec3 geometric, vec3 interpolated) {
  uint flags = chartInfo.z;
  SurfaceDetail d = noSurfaceDetail(interpolated);
  if ((flags & (kFlagTexturedAlbedo | kFlagTexturedEmission | kFlagNormalMapped | kFlagMetallicRoughness)) == 0u) return d;
  uint m = materialRecord(triangle);
  bool glossyMapped = (flags & kFlagNormalMapped) != 0u && chartInfo.y == kGlossy;
  if ((flags & kFlagTexturedAlbedo) != 0u) {
    d.albedo = vertexColorAt(v, b);
    uint texture = detail[m];
    if (texture != kNone) {
      // A normal-mapped glossy chart reads its albedo at full resolution (lookupInputs).
      float lod = glossyMapped ? 0.0 : albedoTextureLod(texture, m + kMaterialAlbedoMapping, v, p0, p1, p2, direction, coneWidth);
      d.albedo = sampleTextureLod(texture, mappedUv(m + kMaterialAlbedoMapping, v, b), lod) * d.albedo;
    }
  }
  if ((flags & kFlagTexturedEmission) != 0u) d.emission = emissionTexelAt(m, v, b);
  if ((flags & kFlagMetallicRoughness) != 0u) {
    d.metallicRoughness = metallicRoughnessTexelAt(m, v, b);
    d.material = m;
  }
  if ((flags & kFlagNormalMapped) != 0u) d.normal = mappedNormalAt(m, v, p0, p1, p2, b, geometric, interpolated);
  return d;
}
// Whether triangle `triangle`'s material is alpha-masked at all (Material::isMasked).
bool maskedMaterial(uint triangle) {
  uint m = materialRecord(triangle);
  return detail[m + 2u] != kNone || detailFloat(m + 4u) < detailFloat(m + 5u) || (detail[m + 7u] & 1u) != 0u;
}
// GgxAlbedoTable::locate (bsdf.cpp) in the tables at detail[5] (ggxAlbedoTables): the
// roughness row r0 of α and the weight tr of r0 + 1, the μ segment i0 and the weight tm of i0 + 1.
void ggxLocate(float mu, float alpha, out int r0, out float tr, out int i0, out float tm) {
  const int muNodes = kGgxMuNodes, roughNodes = kGgxRoughNodes;
  uint muTable = detail[5];
  float rMin = sqrt(kGgxMinAlpha);
  float rPos = (sqrt(clamp(alpha, kGgxMinAlpha, 1.0)) - rMin) / (1.0 - rMin) * float(roughNodes - 1);
  r0 = clamp(int(rPos), 0, roughNodes - 2);
  tr = clamp(rPos - float(r0), 0.0, 1.0);
  mu = clamp(mu, 0.0, 1.0);
  i0 = clamp(int(sqrt(mu) * float(muNodes - 1)), 0, muNodes - 2);
  float mu0 = detailFloat(muTable + uint(i0)), mu1 = detailFloat(muTable + uint(i0) + 1u);
  tm = clamp((mu - mu0) / (mu1 - mu0), 0.0, 1.0);
}
// ggxLobeAlbedo (bsdf.cpp) from the tables at detail[5]: the directional albedo E at μ and the
// cosine-weighted mean Ē of the GGX lobe α with Schlick's Fresnel from f0 to f90 —
// GgxAlbedoTable::lookup, statement for statement.
void ggxLobeAlbedo(float alpha, vec3 f0, float f90, float mu, out vec3 at, out vec3 mean) {
  const int muNodes = kGgxMuNodes, roughNodes = kGgxRoughNodes;
  uint muTable = detail[5], e0 = muTable + uint(muNodes), e5 = e0 + uint(muNodes * roughNodes);
  uint mean0 = e5 + uint(muNodes * roughNodes), mean5 = mean0 + uint(roughNodes);
  int r0, i0;
  float tr, tm;
  ggxLocate(mu, alpha, r0, tr, i0, tm);
  uint row0 = uint(r0 * muNodes + i0), row1 = row0 + uint(muNodes);
  float e00 = detailFloat(e0 + row0) + tm * (detailFloat(e0 + row0 + 1u) - detailFloat(e0 + row0));
  float e01 = detailFloat(e0 + row1) + tm * (detailFloat(e0 + row1 + 1u) - detailFloat(e0 + row1));
  float e50 = detailFloat(e5 + row0) + tm * (detailFloat(e5 + row0 + 1u) - detailFloat(e5 + row0));
  float e51 = detailFloat(e5 + row1) + tm * (detailFloat(e5 + row1 + 1u) - detailFloat(e5 + row1));
  float le0 = e00 + tr * (e01 - e00), le5 = e50 + tr * (e51 - e50);
  float m0 = detailFloat(mean0 + uint(r0)), m5 = detailFloat(mean5 + uint(r0));
  float lm0 = m0 + tr * (detailFloat(mean0 + uint(r0) + 1u) - m0), lm5 = m5 + tr * (detailFloat(mean5 + uint(r0) + 1u) - m5);
  at = f0 * (le0 - le5) + vec3(f90 * le5);
  mean = f0 * (lm0 - lm5) + vec3(f90 * lm5);
}
// ggxDiffuseFactor (bsdf.cpp): k(μ) = max(0, 1 − E(μ)) / √(1 − Ē) per channel (0 where Ē ≈ 1)
// of the lobe α with Fresnel f0 → f90 that the diffuse part gives up (GgxLobeParameters'
// diffuseF0, diffuseF90); 0 for μ ≤ 0 (diffuseDirectionalFactor).
vec3 ggxDiffuseFactor(float alpha, vec3 f0, float f90, float cosTheta) {
  if (!(cosTheta > 0.0)) return vec3(0.0);
  vec3 at, mean;
  ggxLobeAlbedo(alpha, f0, f90, min(cosTheta, 1.0), at, mean);
  vec3 rest = vec3(1.0) - mean;
  return mix(vec3(0.0), max(vec3(0.0), vec3(1.0) - at) / sqrt(max(rest, vec3(1e-6))), greaterThan(rest, vec3(1e-6)));
}
// GgxAlbedoTable::upperAlbedo (bsdf.cpp): the larger of the two roughness rows' albedos at μ
// of the GGX lobe α with Schlick's Fresnel from f0 to f90 (the clear coat's E_c).
float ggxUpperAlbedo(float mu, float alpha, float f0, float f90) {
  const int muNodes = kGgxMuNodes, roughNodes = kGgxRoughNodes;
  uint e0 = detail[5] + uint(muNodes), e5 = e0 + uint(muNodes * roughNodes);
  int r0, i0;
  float tr, tm;
  ggxLocate(mu, alpha, r0, tr, i0, tm);
  float rows[2];
  for (int k = 0; k < 2; ++k) {
    uint row = uint((r0 + k) * muNodes + i0);
    float a0 = detailFloat(e0 + row) + tm * (detailFloat(e0 + row + 1u) - detailFloat(e0 + row));
    float a5 = detailFloat(e5 + row) + tm * (detailFloat(e5 + row + 1u) - detailFloat(e5 + row));
    rows[k] = f0 * (a0 - a5) + f90 * a5;
  }
  return max(rows[0], rows[1]);
}
// SheenAlbedoTable::lookup (bsdf.cpp) from the table at detail[6] (sheenAlbedoTables): the
// Charlie lobe's scaled albedo E_s at μ (x) and the scale (y) for roughness r.
vec2 sheenAlbedo(float mu, float r) {
  const int muNodes = kSheenMuNodes, roughNodes = kSheenRoughNodes;
  uint muTable = detail[6], e = muTable + uint(muNodes), scale = e + uint(muNodes * roughNodes);
  float rPos = (clamp(r, kSheenMinRoughness, 1.0) - kSheenMinRoughness) / (1.0 - kSheenMinRoughness) * float(roughNodes - 1);
  int r0 = clamp(int(rPos), 0, roughNodes - 2);
  float tr = clamp(rPos - float(r0), 0.0, 1.0);
  mu = clamp(mu, 0.0, 1.0);
  int i0 = clamp(int(sqrt(mu) * float(muNodes - 1)), 0, muNodes - 2);
  float mu0 = detailFloat(muTable + uint(i0)), mu1 = detailFloat(muTable + uint(i0) + 1u);
  float tm = clamp((mu - mu0) / (mu1 - mu0), 0.0, 1.0);
  uint row0 = e + uint(r0 * muNodes + i0), row1 = row0 + uint(muNodes);
  float at0 = detailFloat(row0) + tm * (detailFloat(row0 + 1u) - detailFloat(row0));
  float at1 = detailFloat(row1) + tm * (detailFloat(row1 + 1u) - detailFloat(row1));
  float s0 = detailFloat(scale + uint(r0));
  return vec2(at0 + tr * (at1 - at0), s0 + tr * (detailFloat(scale + uint(r0) + 1u) - s0));
}
// A glTF model's layers above its base (GgxLobeParameters: the coat's weight and α, the sheen's
// colour and roughness, the diffuse part's 1/√Ḡ); all 0 without.
struct PbrLayers { float clearcoat, clearcoatAlpha; vec3 sheenColor; float sheenRoughness; vec3 diffuseNorm; };
// The layers of the lobe record at word `lobe` (after its α and Fresnel ends).
PbrLayers pbrLayersAt(uint lobe) {
  return PbrLayers(detailFloat(lobe + 5u), detailFloat(lobe + 6u), detailRgb(lobe + 7u), detailFloat(lobe + 10u),
                   detailRgb(lobe + 11u));
}
bool hasLayers(PbrLayers l) { return l.clearcoat > 0.0 || max(l.sheenColor.r, max(l.sheenColor.g, l.sheenColor.b)) > 0.0; }
// pbrAlbedos' coat and sheen (bsdf.cpp): E_c and E_s at μ, 0 for an absent layer.
vec2 layerAlbedos(PbrLayers l, float mu) {
  float sheenWeight = max(0.0, max(l.sheenColor.r, max(l.sheenColor.g, l.sheenColor.b)));
  return vec2(l.clearcoat > 0.0 ? ggxUpperAlbedo(mu, l.clearcoatAlpha, kClearcoatF0, 1.0) : 0.0,
              sheenWeight > 0.0 ? sheenAlbedo(mu, l.sheenRoughness).x : 0.0);
}
// pbrDiffuseShape (bsdf.cpp): g(μ) = (1 − E_d)(1 − w_s E_s)(1 − w_c E_c) per channel, ≥ 0, with
// E_d the dielectric member's albedo at μ and (E_c, E_s) layerAlbedos'.
vec3 pbrDiffuseShape(PbrLayers l, vec3 dielectricAlbedo, vec2 coatSheen) {
  float sheenWeight = max(0.0, max(l.sheenColor.r, max(l.sheenColor.g, l.sheenColor.b)));
  float layers = max(0.0, 1.0 - sheenWeight * coatSheen.y) * max(0.0, 1.0 - l.clearcoat * coatSheen.x);
  return max(vec3(1.0) - dielectricAlbedo, vec3(0.0)) * layers;
}
// diffuseDirectionalFactor (bsdf.h) of a GGX-like model whose diffuse part gives up the lobe α
// with Fresnel f0 → f90, under layers l: ggxDiffuseFactor without layers, g(μ) · diffuseNorm
// with (GltfPbrBsdf: pbrDiffuseShape × pbrDiffuseNorm).
vec3 layeredDiffuseFactor(float alpha, vec3 f0, float f90, PbrLayers l, float cosTheta) {
  if (!hasLayers(l)) return ggxDiffuseFactor(alpha, f0, f90, cosTheta);
  if (!(cosTheta > 0.0)) return vec3(0.0);
  float mu = min(cosTheta, 1.0);
  vec3 at, mean;
  ggxLobeAlbedo(alpha, f0, f90, mu, at, mean);
  return pbrDiffuseShape(l, at, layerAlbedos(l, mu)) * l.diffuseNorm;
}
// diffuseDirectionalFactor (bsdf.h) of a material whose diffuse part's lobe record is at word
// `lobe` (the material record's kMaterialDiffuseLobe: α, diffuseF0, diffuseF90, the layers),
// kNone where k is 1 (Lambert, Blinn-Phong).
vec3 diffuseFactor(uint lobe, float cosTheta) {
  if (!(cosTheta > 0.0)) return vec3(0.0);
  if (lobe == kNone) return vec3(1.0);
  return layeredDiffuseFactor(detailFloat(lobe), detailRgb(lobe + 1u), detailFloat(lobe + 4u), pbrLayersAt(lobe), cosTheta);
}
// A GGX-like model as GgxLobeParameters (bsdf.h) describes it.
struct GgxLobe { vec3 diffuse; float alpha; vec3 f0; float f90; vec3 diffuseF0; float diffuseF90; };
// materialModelAt (scene.cpp) of material record m, which has a metallic-roughness texture, at
// a point whose albedo modulation is `modulation` and metallic-roughness texel `texel`:
// gltfMetallicRoughnessModel (lobe.cpp: GgxBsdf at metalness 0 or 1) or, for glTF's layered
// model and between, gltfPbrFromInputs with the record's dielectric Fresnel ends.
GgxLobe metallicRoughnessLobe(uint m, vec3 modulation, vec3 texel) {
  uint r = m + kMaterialMetallicRoughness;
  vec3 baseColor = detailRgb(r + 1u) * modulation;
  float metallic = clamp(detailFloat(r + 4u) * texel.b, 0.0, 1.0);
  float roughness = clamp(detailFloat(r + 5u) * texel.g, 0.0, 1.0);
  GgxLobe l;
  l.alpha = max(roughness * roughness, kGgxMinAlpha);  // ggxAlphaFromRoughness
  if (detail[r + 6u] == 0u && !(metallic > 0.0 && metallic < 1.0)) {
    l.f0 = mix(vec3(0.04), baseColor, metallic);
    l.diffuse = baseColor * (1.0 - metallic);
    l.f90 = 1.0;
    l.diffuseF0 = l.f0;
    l.diffuseF90 = 1.0;
    return l;
  }
  vec3 base = clamp(baseColor, 0.0, 1.0);
  float specular = detailFloat(r + 10u);
  l.diffuseF0 = detailRgb(r + 7u);
  l.diffuseF90 = specular;
  l.f0 = mix(l.diffuseF0, base, metallic);
  l.f90 = specular + (1.0 - specular) * metallic;
  l.diffuse = base * (1.0 - metallic);
  return l;
}
// coverageAt (scene.h): the alpha mask's coverage at barycentrics b of triangle `triangle`
// (vertices v); below the material's cutoff the surface is not there (masked() says so).
bool masked(uint triangle, uvec3 v, vec2 b) {
  uint m = materialRecord(triangle);
  float coverage = detailFloat(m + 4u), cutoff = detailFloat(m + 5u);
  uint x = detail[3] + kVertexWords * v.x;
  if ((detail[x + 7u] & 8u) != 0u) {  // the mesh's vertex alphas, interpolated
    float b1 = b.x, b2 = b.y, b0 = 1.0 - b1 - b2;
    coverage *= b0 * detailFloat(x + 8u) + b1 * detailFloat(detail[3] + kVertexWords * v.y + 8u) +
                b2 * detailFloat(detail[3] + kVertexWords * v.z + 8u);
  }
  uint texture = detail[m + 2u];
  if (texture != kNone) coverage *= sampleTexture(texture, mappedUv(m + kMaterialAlphaMapping, v, b)).r;
  return coverage < cutoff;
}
)glsl";
}

}  // namespace pl::gpu
