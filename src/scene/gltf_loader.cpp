// glTF 2.0 (.gltf and .glb) through tinygltf (the only file that includes it).
//
// What is read:
//  * The default scene's node hierarchy (every root node if the file has no scenes); a node's
//    local transform is its `matrix` or T·R·S. Positions go through the world matrix M,
//    normals through the inverse transpose of its upper 3×3, and a mirroring transform
//    (det < 0) swaps the winding so the front side stays the front side.
//  * Triangle primitives (mode 4) with POSITION, optional NORMAL, TEXCOORD_0, TEXCOORD_1
//    (kept only where a material reads it) and COLOR_0 (float, or normalised unsigned
//    byte/short; with KHR_mesh_quantization also signed and unnormalised integers), indexed or
//    not, KHR_draco_mesh_compression-, EXT_meshopt_compression- or KHR_meshopt_compression-
//    compressed or plain
//    (gltf_compression.h). Other modes: warning, skipped. A texture slot reading a TEXCOORD set
//    the primitive lacks is an error naming the mesh and the material.
//  * Metallic-roughness materials → bsdf.h gltfMetallicRoughnessModel: the spec's
//    mix(dielectric, metal, metallic) — a GgxBsdf where metallic is 0 or 1,
//        diffuse = baseColor · (1 − metallic)
//        f0      = mix(0.04, baseColor, metallic)        (0.04: dielectric F0 of the spec)
//        alpha   = max(roughness², 1e-3)                 (GGX α; the floor keeps the
//                                                         microfacet distribution finite)
//    and in between the GltfPbrBsdf of the same, whose diffuse gives up only the dielectric
//    member's lobe.
//    baseColor = baseColorFactor.rgb; baseColorTexture → albedo texture and COLOR_0 → vertex
//    colours, both multiplying `diffuse` (so they tint dielectrics; a metal's f0 keeps the
//    factor only), texels sRGB 8/16-bit decoded to linear; v is flipped to our bottom-left
//    convention (uv_ours = (u, 1 − v)) since glTF's (0,0) is the image's top-left. A
//    metallicRoughnessTexture makes the whole model per point instead (scene.h
//    MetallicRoughnessMap; Material::bsdf keeps its mean, meanMetallicRoughnessModel). Every
//    texture slot has its texCoord and KHR_texture_transform (mappingOf), every texture its
//    sampler (samplingOf). occlusionTexture is checked and ignored. A primitive without a
//    material gets the spec's default material (baseColor 1, metallic 1, roughness 1).
//  * KHR_materials_specular, KHR_materials_clearcoat, KHR_materials_sheen → GltfPbrBsdf
//    (bsdf.h; gltfPbrFromInputs maps the factors, KHR_materials_ior's ior included): the
//    factors, each in its range (an error naming the material otherwise); their textures
//    (specular A, specularColor RGB sRGB, clearcoat R, clearcoatRoughness G, sheenColor RGB
//    sRGB, sheenRoughness A), each with its texCoord and KHR_texture_transform, make the model
//    per hit (scene.h PbrLayerMaps); Material::bsdf keeps the factors × each texture's mean.
//    clearcoatNormalTexture is checked and ignored (warning). On a transmissive material the
//    layers are ignored (warning).
//  * Extensions: those of supportedExtensions; one required but not supported is refused,
//    naming it; those used but not supported are warned about once (checkExtensions).
//  * KHR_materials_transmission (transmissionFactor > 0) → DielectricBsdf: index from
//    KHR_materials_ior (default 1.5), transmittance = baseColor · transmissionFactor (a factor
//    below 1 is absorbed rather than mixed with a diffuse base: warning), α = roughness²
//    (smooth below 1e-3). Without KHR_materials_volume, or with thicknessFactor 0, the
//    surface is a thin sheet (smooth); with a thickness it is a closed volume whose
//    attenuationColor c and attenuationDistance d give the absorption σa = −ln(c)/d.
//    transmissionTexture, thicknessTexture and a baseColorTexture on it are ignored (warning).
//  * alphaMode MASK → alpha mask: coverage = baseColorFactor.a × the baseColorTexture's alpha
//    channel (1 when its image has none) × COLOR_0's alpha (Mesh::alphas; 1 for RGB colours),
//    cut at alphaCutoff (default 0.5). BLEND is read as
//    MASK with cutoff 0.5 (warning): ray casting has no partial coverage. OPAQUE (the
//    default) ignores alpha.
//  * normalTexture → tangent-space normal map (raw values, no sRGB decoding; +x = +u,
//    +y = up the image = +v after the flip), `scale` → normalScale (scene.h normalMapped).
//  * emissiveFactor × KHR_materials_emissive_strength.emissiveStrength → emitted radiance in
//    W·sr⁻¹·m⁻², times the emissiveTexture's sRGB-decoded texel at each point when there is
//    one (Material::emissionTexture); doubleSided materials emit from both sides.
//  * Perspective cameras: yfov (radians) and aspectRatio; the camera looks down its node's
//    −z with +y up. Named after the node, else the camera, else "camera<N>".
//  * KHR_lights_punctual point, spot and directional lights (shining down the node's −z).
//    glTF gives photometric intensities (point/spot: candela = lm/sr; directional: lux =
//    lm/m²). We convert them to radiometric units with the photometric efficacy of
//    683 lm/W (the definition of the candela at 555 nm), as Blender's glTF exporter does in
//    reverse: I [W/sr] = color · intensity[cd] / 683 and E [W/m²] = color · intensity[lx] / 683.
//    `range` is ignored (physically lights have no cut-off).
#include "core/error.h"
#include "core/file_io.h"
#include "scene/gltf_compression.h"
#include "scene/loaders.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <tuple>

namespace pl::detail {

namespace {

/// Photometric efficacy used to turn lumens into watts (see the header comment).
constexpr double kLumensPerWatt = 683.0;

constexpr const char* kDraco = "KHR_draco_mesh_compression";
constexpr const char* kMeshopt = "EXT_meshopt_compression";
/// The ratified successor of EXT_meshopt_compression: the same JSON, plus an attribute codec
/// version and a filter (gltf_compression.h MeshoptView).
constexpr const char* kMeshoptKhr = "KHR_meshopt_compression";
constexpr std::array<const char*, 2> kMeshoptExtensions = {kMeshopt, kMeshoptKhr};

/// The extensions this loader reads (docs/scenes.md): a file that requires another is refused.
/// KHR_draco_mesh_compression, EXT_ and KHR_meshopt_compression join them where the build has their
/// decoders (gltf_compression.h); a build without one refuses a file that requires it with the
/// decoder's "built without … support", and reads the uncompressed fallback of one that only
/// uses it.
const std::set<std::string>& supportedExtensions() {
  static const std::set<std::string> kSupported = [] {
    std::set<std::string> names = {"KHR_lights_punctual",       "KHR_materials_clearcoat",
                                   "KHR_materials_emissive_strength", "KHR_materials_ior",
                                   "KHR_materials_sheen",       "KHR_materials_specular",
                                   "KHR_materials_transmission", "KHR_materials_volume",
                                   "KHR_mesh_quantization",     "KHR_texture_transform"};
    if (dracoSupported()) names.insert(kDraco);
    if (meshoptSupported()) names.insert(kMeshoptExtensions.begin(), kMeshoptExtensions.end());
    return names;
  }();
  return kSupported;
}

/// Refuses a file that requires an extension we do not read (naming it), and warns once,
/// listing them, about extensions it uses that we ignore (what they add is then missing).
void checkExtensions(const std::string& path, const tinygltf::Model& model) {
  const std::set<std::string>& supported = supportedExtensions();
  for (const std::string& name : model.extensionsRequired)
    if (!supported.contains(name) && name != kDraco && name != kMeshopt && name != kMeshoptKhr)
      fail("{}: the file requires the glTF extension '{}', which plenoptic does not support (supported: {})", path,
           name, fmt::join(supported, ", "));
  std::vector<std::string> ignored;
  for (const std::string& name : model.extensionsUsed)
    if (!supported.contains(name) && std::find(ignored.begin(), ignored.end(), name) == ignored.end())
      ignored.push_back(name);
  if (!ignored.empty())
    spdlog::warn("{}: ignoring glTF extension(s) the file uses but does not require: {}", path, fmt::join(ignored, ", "));
}

struct GltfContext {
  const std::string& path;
  const tinygltf::Model& model;
  Scene& scene;
  /// Each glTF image's encoded bytes (PNG/JPEG as in its file, data URI or buffer view), kept by
  /// keepEncodedImage instead of tinygltf's decoding; decoded by us when a material uses it.
  const std::vector<std::vector<unsigned char>>& encodedImages;
  /// Scene texture per (glTF image, decoding, samplingKey of its sampler).
  std::map<std::tuple<int, ImageDecode, int>, int> textureOfImage;
  int defaultMaterial = -1;
  int unnamedCameras = 0;
  bool dracoRequired = false;  ///< the file lists KHR_draco_mesh_compression in extensionsRequired
};

/// Reads accessor `index` as `components` floats per element (float or normalised integers).
std::vector<float> readFloats(const GltfContext& ctx, int index, int components, const char* what) {
  const tinygltf::Model& model = ctx.model;
  // Unsigned integers read as normalised whatever the flag says, as before KHR_mesh_quantization
  // (the core spec allows them only normalised); files using the extension get the flag's word.
  const bool quantized = std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), "KHR_mesh_quantization") !=
                         model.extensionsUsed.end();
  if (index < 0 || size_t(index) >= model.accessors.size())
    fail("{}: {} accessor {} does not exist", ctx.path, what, index);
  const tinygltf::Accessor& accessor = model.accessors[size_t(index)];
  if (accessor.sparse.isSparse) fail("{}: sparse accessors ({}) are not supported", ctx.path, what);
  if (tinygltf::GetNumComponentsInType(uint32_t(accessor.type)) != components)
    fail("{}: {} accessor {} has {} components per element, expected {}", ctx.path, what, index,
         tinygltf::GetNumComponentsInType(uint32_t(accessor.type)), components);
  if (accessor.bufferView < 0 || size_t(accessor.bufferView) >= model.bufferViews.size())
    fail("{}: {} accessor {} has no buffer view", ctx.path, what, index);
  const tinygltf::BufferView& view = model.bufferViews[size_t(accessor.bufferView)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
    fail("{}: buffer view {} refers to a missing buffer", ctx.path, accessor.bufferView);
  const tinygltf::Buffer& buffer = model.buffers[size_t(view.buffer)];
  const int componentSize = tinygltf::GetComponentSizeInBytes(uint32_t(accessor.componentType));
  const int stride = accessor.ByteStride(view);
  if (componentSize <= 0 || stride <= 0) fail("{}: {} accessor {} has an invalid layout", ctx.path, what, index);
  // Every element takes at least one byte; this also keeps the products below from overflowing.
  if (accessor.count > buffer.data.size() || view.byteOffset > buffer.data.size() ||
      accessor.byteOffset > buffer.data.size())
    fail("{}: {} accessor {} reads past the end of its buffer", ctx.path, what, index);
  const size_t start = view.byteOffset + accessor.byteOffset;
  const size_t elementBytes = size_t(componentSize) * size_t(components);
  if (accessor.count > 0 &&
      (start + size_t(stride) * (accessor.count - 1) + elementBytes > buffer.data.size() ||
       accessor.byteOffset + size_t(stride) * (accessor.count - 1) + elementBytes > view.byteLength))
    fail("{}: {} accessor {} reads past the end of its buffer", ctx.path, what, index);

  std::vector<float> values(accessor.count * size_t(components));
  for (size_t i = 0; i < accessor.count; ++i) {
    const unsigned char* element = buffer.data.data() + start + size_t(stride) * i;
    for (int c = 0; c < components; ++c) {
      const unsigned char* p = element + size_t(c) * size_t(componentSize);
      float value;
      // Integers: normalised ones (the core spec's TEXCOORD/COLOR types, and
      // KHR_mesh_quantization's) as the spec maps them, c/max for unsigned and max(c/max, −1)
      // for signed; others (KHR_mesh_quantization) as their value.
      switch (accessor.componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: std::memcpy(&value, p, 4); break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: value = accessor.normalized || !quantized ? float(*p) / 255.0f : float(*p); break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          uint16_t v;
          std::memcpy(&v, p, 2);
          value = accessor.normalized || !quantized ? float(v) / 65535.0f : float(v);
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
          int8_t v;
          std::memcpy(&v, p, 1);
          value = accessor.normalized ? std::max(float(v) / 127.0f, -1.0f) : float(v);
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
          int16_t v;
          std::memcpy(&v, p, 2);
          value = accessor.normalized ? std::max(float(v) / 32767.0f, -1.0f) : float(v);
          break;
        }
        default: fail("{}: {} accessor {} has an unsupported component type {}", ctx.path, what, index,
                      accessor.componentType);
      }
      values[i * size_t(components) + size_t(c)] = value;
    }
  }
  return values;
}

std::vector<uint32_t> readIndices(const GltfContext& ctx, int index) {
  const tinygltf::Model& model = ctx.model;
  if (index < 0 || size_t(index) >= model.accessors.size()) fail("{}: index accessor {} does not exist", ctx.path, index);
  const tinygltf::Accessor& accessor = model.accessors[size_t(index)];
  if (accessor.type != TINYGLTF_TYPE_SCALAR) fail("{}: index accessor {} is not scalar", ctx.path, index);
  if (accessor.bufferView < 0 || size_t(accessor.bufferView) >= model.bufferViews.size())
    fail("{}: index accessor {} has no buffer view", ctx.path, index);
  const tinygltf::BufferView& view = model.bufferViews[size_t(accessor.bufferView)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
    fail("{}: buffer view {} refers to a missing buffer", ctx.path, accessor.bufferView);
  const tinygltf::Buffer& buffer = model.buffers[size_t(view.buffer)];
  const int size = tinygltf::GetComponentSizeInBytes(uint32_t(accessor.componentType));
  const int stride = accessor.ByteStride(view);
  if (size <= 0 || stride <= 0) fail("{}: index accessor {} has an invalid layout", ctx.path, index);
  if (accessor.count > buffer.data.size() || view.byteOffset > buffer.data.size() ||
      accessor.byteOffset > buffer.data.size())
    fail("{}: index accessor {} reads past the end of its buffer", ctx.path, index);
  const size_t start = view.byteOffset + accessor.byteOffset;
  if (accessor.count > 0 && start + size_t(stride) * (accessor.count - 1) + size_t(size) > buffer.data.size())
    fail("{}: index accessor {} reads past the end of its buffer", ctx.path, index);
  std::vector<uint32_t> indices(accessor.count);
  for (size_t i = 0; i < accessor.count; ++i) {
    const unsigned char* p = buffer.data.data() + start + size_t(stride) * i;
    switch (accessor.componentType) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: indices[i] = *p; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        indices[i] = v;
        break;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: std::memcpy(&indices[i], p, 4); break;
      default: fail("{}: index accessor {} has an unsupported component type {}", ctx.path, index, accessor.componentType);
    }
  }
  return indices;
}

Mat4 localTransform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    Mat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = float(node.matrix[size_t(c * 4 + r)]);  // column-major, like glm
    return m;
  }
  Mat4 m(1.0f);
  if (node.translation.size() == 3)
    m = glm::translate(m, Vec3(float(node.translation[0]), float(node.translation[1]), float(node.translation[2])));
  if (node.rotation.size() == 4) {
    const glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]),
                      float(node.rotation[2]));  // glTF stores (x, y, z, w)
    m = m * glm::mat4_cast(glm::normalize(q));
  }
  if (node.scale.size() == 3) m = glm::scale(m, Vec3(float(node.scale[0]), float(node.scale[1]), float(node.scale[2])));
  return m;
}

/// The encoded bytes of the glTF image behind texture `textureIndex` (its file, data URI or
/// buffer view, as keepEncodedImage kept them), checked: present. `source` is the glTF image
/// index, `label` names it in messages.
const std::vector<unsigned char>& textureImageBytes(GltfContext& ctx, int textureIndex, int& source,
                                                   std::string& label) {
  const tinygltf::Model& model = ctx.model;
  if (textureIndex < 0 || size_t(textureIndex) >= model.textures.size())
    fail("{}: texture {} does not exist", ctx.path, textureIndex);
  source = model.textures[size_t(textureIndex)].source;
  if (source < 0 || size_t(source) >= model.images.size())
    fail("{}: texture {} has no image source", ctx.path, textureIndex);
  const tinygltf::Image& gltfImage = model.images[size_t(source)];
  label = gltfImage.uri.empty() ? fmt::format("image {}", source) : gltfImage.uri;
  const std::vector<unsigned char>* bytes =
      size_t(source) < ctx.encodedImages.size() ? &ctx.encodedImages[size_t(source)] : nullptr;
  if (!bytes || bytes->empty()) {
    if (!gltfImage.uri.empty() && gltfImage.uri.rfind("data:", 0) != 0) {
      const std::filesystem::path file = std::filesystem::path(ctx.path).parent_path() / gltfImage.uri;
      if (const std::string problem = inputFileProblem(file); !problem.empty())
        fail("{}: texture file '{}' {}", ctx.path, file.string(), problem);
    }
    fail("{}: texture image '{}' could not be read", ctx.path, label);
  }
  return *bytes;
}

/// Whether the image of texture `textureIndex` has an alpha channel (grey + alpha or RGBA)
/// with a value below opaque: an all-opaque alpha channel is treated as none (it could cut
/// nothing).
bool textureHasAlpha(GltfContext& ctx, int textureIndex) {
  int source = 0;
  std::string label;
  const std::vector<unsigned char>& bytes = textureImageBytes(ctx, textureIndex, source, label);
  if (!ldrImageHasAlphaChannel(bytes)) return false;
  const Image alpha = decodeLdrImage(bytes, fmt::format("{}: texture image '{}'", ctx.path, label), ImageDecode::Coverage);
  return std::any_of(alpha.pixels.begin(), alpha.pixels.end(), [](const Rgb& a) { return a.r < 1.0f; });
}

/// One sampler wrap mode (glTF's GL enum values) as ours.
TextureWrap wrapMode(const GltfContext& ctx, int samplerIndex, int mode, const char* axis) {
  switch (mode) {
    case TINYGLTF_TEXTURE_WRAP_REPEAT: return TextureWrap::Repeat;
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return TextureWrap::ClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return TextureWrap::MirroredRepeat;
    default:
      fail("{}: sampler {}: {} {} is not a wrap mode (10497 REPEAT, 33071 CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT)",
           ctx.path, samplerIndex, axis, mode);
  }
}

/// The sampling of glTF texture `textureIndex` (its sampler; the defaults without one): wrapS
/// → u, wrapT → v (the v flip maps each mode onto itself), magFilter NEAREST → nearest,
/// minFilter NEAREST or LINEAR → no mip levels (texture.h TextureSampling).
TextureSampling samplingOf(const GltfContext& ctx, int textureIndex) {
  TextureSampling sampling;
  const int samplerIndex = ctx.model.textures[size_t(textureIndex)].sampler;
  if (samplerIndex < 0) return sampling;
  if (size_t(samplerIndex) >= ctx.model.samplers.size())
    fail("{}: texture {} uses sampler {} but the file has {}", ctx.path, textureIndex, samplerIndex,
         ctx.model.samplers.size());
  const tinygltf::Sampler& sampler = ctx.model.samplers[size_t(samplerIndex)];
  sampling.wrapU = wrapMode(ctx, samplerIndex, sampler.wrapS, "wrapS");
  sampling.wrapV = wrapMode(ctx, samplerIndex, sampler.wrapT, "wrapT");
  sampling.nearest = sampler.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
  sampling.mipmaps = !(sampler.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST || sampler.minFilter == TINYGLTF_TEXTURE_FILTER_LINEAR);
  return sampling;
}

/// The scene texture for glTF texture `textureIndex` decoded as `decode` (image.h): sRGB
/// colour for baseColorTexture (glTF spec 3.9.2), raw values for normalTexture and
/// metallicRoughnessTexture, the alpha channel for alpha masks, sampled as its sampler says.
/// One scene texture per (image, decoding, sampling); it keeps the image's encoded bytes for
/// the .plf.
int textureFor(GltfContext& ctx, int textureIndex, ImageDecode decode = ImageDecode::Colour) {
  int source = 0;
  std::string label;
  const std::vector<unsigned char>& bytes = textureImageBytes(ctx, textureIndex, source, label);
  const TextureSampling sampling = samplingOf(ctx, textureIndex);
  const int samplingKey = int(sampling.wrapU) | int(sampling.wrapV) << 2 | int(sampling.nearest) << 4 |
                          int(sampling.mipmaps) << 5;
  if (auto it = ctx.textureOfImage.find({source, decode, samplingKey}); it != ctx.textureOfImage.end()) return it->second;
  Texture texture = textureFromEncoded(label, bytes, fmt::format("{}: texture image '{}'", ctx.path, label), decode);
  texture.sampling = sampling;
  const int ours = int(ctx.scene.textures.size());
  ctx.scene.textures.push_back(std::move(texture));
  ctx.textureOfImage[{source, decode, samplingKey}] = ours;
  return ours;
}

/// Fails unless texture `index` of material slot `slot` exists, naming the material.
void checkTextureIndex(const GltfContext& ctx, const char* slot, int index, const std::string& material) {
  if (index < 0 || size_t(index) >= ctx.model.textures.size())
    fail("{}: material '{}': {} refers to texture {} but the file has {}", ctx.path, material, slot, index,
         ctx.model.textures.size());
}

/// A texture slot of a material as the file gives it: the texture index, its texCoord and
/// extensions (KHR_texture_transform).
struct TextureSlotRef {
  const char* slot;  ///< "baseColorTexture", … (for messages)
  int index;
  int texCoord;
  const tinygltf::ExtensionMap& extensions;
};

/// The slot's TextureMapping, checked: the texture exists, the uv set is TEXCOORD_0 or
/// TEXCOORD_1 (after KHR_texture_transform's own texCoord, which overrides the slot's).
///
/// KHR_texture_transform gives, in glTF's uv convention ((0,0) = the image's top left),
///   uv' = T(offset) · R(rotation) · S(scale) · uv,   R = [cos r, sin r; −sin r, cos r]
/// (rows; the extension's matrix, a rotation by −r). Ours has v flipped, uv_ours = F(uv) with
/// F(u, v) = (u, 1 − v) = D·uv + e (D = diag(1, −1), e = (0, 1)), so in our convention the
/// mapping is F ∘ (A·, + b) ∘ F with A = R·S, b = offset:
///   linear = D·A·D,  offset = D·(A·e + b) + e.
TextureMapping mappingOf(const GltfContext& ctx, const TextureSlotRef& slot, const std::string& material) {
  checkTextureIndex(ctx, slot.slot, slot.index, material);
  TextureMapping mapping;
  int texCoord = slot.texCoord;
  if (auto it = slot.extensions.find("KHR_texture_transform"); it != slot.extensions.end()) {
    const tinygltf::Value& v = it->second;
    auto pair = [&](const char* key, Vec2 fallback) {
      if (!v.Has(key)) return fallback;
      const tinygltf::Value& array = v.Get(key);
      if (!array.IsArray() || array.ArrayLen() != 2 || !array.Get(0).IsNumber() || !array.Get(1).IsNumber())
        fail("{}: material '{}': {} KHR_texture_transform.{} must be two numbers", ctx.path, material, slot.slot, key);
      return Vec2(float(array.Get(0).GetNumberAsDouble()), float(array.Get(1).GetNumberAsDouble()));
    };
    const Vec2 offset = pair("offset", Vec2(0.0f)), scale = pair("scale", Vec2(1.0f));
    float rotation = 0.0f;
    if (v.Has("rotation")) {
      if (!v.Get("rotation").IsNumber())
        fail("{}: material '{}': {} KHR_texture_transform.rotation must be a number", ctx.path, material, slot.slot);
      rotation = float(v.Get("rotation").GetNumberAsDouble());
    }
    if (v.Has("texCoord")) {
      if (!v.Get("texCoord").IsInt())
        fail("{}: material '{}': {} KHR_texture_transform.texCoord must be an integer", ctx.path, material, slot.slot);
      texCoord = v.Get("texCoord").GetNumberAsInt();
    }
    const float c = std::cos(rotation), s = std::sin(rotation);
    const Mat2 a(Vec2(c * scale.x, -s * scale.x), Vec2(s * scale.y, c * scale.y));  // columns of R·S
    const Mat2 d(Vec2(1.0f, 0.0f), Vec2(0.0f, -1.0f));
    const Vec2 e(0.0f, 1.0f);
    mapping.linear = d * a * d;
    mapping.offset = d * (a * e + offset) + e;
    if (!std::isfinite(mapping.offset.x) || !std::isfinite(mapping.offset.y) || !isFinite(Vec3(mapping.linear[0], 0.0f)) ||
        !isFinite(Vec3(mapping.linear[1], 0.0f)))
      fail("{}: material '{}': {} KHR_texture_transform is not finite", ctx.path, material, slot.slot);
  }
  if (texCoord < 0 || texCoord > 1)
    fail("{}: material '{}': {} reads TEXCOORD_{}; only TEXCOORD_0 and TEXCOORD_1 are supported", ctx.path, material,
         slot.slot, texCoord);
  mapping.uvSet = uint8_t(texCoord);
  return mapping;
}

TextureSlotRef slotRef(const char* slot, const tinygltf::TextureInfo& info) {
  return {slot, info.index, info.texCoord, info.extensions};
}

/// alphaMode MASK / BLEND → an alpha mask; normalTexture → a normal map (see the header).
void applyAlphaAndNormals(GltfContext& ctx, const tinygltf::Material& gltf, Material& material) {
  const auto& pbr = gltf.pbrMetallicRoughness;
  if (gltf.alphaMode == "MASK" || gltf.alphaMode == "BLEND") {
    if (gltf.alphaMode == "BLEND")
      spdlog::warn("{}: material '{}': alphaMode BLEND is rendered as MASK with cutoff 0.5 (no partial coverage)",
                   ctx.path, material.name);
    material.alphaCutoff = gltf.alphaMode == "MASK" ? float(gltf.alphaCutoff) : 0.5f;
    if (!(material.alphaCutoff >= 0.0f && material.alphaCutoff <= 1.0f))
      fail("{}: material '{}': alphaCutoff {} must be in [0, 1]", ctx.path, material.name, gltf.alphaCutoff);
    material.alphaFactor = pbr.baseColorFactor.size() >= 4 ? std::clamp(float(pbr.baseColorFactor[3]), 0.0f, 1.0f) : 1.0f;
    if (pbr.baseColorTexture.index >= 0 && textureHasAlpha(ctx, pbr.baseColorTexture.index)) {
      material.alphaMapping = mappingOf(ctx, slotRef("baseColorTexture", pbr.baseColorTexture), material.name);
      material.alphaTexture = textureFor(ctx, pbr.baseColorTexture.index, ImageDecode::Coverage);
    }
  } else if (!gltf.alphaMode.empty() && gltf.alphaMode != "OPAQUE") {
    fail("{}: material '{}': unknown alphaMode '{}' (OPAQUE, MASK or BLEND)", ctx.path, material.name, gltf.alphaMode);
  }
  if (gltf.normalTexture.index >= 0) {
    const tinygltf::NormalTextureInfo& info = gltf.normalTexture;
    material.normalMapping = mappingOf(ctx, {"normalTexture", info.index, info.texCoord, info.extensions}, material.name);
    material.normalTexture = textureFor(ctx, gltf.normalTexture.index, ImageDecode::Data);
    material.normalScale = float(gltf.normalTexture.scale);
  }
}

/// A number of an extension object, or `fallback` when absent.
float extensionNumber(const tinygltf::Value& extension, const char* key, float fallback) {
  return extension.Has(key) && extension.Get(key).IsNumber() ? float(extension.Get(key).GetNumberAsDouble()) : fallback;
}

/// KHR_materials_transmission (+ _ior, _volume) → DielectricBsdf (see the header comment).
void applyTransmission(GltfContext& ctx, const tinygltf::Material& gltf, Material& material, const Rgb& baseColor,
                       float roughness) {
  const auto transmission = gltf.extensions.find("KHR_materials_transmission");
  if (transmission == gltf.extensions.end()) return;
  const float factor = std::clamp(extensionNumber(transmission->second, "transmissionFactor", 0.0f), 0.0f, 1.0f);
  if (!(factor > 0.0f)) return;
  if (transmission->second.Has("transmissionTexture"))
    spdlog::warn("{}: material '{}': transmissionTexture is not supported; transmissionFactor used alone", ctx.path,
                 material.name);
  if (factor < 1.0f)
    spdlog::warn("{}: material '{}': transmissionFactor {} < 1: the rest is absorbed, not diffusely reflected",
                 ctx.path, material.name, factor);
  DielectricBsdf glass;
  if (auto ior = gltf.extensions.find("KHR_materials_ior"); ior != gltf.extensions.end())
    glass.ior = extensionNumber(ior->second, "ior", 1.5f);
  if (!(glass.ior > 1.0f && std::isfinite(glass.ior)))
    fail("{}: material '{}': KHR_materials_ior.ior {} must be a finite number > 1", ctx.path, material.name, glass.ior);
  glass.transmittance = baseColor * factor;
  glass.alpha = dielectricAlphaFromRoughness(roughness);
  glass.thin = true;
  if (auto volume = gltf.extensions.find("KHR_materials_volume"); volume != gltf.extensions.end()) {
    const tinygltf::Value& v = volume->second;
    glass.thin = !(extensionNumber(v, "thicknessFactor", 0.0f) > 0.0f);
    const float distance = extensionNumber(v, "attenuationDistance", kInfinity);
    Rgb colour(1.0f);
    if (v.Has("attenuationColor") && v.Get("attenuationColor").IsArray() && v.Get("attenuationColor").ArrayLen() >= 3)
      for (int c = 0; c < 3; ++c) colour[c] = float(v.Get("attenuationColor").Get(c).GetNumberAsDouble());
    if (!(distance > 0.0f) || !isFinite(colour) || glm::any(glm::lessThanEqual(colour, Rgb(0.0f))) ||
        maxComponent(colour) > 1.0f)
      fail("{}: material '{}': KHR_materials_volume needs attenuationDistance > 0 and attenuationColor in (0, 1]",
           ctx.path, material.name);
    // Beer–Lambert: after `distance` the colour is left, exp(−σa d) = c.
    if (!glass.thin && std::isfinite(distance))
      for (int c = 0; c < 3; ++c) glass.absorption[c] = -std::log(colour[c]) / distance;
  }
  if (glass.thin) glass.alpha = 0.0f;  // thin sheets are smooth (bsdf.h)
  if (material.albedoTexture >= 0) {
    spdlog::warn("{}: material '{}': baseColorTexture is ignored on a transmissive material", ctx.path, material.name);
    material.albedoTexture = -1;
    material.albedoMapping = {};
  }
  if (material.metallicRoughness.texture >= 0) {
    spdlog::warn("{}: material '{}': metallicRoughnessTexture is ignored on a transmissive material", ctx.path,
                 material.name);
    material.metallicRoughness = {};
  }
  if (std::holds_alternative<GltfPbrBsdf>(material.bsdf)) {
    spdlog::warn("{}: material '{}': KHR_materials_specular, _clearcoat and _sheen are ignored on a transmissive material",
                 ctx.path, material.name);
    material.layers = {};
  }
  material.bsdf = glass;
}

/// The mean texel of a decoded texture (black for an empty one).
Rgb meanTexel(const Image& image) {
  glm::dvec3 sum(0.0);
  for (const Rgb& p : image.pixels) sum += glm::dvec3(p);
  return image.pixels.empty() ? Rgb(0.0f) : Rgb(sum / double(image.pixels.size()));
}

/// KHR_materials_specular, _clearcoat and _sheen → GltfPbrBsdf (see the header comment).
void applyLayers(GltfContext& ctx, const tinygltf::Material& gltf, Material& material, const Rgb& baseColor,
                 float metallic, float roughness) {
  auto extension = [&](const char* name) -> const tinygltf::Value* {
    const auto it = gltf.extensions.find(name);
    return it == gltf.extensions.end() ? nullptr : &it->second;
  };
  const tinygltf::Value* specular = extension("KHR_materials_specular");
  const tinygltf::Value* coat = extension("KHR_materials_clearcoat");
  const tinygltf::Value* sheen = extension("KHR_materials_sheen");
  if (!specular && !coat && !sheen) return;
  auto factor = [&](const tinygltf::Value* ext, const char* key, float fallback) {
    if (!ext || !ext->Has(key)) return fallback;
    const tinygltf::Value& v = ext->Get(key);
    const float x = v.IsNumber() ? float(v.GetNumberAsDouble()) : -1.0f;
    if (!(x >= 0.0f && x <= 1.0f)) fail("{}: material '{}': {} must be a number in [0, 1]", ctx.path, material.name, key);
    return x;
  };
  auto colour = [&](const tinygltf::Value* ext, const char* key, Rgb fallback, float maximum) {
    if (!ext || !ext->Has(key)) return fallback;
    const tinygltf::Value& v = ext->Get(key);
    Rgb c(-1.0f);
    if (v.IsArray() && v.ArrayLen() == 3)
      for (int i = 0; i < 3; ++i)
        if (v.Get(i).IsNumber()) c[i] = float(v.Get(i).GetNumberAsDouble());
    if (!isFinite(c) || glm::any(glm::lessThan(c, Rgb(0.0f))) || maxComponent(c) > maximum)
      fail("{}: material '{}': {} must be three numbers in [0, {}]", ctx.path, material.name, key, maximum);
    return c;
  };
  PbrLayerMaps& layers = material.layers;
  layers.layered = true;
  GltfPbrInputs& in = layers.factors;
  in.baseColor = baseColor;
  in.metallic = metallic;
  in.roughness = roughness;
  if (const tinygltf::Value* ior = extension("KHR_materials_ior")) in.ior = extensionNumber(*ior, "ior", 1.5f);
  if (!(in.ior >= 1.0f && std::isfinite(in.ior)))
    fail("{}: material '{}': KHR_materials_ior.ior {} must be a finite number >= 1", ctx.path, material.name, in.ior);
  in.specular = factor(specular, "specularFactor", 1.0f);
  in.specularColor = colour(specular, "specularColorFactor", Rgb(1.0f), std::numeric_limits<float>::max());
  in.clearcoat = factor(coat, "clearcoatFactor", 0.0f);
  in.clearcoatRoughness = factor(coat, "clearcoatRoughnessFactor", 0.0f);
  in.sheenColor = colour(sheen, "sheenColorFactor", Rgb(0.0f), 1.0f);
  in.sheenRoughness = factor(sheen, "sheenRoughnessFactor", 0.0f);

  // The textures: each slot's channel, its decoding, and its mean for Material::bsdf.
  GltfPbrInputs mean = in;
  struct SlotSpec {
    PbrLayerMaps::Slot slot;
    const tinygltf::Value* extension;
    ImageDecode decode;
  };
  const SlotSpec slots[] = {{PbrLayerMaps::kSpecular, specular, ImageDecode::Coverage},
                            {PbrLayerMaps::kSpecularColor, specular, ImageDecode::Colour},
                            {PbrLayerMaps::kClearcoat, coat, ImageDecode::Data},
                            {PbrLayerMaps::kClearcoatRoughness, coat, ImageDecode::Data},
                            {PbrLayerMaps::kSheenColor, sheen, ImageDecode::Colour},
                            {PbrLayerMaps::kSheenRoughness, sheen, ImageDecode::Coverage}};
  for (const SlotSpec& s : slots) {
    const char* name = PbrLayerMaps::kSlotNames[s.slot];
    if (!s.extension || !s.extension->Has(name)) continue;
    const tinygltf::Value& info = s.extension->Get(name);
    if (!info.IsObject() || !info.Has("index") || !info.Get("index").IsInt())
      fail("{}: material '{}': {} must be an object with an integer \"index\"", ctx.path, material.name, name);
    const int index = info.Get("index").GetNumberAsInt();
    const int texCoord = info.Has("texCoord") && info.Get("texCoord").IsInt() ? info.Get("texCoord").GetNumberAsInt() : 0;
    tinygltf::ExtensionMap slotExtensions;
    if (info.Has("extensions") && info.Get("extensions").IsObject())
      for (const std::string& key : info.Get("extensions").Keys()) slotExtensions[key] = info.Get("extensions").Get(key);
    const TextureMapping mapping = mappingOf(ctx, {name, index, texCoord, slotExtensions}, material.name);
    // An alpha slot whose image has no alpha below 1 is 1 everywhere: the factor alone.
    if (s.decode == ImageDecode::Coverage && !textureHasAlpha(ctx, index)) continue;
    const int texture = textureFor(ctx, index, s.decode);
    layers.texture[s.slot] = texture;
    layers.mapping[s.slot] = mapping;
    const Rgb m = meanTexel(ctx.scene.textures[size_t(texture)].image);
    layers.meanTexel[s.slot] = m;
    switch (s.slot) {
      case PbrLayerMaps::kSpecular: mean.specular *= m.r; break;
      case PbrLayerMaps::kSpecularColor: mean.specularColor *= m; break;
      case PbrLayerMaps::kClearcoat: mean.clearcoat *= m.r; break;
      case PbrLayerMaps::kClearcoatRoughness: mean.clearcoatRoughness *= m.g; break;
      case PbrLayerMaps::kSheenColor: mean.sheenColor *= m; break;
      default: mean.sheenRoughness *= m.r; break;
    }
  }
  if (coat && coat->Has("clearcoatNormalTexture")) {
    const tinygltf::Value& info = coat->Get("clearcoatNormalTexture");
    checkTextureIndex(ctx, "clearcoatNormalTexture",
                      info.Has("index") && info.Get("index").IsInt() ? info.Get("index").GetNumberAsInt() : -1,
                      material.name);
    spdlog::warn("{}: material '{}': clearcoatNormalTexture is not supported; the coat uses the base's normal",
                 ctx.path, material.name);
  }
  if (material.metallicRoughness.texture >= 0) {
    const Rgb m = meanTexel(ctx.scene.textures[size_t(material.metallicRoughness.texture)].image);
    mean.metallic *= m.b;
    mean.roughness *= m.g;
  }
  material.bsdf = gltfPbrFromInputs(mean);
}

/// The one model a material with a metallic-roughness texture keeps (Material::bsdf) for what
/// takes one model per material — the bake's glossy lobe and chart classification, the
/// renderers' punctual highlights: gltfMetallicRoughnessModel(baseColor·ā, m̄) with its α
/// replaced by ᾱ, the means over the texels of m = metallic·B and α = ggxAlpha(roughness·G)
/// (ā the mean of the base colour texture, `albedo`, null without one: 1). Its F0 = mix(0.04,
/// baseColor·ā, m̄) and diffuse baseColor·ā·(1 − m̄) are the texels' means too (both linear in
/// m). The path tracer and the per-point diffuse albedo read the texels themselves
/// (materialModelAt).
Bsdf meanMetallicRoughnessModel(const Image& texels, const MetallicRoughnessMap& mr, const Image* albedo) {
  const Rgb base = albedo && !albedo->pixels.empty() ? mr.baseColor * meanTexel(*albedo) : mr.baseColor;
  double alpha = 0.0, metalness = 0.0;
  for (const Rgb& t : texels.pixels) {
    alpha += ggxAlphaFromRoughness(mr.roughness * t.g);
    metalness += std::clamp(mr.metallic * t.b, 0.0f, 1.0f);
  }
  const double n = double(std::max<size_t>(1, texels.pixels.size()));
  Bsdf mean = gltfMetallicRoughnessModel(base, float(metalness / n), 1.0f);
  std::visit([&](auto& b) {
    if constexpr (requires { b.alpha; }) b.alpha = float(alpha / n);
  }, mean);
  return mean;
}

Material convertMaterial(GltfContext& ctx, const tinygltf::Material& gltf, int index) {
  const auto& pbr = gltf.pbrMetallicRoughness;
  Rgb baseColor(1.0f);
  if (pbr.baseColorFactor.size() >= 3)
    baseColor = glm::clamp(
        Rgb(float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]), float(pbr.baseColorFactor[2])), 0.0f, 1.0f);
  const float metallic = std::clamp(float(pbr.metallicFactor), 0.0f, 1.0f);
  const float roughness = std::clamp(float(pbr.roughnessFactor), 0.0f, 1.0f);

  Material material;
  material.name = gltf.name.empty() ? fmt::format("material{}", index) : gltf.name;
  material.bsdf = gltfMetallicRoughnessModel(baseColor, metallic, roughness);
  if (pbr.baseColorTexture.index >= 0) {
    material.albedoMapping = mappingOf(ctx, slotRef("baseColorTexture", pbr.baseColorTexture), material.name);
    material.albedoTexture = textureFor(ctx, pbr.baseColorTexture.index);
  }
  if (pbr.metallicRoughnessTexture.index >= 0) {
    // B = metalness, G = roughness, linear (spec 3.9.2), times the factors at each point.
    MetallicRoughnessMap& mr = material.metallicRoughness;
    mr.mapping = mappingOf(ctx, slotRef("metallicRoughnessTexture", pbr.metallicRoughnessTexture), material.name);
    mr.texture = textureFor(ctx, pbr.metallicRoughnessTexture.index, ImageDecode::Data);
    mr.baseColor = baseColor;
    mr.metallic = metallic;
    mr.roughness = roughness;
    material.bsdf = meanMetallicRoughnessModel(
        ctx.scene.textures[size_t(mr.texture)].image, mr,
        material.albedoTexture >= 0 ? &ctx.scene.textures[size_t(material.albedoTexture)].image : nullptr);
  }
  // Occlusion is read (its texture must exist) and not used: the bake and the path tracer
  // compute occlusion themselves (docs/scenes.md).
  if (gltf.occlusionTexture.index >= 0)
    checkTextureIndex(ctx, "occlusionTexture", gltf.occlusionTexture.index, material.name);
  applyLayers(ctx, gltf, material, baseColor, metallic, roughness);
  applyTransmission(ctx, gltf, material, baseColor, roughness);
  applyAlphaAndNormals(ctx, gltf, material);
  if (gltf.emissiveFactor.size() >= 3) {
    float strength = 1.0f;
    if (auto it = gltf.extensions.find("KHR_materials_emissive_strength"); it != gltf.extensions.end()) {
      if (it->second.Has("emissiveStrength")) strength = float(it->second.Get("emissiveStrength").GetNumberAsDouble());
    }
    material.emission = strength * Rgb(float(gltf.emissiveFactor[0]), float(gltf.emissiveFactor[1]),
                                       float(gltf.emissiveFactor[2]));
  }
  if (gltf.emissiveTexture.index >= 0) {
    // sRGB colour (spec 3.9.2), multiplying the factor × strength at each point (scene.h
    // emissionModulation). Read only where it can matter: a black factor emits nothing.
    const TextureMapping mapping = mappingOf(ctx, slotRef("emissiveTexture", gltf.emissiveTexture), material.name);
    if (material.isEmissive()) {
      material.emissionMapping = mapping;
      material.emissionTexture = textureFor(ctx, gltf.emissiveTexture.index);
    }
  }
  material.twoSidedEmission = gltf.doubleSided;
  return material;
}

/// The bytes of buffer view `viewIndex`, checked against its buffer; `what` names it in messages.
std::span<const unsigned char> bufferViewBytes(const tinygltf::Model& model, const std::string& path, int viewIndex,
                                               const std::string& what) {
  if (viewIndex < 0 || size_t(viewIndex) >= model.bufferViews.size())
    fail("{}: {} refers to buffer view {} but the file has {}", path, what, viewIndex, model.bufferViews.size());
  const tinygltf::BufferView& view = model.bufferViews[size_t(viewIndex)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
    fail("{}: buffer view {} refers to a missing buffer", path, viewIndex);
  const std::vector<unsigned char>& data = model.buffers[size_t(view.buffer)].data;
  if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
    fail("{}: {}: buffer view {} runs past the end of its buffer", path, what, viewIndex);
  return {data.data() + view.byteOffset, view.byteLength};
}

/// A KHR_draco_mesh_compression primitive decoded (gltf_compression.h): the extension object
/// `extension` names the buffer view and each attribute's Draco id; `components` says which
/// glTF attributes to read and with how many components (others are not read).
DracoPrimitive decodeDracoPrimitive(const GltfContext& ctx, const tinygltf::Value& extension,
                                    const tinygltf::Primitive& primitive, const std::map<std::string, int>& components,
                                    const std::string& name) {
  const std::string label = fmt::format("{}: mesh '{}'", ctx.path, name);
  if (!extension.Has("bufferView") || !extension.Get("bufferView").IsInt() || !extension.Has("attributes") ||
      !extension.Get("attributes").IsObject())
    fail("{}: {} needs a bufferView and attributes", label, kDraco);
  const std::span<const unsigned char> bytes =
      bufferViewBytes(ctx.model, ctx.path, extension.Get("bufferView").GetNumberAsInt(), fmt::format("mesh '{}' ({})", name, kDraco));
  std::map<std::string, int> ids;
  const tinygltf::Value& attributes = extension.Get("attributes");
  for (const std::string& key : attributes.Keys()) {
    if (!components.contains(key) || !primitive.attributes.contains(key)) continue;
    if (!attributes.Get(key).IsInt()) fail("{}: {} attribute {} is not an integer id", label, kDraco, key);
    ids[key] = attributes.Get(key).GetNumberAsInt();
  }
  DracoPrimitive decoded = decodeDraco(bytes, ids, components, label);
  if (decoded.indices.size() % 3 != 0 || decoded.vertexCount == 0)
    fail("{}: the Draco buffer decodes to no triangles", label);
  return decoded;
}

/// Decodes every EXT_meshopt_compression or KHR_meshopt_compression buffer view into a buffer
/// of its own and points the view at it, so that the accessors read plain data
/// (gltf_compression.h). Without meshopt in the build the views keep their uncompressed
/// fallback, unless the file requires the extension (then decodeMeshopt refuses). A view may
/// use one of the two, not both (the KHR extension's exclusion).
void decodeMeshoptViews(const std::string& path, tinygltf::Model& model) {
  auto required = [&](const char* name) {
    return std::find(model.extensionsRequired.begin(), model.extensionsRequired.end(), name) !=
           model.extensionsRequired.end();
  };
  for (size_t v = 0; v < model.bufferViews.size(); ++v) {
    const auto& extensions = model.bufferViews[v].extensions;
    if (extensions.contains(kMeshopt) && extensions.contains(kMeshoptKhr))
      fail("{}: buffer view {} uses both {} and {}; a view may use one of them", path, v, kMeshopt, kMeshoptKhr);
    const char* name = extensions.contains(kMeshoptKhr) ? kMeshoptKhr : kMeshopt;
    auto it = extensions.find(name);
    if (it == extensions.end() || !(meshoptSupported() || required(name))) continue;
    const tinygltf::Value& e = it->second;
    const std::string label = fmt::format("{}: buffer view {} ({})", path, v, name);
    auto integer = [&](const char* key, bool needed) -> size_t {
      if (!e.Has(key)) {
        if (needed) fail("{} lacks {}", label, key);
        return 0;
      }
      if (!e.Get(key).IsInt() || e.Get(key).GetNumberAsInt() < 0) fail("{}: {} must be a non-negative integer", label, key);
      return size_t(e.Get(key).GetNumberAsInt());
    };
    const size_t buffer = integer("buffer", true), offset = integer("byteOffset", false), length = integer("byteLength", true);
    MeshoptView view;
    view.extension = name;
    view.byteStride = integer("byteStride", true);
    view.count = integer("count", true);
    view.mode = e.Has("mode") && e.Get("mode").IsString() ? e.Get("mode").Get<std::string>() : "";
    view.filter = e.Has("filter") && e.Get("filter").IsString() ? e.Get("filter").Get<std::string>() : "NONE";
    if (buffer >= model.buffers.size() || offset > model.buffers[buffer].data.size() ||
        length > model.buffers[buffer].data.size() - offset)
      fail("{}: its data lies outside buffer {}", label, buffer);
    const unsigned char* source = model.buffers[buffer].data.data() + offset;
    tinygltf::Buffer decoded;
    decoded.data = decodeMeshopt({source, length}, view, label);
    tinygltf::BufferView& target = model.bufferViews[v];
    if (target.byteLength > decoded.data.size()) fail("{}: decodes to fewer bytes than the view's byteLength", label);
    target.buffer = int(model.buffers.size());
    target.byteOffset = 0;
    model.buffers.push_back(std::move(decoded));
  }
}

void addPrimitive(GltfContext& ctx, const tinygltf::Primitive& primitive, const Mat4& world, const std::string& name) {
  const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
  if (mode != TINYGLTF_MODE_TRIANGLES) {
    spdlog::warn("{}: mesh '{}': primitive mode {} is not triangles (4); skipped", ctx.path, name, mode);
    return;
  }
  auto attribute = [&](const char* key) {
    auto it = primitive.attributes.find(key);
    return it == primitive.attributes.end() ? -1 : it->second;
  };
  const int positionAccessor = attribute("POSITION");
  if (positionAccessor < 0) fail("{}: mesh '{}' has a primitive without POSITION", ctx.path, name);
  auto componentsOf = [&](int accessor) {
    return size_t(accessor) < ctx.model.accessors.size() && ctx.model.accessors[size_t(accessor)].type == TINYGLTF_TYPE_VEC4 ? 4 : 3;
  };
  // A Draco-compressed primitive: its attributes and indices from the decoded mesh (the
  // accessors then give only counts and types); without Draco in the build and the extension
  // not required, the accessors' uncompressed fallback.
  std::optional<DracoPrimitive> draco;
  if (auto it = primitive.extensions.find(kDraco); it != primitive.extensions.end() && (dracoSupported() || ctx.dracoRequired))
    draco = decodeDracoPrimitive(ctx, it->second, primitive,
                                 {{"POSITION", 3}, {"NORMAL", 3}, {"TEXCOORD_0", 2}, {"TEXCOORD_1", 2},
                                  {"COLOR_0", componentsOf(attribute("COLOR_0"))}},
                                 name);
  auto floatsOf = [&](int accessor, int components, const char* key) {
    if (draco) {
      auto found = draco->attributes.find(key);
      if (found != draco->attributes.end()) return found->second;
    }
    return readFloats(ctx, accessor, components, key);
  };

  Mesh mesh;
  mesh.name = name;
  const std::vector<float> positions = floatsOf(positionAccessor, 3, "POSITION");
  const size_t vertexCount = positions.size() / 3;
  const Mat3 linear(world);
  const Mat3 normalMatrix = glm::transpose(glm::inverse(linear));
  for (size_t v = 0; v < vertexCount; ++v)
    mesh.positions.push_back(Vec3(world * Vec4(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2], 1.0f)));
  if (const int normalAccessor = attribute("NORMAL"); normalAccessor >= 0) {
    const std::vector<float> normals = floatsOf(normalAccessor, 3, "NORMAL");
    if (normals.size() != positions.size()) fail("{}: mesh '{}': NORMAL and POSITION counts differ", ctx.path, name);
    for (size_t v = 0; v < vertexCount; ++v)
      mesh.normals.push_back(normalMatrix * Vec3(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]));
  }
  // The material first: which uv sets its textures read (a set they read must be there).
  if (primitive.material >= 0 && size_t(primitive.material) >= ctx.model.materials.size())
    fail("{}: mesh '{}' uses material {} but the file has {}", ctx.path, name, primitive.material,
         ctx.model.materials.size());
  bool readsSet[2] = {false, false};
  if (primitive.material >= 0) {
    const Material& m = ctx.scene.materials[size_t(primitive.material)];
    const std::pair<int, const TextureMapping*> slots[] = {{m.albedoTexture, &m.albedoMapping},
                                                          {m.alphaTexture, &m.alphaMapping},
                                                          {m.normalTexture, &m.normalMapping},
                                                          {m.metallicRoughness.texture, &m.metallicRoughness.mapping},
                                                          {m.emissionTexture, &m.emissionMapping}};
    for (const auto& [texture, mapping] : slots)
      if (texture >= 0) readsSet[mapping->uvSet] = true;
    for (int s = 0; s < PbrLayerMaps::kSlots; ++s)
      if (m.layers.texture[size_t(s)] >= 0) readsSet[m.layers.mapping[size_t(s)].uvSet] = true;
    for (int set = 0; set < 2; ++set)
      if (readsSet[set] && attribute(set == 0 ? "TEXCOORD_0" : "TEXCOORD_1") < 0)
        fail("{}: mesh '{}': its material '{}' reads TEXCOORD_{}, which the primitive does not have", ctx.path, name,
             m.name, set);
  }
  // TEXCOORD_0 always (the barycentrics stand in without it); TEXCOORD_1 only where read.
  for (int set = 0; set < 2; ++set) {
    const char* key = set == 0 ? "TEXCOORD_0" : "TEXCOORD_1";
    const int uvAccessor = attribute(key);
    if (uvAccessor < 0 || (set == 1 && !readsSet[1])) continue;
    const std::vector<float> uvs = floatsOf(uvAccessor, 2, key);
    if (uvs.size() / 2 != vertexCount) fail("{}: mesh '{}': {} and POSITION counts differ", ctx.path, name, key);
    std::vector<Vec2>& target = set == 0 ? mesh.uvs : mesh.uvs1;
    for (size_t v = 0; v < vertexCount; ++v) target.push_back(Vec2(uvs[2 * v], 1.0f - uvs[2 * v + 1]));
  }
  // COLOR_0 (RGB or RGBA, linear) multiplies the base colour, and its alpha the base colour's
  // alpha: the coverage of an alpha-masked material (alphaMode MASK or BLEND; OPAQUE ignores
  // alpha). All white is the same as none, which keeps the material's albedo constant
  // (exporters often write it); all-opaque alphas likewise.
  if (const int colorAccessor = attribute("COLOR_0"); colorAccessor >= 0) {
    const int components = componentsOf(colorAccessor);
    const std::vector<float> colors = floatsOf(colorAccessor, components, "COLOR_0");
    if (colors.size() / size_t(components) != vertexCount)
      fail("{}: mesh '{}': COLOR_0 and POSITION counts differ", ctx.path, name);
    const std::string alphaMode = primitive.material >= 0 ? ctx.model.materials[size_t(primitive.material)].alphaMode : "";
    const bool masked = components == 4 && (alphaMode == "MASK" || alphaMode == "BLEND");
    bool clamped = false, white = true, opaque = true;
    for (size_t v = 0; v < vertexCount; ++v) {
      const float* value = &colors[size_t(components) * v];
      const Rgb c(value[0], value[1], value[2]);
      const Rgb kept = glm::clamp(c, 0.0f, 1.0f);
      if (!isFinite(c) || (components == 4 && !std::isfinite(value[3])))
        fail("{}: mesh '{}': COLOR_0 {} is not finite", ctx.path, name, v);
      clamped = clamped || kept != c;
      white = white && kept == Rgb(1.0f);
      mesh.colors.push_back(kept);
      if (masked) {
        const float alpha = std::clamp(value[3], 0.0f, 1.0f);
        clamped = clamped || alpha != value[3];
        opaque = opaque && alpha == 1.0f;
        mesh.alphas.push_back(alpha);
      }
    }
    if (clamped) spdlog::warn("{}: mesh '{}': COLOR_0 values outside [0, 1] clamped", ctx.path, name);
    if (white) mesh.colors.clear();
    if (opaque) mesh.alphas.clear();
  }

  std::vector<uint32_t> indices;
  if (draco) indices = std::move(draco->indices);
  else if (primitive.indices >= 0) indices = readIndices(ctx, primitive.indices);
  else {
    indices.resize(vertexCount);
    for (size_t i = 0; i < vertexCount; ++i) indices[i] = uint32_t(i);
  }
  if (indices.size() % 3 != 0)
    fail("{}: mesh '{}': {} indices is not a multiple of 3 for triangles", ctx.path, name, indices.size());

  uint32_t material;
  if (primitive.material >= 0) {
    material = uint32_t(primitive.material);
  } else {
    if (ctx.defaultMaterial < 0) {
      ctx.defaultMaterial = int(ctx.scene.materials.size());
      // The glTF default material: baseColor 1, metallic 1, roughness 1 (spec 3.9.6).
      ctx.scene.materials.push_back({.name = "default", .bsdf = GgxBsdf{Rgb(0.0f), Rgb(1.0f), 1.0f}});
    }
    material = uint32_t(ctx.defaultMaterial);
  }
  // A mirroring transform reverses the apparent winding; swap to keep the front side.
  const bool mirrored = glm::determinant(linear) < 0.0f;
  for (size_t i = 0; i < indices.size(); i += 3) {
    mesh.triangles.push_back(mirrored ? UVec3(indices[i], indices[i + 2], indices[i + 1])
                                      : UVec3(indices[i], indices[i + 1], indices[i + 2]));
    mesh.materials.push_back(material);
  }
  // finalize() checks the indices against the vertex count and names the file.
  ctx.scene.meshes.push_back(std::move(mesh));
}

void addLight(GltfContext& ctx, int lightIndex, const Mat4& world, const std::string& nodeName) {
  if (lightIndex < 0 || size_t(lightIndex) >= ctx.model.lights.size())
    fail("{}: node '{}' refers to light {} but the file has {}", ctx.path, nodeName, lightIndex, ctx.model.lights.size());
  const tinygltf::Light& light = ctx.model.lights[size_t(lightIndex)];
  Rgb color(1.0f);
  if (light.color.size() >= 3) color = Rgb(float(light.color[0]), float(light.color[1]), float(light.color[2]));
  const Rgb radiometric = color * float(light.intensity / kLumensPerWatt);
  const Vec3 position(world * Vec4(0.0f, 0.0f, 0.0f, 1.0f));
  const Vec3 direction = glm::normalize(Mat3(world) * Vec3(0.0f, 0.0f, -1.0f));
  // KHR_lights_punctual's types are plenoptic's of the same names (light/lights.h). Each takes
  // what it has of the node's pose and the cone, and glTF's intensity as its Emission.
  if (light.type != "point" && light.type != "spot" && light.type != "directional")
    fail("{}: light {} has unknown type '{}' (point, spot, directional)", ctx.path, lightIndex, light.type);
  LightParameters parameters = {{"position", position},
                                {"direction", direction},
                                {"inner_angle", float(light.spot.innerConeAngle)},
                                {"outer_angle", float(light.spot.outerConeAngle)}};
  Light created = createLight(light.type, parameters, fmt::format("{}: light {}", ctx.path, lightIndex), {.ignoreUnknown = true});
  setLightEmission(created, radiometric);
  ctx.scene.lights.push_back(created);
}

void addCamera(GltfContext& ctx, int cameraIndex, const Mat4& world, const std::string& nodeName) {
  if (cameraIndex < 0 || size_t(cameraIndex) >= ctx.model.cameras.size())
    fail("{}: node '{}' refers to camera {} but the file has {}", ctx.path, nodeName, cameraIndex,
         ctx.model.cameras.size());
  const tinygltf::Camera& gltf = ctx.model.cameras[size_t(cameraIndex)];
  if (gltf.type != "perspective") {
    spdlog::warn("{}: camera '{}' is {}; only perspective cameras are supported, skipped", ctx.path, gltf.name,
                 gltf.type);
    return;
  }
  CameraDesc camera;
  camera.name = !nodeName.empty() ? nodeName : !gltf.name.empty() ? gltf.name : fmt::format("camera{}", ctx.unnamedCameras++);
  camera.eye = Vec3(world * Vec4(0.0f, 0.0f, 0.0f, 1.0f));
  const Vec3 forward = glm::normalize(Mat3(world) * Vec3(0.0f, 0.0f, -1.0f));
  camera.target = camera.eye + forward;
  camera.up = glm::normalize(Mat3(world) * Vec3(0.0f, 1.0f, 0.0f));
  camera.fovYDegrees = glm::degrees(float(gltf.perspective.yfov));
  if (gltf.perspective.aspectRatio > 0.0) camera.aspectRatio = float(gltf.perspective.aspectRatio);
  ctx.scene.cameras.push_back(camera);
}

void visitNode(GltfContext& ctx, int nodeIndex, const Mat4& parent, int depth) {
  const tinygltf::Model& model = ctx.model;
  if (nodeIndex < 0 || size_t(nodeIndex) >= model.nodes.size()) fail("{}: node {} does not exist", ctx.path, nodeIndex);
  // glTF requires the hierarchy to be a forest; a cycle would recurse forever.
  if (depth > int(model.nodes.size())) fail("{}: the node hierarchy has a cycle (at node {})", ctx.path, nodeIndex);
  const tinygltf::Node& node = model.nodes[size_t(nodeIndex)];
  const Mat4 world = parent * localTransform(node);
  if (node.mesh >= 0) {
    if (size_t(node.mesh) >= model.meshes.size()) fail("{}: node '{}' refers to missing mesh {}", ctx.path, node.name, node.mesh);
    const tinygltf::Mesh& mesh = model.meshes[size_t(node.mesh)];
    const std::string name = !mesh.name.empty() ? mesh.name : node.name;
    for (const tinygltf::Primitive& primitive : mesh.primitives) addPrimitive(ctx, primitive, world, name);
  }
  if (node.camera >= 0) addCamera(ctx, node.camera, world, node.name);
  if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end() && it->second.Has("light"))
    addLight(ctx, it->second.Get("light").GetNumberAsInt(), world, node.name);
  for (int child : node.children) visitNode(ctx, child, world, depth + 1);
}

/// What keepEncodedImage reads and fills while tinygltf loads: the model being loaded (its
/// buffers and buffer views are parsed before the images) and each image's encoded bytes.
struct EncodedImages {
  const tinygltf::Model* model = nullptr;
  std::vector<std::vector<unsigned char>> bytes;  ///< per glTF image
};

/// Whether buffer view `viewIndex` of `model` exists and `size` bytes from its start lie inside its buffer.
bool bufferViewHolds(const tinygltf::Model& model, int viewIndex, size_t size) {
  if (size_t(viewIndex) >= model.bufferViews.size()) return false;
  const tinygltf::BufferView& view = model.bufferViews[size_t(viewIndex)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size()) return false;
  const size_t bufferSize = model.buffers[size_t(view.buffer)].data.size();
  return view.byteOffset <= bufferSize && size <= bufferSize - view.byteOffset;
}

/// tinygltf's image loader callback: keeps the bytes (user data: EncodedImages) and leaves
/// decoding to textureFor, so that a texture is decoded once, by decodeLdrImage, the same
/// decoder the .plf reader uses for the embedded bytes. An image stored in a buffer view is
/// checked against its buffer first: tinygltf checks only the view's start, and hands over
/// byteLength bytes from there even when they run past the buffer's end.
bool keepEncodedImage(tinygltf::Image* image, const int imageIndex, std::string* error, std::string*, int, int,
                      const unsigned char* bytes, int size, void* userData) {
  auto& images = *static_cast<EncodedImages*>(userData);
  if (imageIndex < 0 || size < 0) return false;
  if (image && image->bufferView >= 0 && !bufferViewHolds(*images.model, image->bufferView, size_t(size))) {
    if (error) *error += fmt::format("image {}: buffer view {} runs past the end of its buffer", imageIndex, image->bufferView);
    return false;
  }
  if (size_t(imageIndex) >= images.bytes.size()) images.bytes.resize(size_t(imageIndex) + 1);
  images.bytes[size_t(imageIndex)].assign(bytes, bytes + size);
  return true;
}

/// tinygltf refuses an index accessor without a buffer view, which is what an exporter writes
/// for a KHR_draco_mesh_compression primitive (its indices are in the Draco stream). So such
/// accessors get their primitive's Draco buffer view; their data is never read
/// (decodeDracoPrimitive replaces it). Returns whether it changed `doc`.
bool patchDracoIndices(nlohmann::json& doc) {
  if (!doc.contains("meshes") || !doc["meshes"].is_array() || !doc.contains("accessors") || !doc["accessors"].is_array())
    return false;
  nlohmann::json& accessors = doc["accessors"];
  bool patched = false;
  for (nlohmann::json& mesh : doc["meshes"]) {
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (nlohmann::json& primitive : mesh["primitives"]) {
      if (!primitive.is_object() || !primitive.contains("indices") || !primitive["indices"].is_number_unsigned()) continue;
      const auto extensions = primitive.find("extensions");
      if (extensions == primitive.end() || !extensions->is_object() || !extensions->contains(kDraco)) continue;
      const nlohmann::json& draco = (*extensions)[kDraco];
      if (!draco.is_object() || !draco.contains("bufferView") || !draco["bufferView"].is_number_unsigned()) continue;
      const size_t index = primitive["indices"].get<size_t>();
      if (index >= accessors.size() || !accessors[index].is_object() || accessors[index].contains("bufferView")) continue;
      accessors[index]["bufferView"] = draco["bufferView"];
      patched = true;
    }
  }
  return patched;
}

/// An EXT_meshopt_compression or KHR_meshopt_compression fallback buffer (its extension says
/// "fallback": true) may have no data at all: no `uri`, only a byteLength, the size of the
/// uncompressed views it stands for. tinygltf refuses that — in a .gltf for the missing uri, in a .glb (what gltfpack
/// writes) because the byteLength is larger than the binary chunk, which holds the compressed
/// data. The fallback is never read where meshopt decodes (decodeMeshoptViews points every
/// view at its decoded bytes), so in a build with meshopt each such buffer becomes a 3-byte
/// data URI. Returns whether it changed `doc`.
bool patchMeshoptFallbacks(nlohmann::json& doc) {
  if (!meshoptSupported() || !doc.contains("buffers") || !doc["buffers"].is_array()) return false;
  bool patched = false;
  for (nlohmann::json& buffer : doc["buffers"]) {
    if (!buffer.is_object() || buffer.contains("uri")) continue;
    const auto extensions = buffer.find("extensions");
    if (extensions == buffer.end() || !extensions->is_object()) continue;
    const bool fallback = std::any_of(kMeshoptExtensions.begin(), kMeshoptExtensions.end(), [&](const char* name) {
      const auto meshopt = extensions->find(name);
      return meshopt != extensions->end() && meshopt->is_object() && meshopt->contains("fallback") &&
             (*meshopt)["fallback"] == true;
    });
    if (!fallback) continue;
    buffer["uri"] = "data:application/octet-stream;base64,AAAA";
    buffer["byteLength"] = 3;
    patched = true;
  }
  return patched;
}

/// The glTF file's bytes as tinygltf should read them (patchDracoIndices, patchMeshoptFallbacks;
/// a .glb with its JSON chunk rebuilt), or "" when nothing needs patching (then tinygltf reads
/// the file itself, and reports whatever is wrong with it).
std::string patchedFile(const std::string& path, bool binary) {
  // The JSON alone first (a .glb's first chunk): the binary chunk is read only when patching.
  std::ifstream in(path, std::ios::binary);
  std::string header(binary ? 20 : 0, '\0'), text;
  uint32_t jsonLength = 0;
  if (binary) {
    if (!in.read(header.data(), 20) || header.compare(0, 4, "glTF") != 0 || header.compare(16, 4, "JSON") != 0) return "";
    std::memcpy(&jsonLength, header.data() + 12, 4);
    std::error_code ec;
    const uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec || jsonLength > size - 20) return "";  // a lying length: tinygltf reports the file
    text.resize(jsonLength);
    if (!in.read(text.data(), std::streamsize(jsonLength))) return "";
  } else {
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  if (text.find(kDraco) == std::string::npos && text.find(kMeshopt) == std::string::npos &&
      text.find(kMeshoptKhr) == std::string::npos)
    return "";
  nlohmann::json doc = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) return "";
  const bool draco = patchDracoIndices(doc);
  const bool meshopt = patchMeshoptFallbacks(doc);
  if (!draco && !meshopt) return "";
  std::string json = doc.dump();
  if (!binary) return json;
  const std::string rest((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (json.size() % 4 != 0) json += ' ';  // GLB chunks are 4-byte aligned
  std::string glb = header.substr(0, 12);
  const uint32_t total = uint32_t(20 + json.size() + rest.size()), length = uint32_t(json.size());
  std::memcpy(glb.data() + 8, &total, 4);
  glb.append(reinterpret_cast<const char*>(&length), 4);
  glb += "JSON";
  return glb + json + rest;
}

}  // namespace

Scene loadGltf(const std::string& path) {
  requireRegularFile(path);
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  EncodedImages encodedImages{&model, {}};
  loader.SetImageLoader(keepEncodedImage, &encodedImages);
  std::string error, warning;
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  bool ok = false;
  try {
    const bool binary = extension == ".glb";
    if (const std::string patched = patchedFile(path, binary); !patched.empty()) {
      const std::string baseDir = std::filesystem::path(path).parent_path().string();
      ok = binary ? loader.LoadBinaryFromMemory(&model, &error, &warning, reinterpret_cast<const unsigned char*>(patched.data()),
                                                unsigned(patched.size()), baseDir)
                  : loader.LoadASCIIFromString(&model, &error, &warning, patched.data(), unsigned(patched.size()), baseDir);
    } else {
      ok = binary ? loader.LoadBinaryFromFile(&model, &error, &warning, path)
                  : loader.LoadASCIIFromFile(&model, &error, &warning, path);
    }
  } catch (const std::exception& e) {
    // tinygltf mostly reports through `error`, but some malformed files make it (or the JSON
    // library inside it) throw, e.g. std::out_of_range on a GLB whose chunk lengths lie.
    fail("{}: not a valid glTF file: {}", path, e.what());
  }
  while (!warning.empty() && std::isspace(static_cast<unsigned char>(warning.back()))) warning.pop_back();
  if (!warning.empty()) spdlog::warn("{}: {}", path, warning);
  if (!ok) {
    while (!error.empty() && (error.back() == '\n' || error.back() == '\r')) error.pop_back();
    fail("{}: not a valid glTF file: {}", path, error.empty() ? "unknown error" : error);
  }
  checkExtensions(path, model);
  decodeMeshoptViews(path, model);

  Scene scene;
  scene.sourcePath = path;
  GltfContext ctx{path, model, scene, encodedImages.bytes, {}};
  ctx.dracoRequired = std::find(model.extensionsRequired.begin(), model.extensionsRequired.end(), kDraco) !=
                      model.extensionsRequired.end();
  for (size_t m = 0; m < model.materials.size(); ++m)
    scene.materials.push_back(convertMaterial(ctx, model.materials[m], int(m)));

  std::vector<int> roots;
  if (!model.scenes.empty()) {
    const int sceneIndex = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (size_t(sceneIndex) >= model.scenes.size()) fail("{}: default scene {} does not exist", path, sceneIndex);
    roots = model.scenes[size_t(sceneIndex)].nodes;
  } else {
    std::vector<bool> isChild(model.nodes.size(), false);
    for (const tinygltf::Node& node : model.nodes)
      for (int child : node.children)
        if (child >= 0 && size_t(child) < isChild.size()) isChild[size_t(child)] = true;
    for (size_t n = 0; n < model.nodes.size(); ++n)
      if (!isChild[n]) roots.push_back(int(n));
  }
  for (int root : roots) visitNode(ctx, root, Mat4(1.0f), 0);
  if (scene.materials.empty()) scene.materials.push_back({.name = "unused", .bsdf = LambertBsdf{}});
  scene.finalize();
  return scene;
}

}  // namespace pl::detail
