// glTF texturing (gltf_loader.cpp, scene.h albedoModulation / materialModelAt, texture.h
// TextureSampling): KHR_texture_transform, texCoord sets, sampler wrap modes and filters,
// COLOR_0, metallic-roughness textures, and the errors and warnings for bad or unsupported input.
// Every file is generated here: a unit quad in the z = 0 plane, (0,0)–(1,1), whose TEXCOORD_0 is
// glTF's (x, 1 − y) (so our uv is the position), with a 4×4 PNG whose texels are all different.
#include "core/error.h"
#include "scene/scene.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "support/expect_error.h"
#include "support/expect_vec3.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

// Float tolerance for values that went through a few float operations.
constexpr float kTight = 1e-5f;
constexpr int kSide = 4;  ///< texels per side of the test texture

/// The test texture's 8-bit value of texel (x, y), x to the right, y down from the top row
/// (the file's order), channel c: all 16 texels differ in R and in G.
uint8_t texelByte(int x, int y, int c) { return uint8_t(c == 0 ? 20 + 60 * x : c == 1 ? 20 + 60 * y : 100); }
Rgb texelLinear(int x, int y) {
  return Rgb(srgbToLinear(texelByte(x, y, 0) / 255.0f), srgbToLinear(texelByte(x, y, 1) / 255.0f),
             srgbToLinear(texelByte(x, y, 2) / 255.0f));
}
Rgb texelRaw(int x, int y) { return Rgb(texelByte(x, y, 0), texelByte(x, y, 1), texelByte(x, y, 2)) / 255.0f; }

/// The texel a glTF uv (top-left origin) falls in under nearest filtering, wrapped by `wrap`
/// ("repeat", "clamp", "mirror") the way the glTF/OpenGL specification defines it.
int wrappedTexel(float t, const std::string& wrap) {
  const int i = int(std::floor(t * kSide));
  if (wrap == "clamp") return std::clamp(i, 0, kSide - 1);
  const int period = wrap == "mirror" ? 2 * kSide : kSide;
  const int m = ((i % period) + period) % period;
  return m < kSide ? m : 2 * kSide - 1 - m;
}

/// A fresh directory with the texture and the quad's buffer.
fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) / ("pl_gltf_texturing_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  Image8 png{kSide, kSide, {}};
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x)
      for (int c = 0; c < 3; ++c) png.rgb.push_back(texelByte(x, y, c));
  writePng((dir / "tex.png").string(), png);
  // Buffer: POSITION (4 × vec3), TEXCOORD_0, TEXCOORD_1 (= TEXCOORD_0 / 2), COLOR_0 (vec3),
  // indices, COLOR_0 (vec4: white, alpha = y).
  std::vector<float> floats;
  const float xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const auto& p : xy) floats.insert(floats.end(), {p[0], p[1], 0.0f});
  for (const auto& p : xy) floats.insert(floats.end(), {p[0], 1.0f - p[1]});
  for (const auto& p : xy) floats.insert(floats.end(), {0.5f * p[0], 0.5f * (1.0f - p[1])});
  for (int v = 0; v < 4; ++v) floats.insert(floats.end(), {0.5f, 1.0f, 0.25f});
  const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
  std::ofstream bin(dir / "quad.bin", std::ios::binary);
  bin.write(reinterpret_cast<const char*>(floats.data()), std::streamsize(floats.size() * 4));
  bin.write(reinterpret_cast<const char*>(indices), sizeof(indices));
  std::vector<float> rgba;
  for (const auto& p : xy) rgba.insert(rgba.end(), {1.0f, 1.0f, 1.0f, p[1]});
  bin.write(reinterpret_cast<const char*>(rgba.data()), std::streamsize(rgba.size() * 4));
  return dir;
}

/// The quad file: `material` is the material object's JSON, `attributes` extra attributes,
/// `top` extra top-level keys (with a trailing comma), `sampler` the sampler's JSON.
std::string writeQuad(const fs::path& dir, const std::string& material, const std::string& attributes = "",
                      const std::string& top = "", const std::string& sampler = "{}") {
  const std::string text = R"({"asset": {"version": "2.0"}, )" + top + R"(
    "buffers": [{"byteLength": 236, "uri": "quad.bin"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                    {"buffer": 0, "byteOffset": 80, "byteLength": 32}, {"buffer": 0, "byteOffset": 112, "byteLength": 48},
                    {"buffer": 0, "byteOffset": 160, "byteLength": 12}, {"buffer": 0, "byteOffset": 172, "byteLength": 64}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
                  {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                  {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                  {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC3"},
                  {"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"},
                  {"bufferView": 5, "componentType": 5126, "count": 4, "type": "VEC4"}],
    "images": [{"uri": "tex.png"}], "samplers": [)" + sampler + R"(],
    "textures": [{"source": 0, "sampler": 0}],
    "materials": [)" + material + R"(],
    "meshes": [{"name": "quad", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1)" + attributes +
                           R"(}, "indices": 4, "material": 0}]}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]})";
  const fs::path path = dir / "quad.gltf";
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

constexpr const char* kNearest = R"({"magFilter": 9728, "minFilter": 9728})";

/// The albedo point at position (x, y) of the quad (triangle 0 below the diagonal, 1 above).
AlbedoPoint pointAt(const Scene& scene, float x, float y) {
  return x >= y ? albedoPointAt(scene, 0, 0, Vec2(x - y, y)) : albedoPointAt(scene, 0, 1, Vec2(x, y - x));
}

using test_support::expectError;

/// What the loader logs while `run` runs.
std::string logOf(const std::function<void()>& run) {
  std::ostringstream log;
  const auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("capture", std::make_shared<spdlog::sinks::ostream_sink_mt>(log)));
  run();
  spdlog::set_default_logger(previous);
  return log.str();
}

size_t occurrences(const std::string& text, const std::string& needle) {
  size_t count = 0;
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++count;
  return count;
}

// A tiled, offset and rotated baseColorTexture read at known points gives the texel the glTF
// specification's matrix T·R·S puts there, in glTF's own top-left convention (nearest filter,
// so the texel exactly).
TEST(GltfTexturing, TextureTransformReadsTheSpecifiedTexel) {
  const fs::path dir = scratch("transform");
  struct Case {
    float offset[2], rotation, scale[2];
  };
  for (const Case& k : {Case{{0.25f, 0.0f}, 0.0f, {2.0f, 3.0f}}, Case{{0.1f, 0.3f}, 1.5707964f, {1.0f, 1.0f}},
                        Case{{-0.2f, 0.6f}, 0.4f, {1.5f, 0.7f}}}) {
    const std::string transform = fmt::format(R"({{"offset": [{}, {}], "rotation": {}, "scale": [{}, {}]}})", k.offset[0],
                                              k.offset[1], k.rotation, k.scale[0], k.scale[1]);
    const Scene scene = loadScene(writeQuad(
        dir, R"({"pbrMetallicRoughness": {"metallicFactor": 0, "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": )" +
                 transform + "}}}}",
        "", R"("extensionsUsed": ["KHR_texture_transform"],)", kNearest));
    const Material& material = scene.materials[0];
    for (const Vec2 p : {Vec2(0.33f, 0.13f), Vec2(0.83f, 0.41f), Vec2(0.12f, 0.77f), Vec2(0.61f, 0.93f)}) {
      // (No point where T·R·S lands on a texel edge, which rounding could put on either side.)
      const Vec2 g(p.x, 1.0f - p.y);  // glTF uv at the point
      const float c = std::cos(k.rotation), s = std::sin(k.rotation);
      const Vec2 scaled(k.scale[0] * g.x, k.scale[1] * g.y);
      const Vec2 t(k.offset[0] + c * scaled.x + s * scaled.y, k.offset[1] - s * scaled.x + c * scaled.y);
      const Rgb expected = texelLinear(wrappedTexel(t.x, "repeat"), wrappedTexel(t.y, "repeat"));
      SCOPED_TRACE(fmt::format("at {}, {} with {}", p.x, p.y, transform));
      EXPECT_VEC3_NEAR(albedoModulation(scene, material, pointAt(scene, p.x, p.y)), expected, kTight);
    }
  }
}

// Sampler wrap modes: the same point beyond the image reads different texels for repeat,
// clamp-to-edge and mirrored repeat, as the specification defines them, and the bilinear filter
// (the default) holds the edge under clamp.
TEST(GltfTexturing, WrapModesPerAxis) {
  const fs::path dir = scratch("wrap");
  const std::string material =
      R"({"pbrMetallicRoughness": {"metallicFactor": 0, "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [3, 2.5]}}}}})";
  for (const auto& [wrapS, nameS] : {std::pair{10497, "repeat"}, {33071, "clamp"}, {33648, "mirror"}})
    for (const auto& [wrapT, nameT] : {std::pair{10497, "repeat"}, {33071, "clamp"}, {33648, "mirror"}}) {
      const std::string sampler = fmt::format(R"({{"magFilter": 9728, "wrapS": {}, "wrapT": {}}})", wrapS, wrapT);
      const Scene scene = loadScene(writeQuad(dir, material, "", "", sampler));
      ASSERT_EQ(scene.textures.size(), 1u);
      for (const Vec2 p : {Vec2(0.55f, 0.2f), Vec2(0.9f, 0.1f), Vec2(0.2f, 0.7f), Vec2(0.75f, 0.45f)}) {
        const Vec2 t(3.0f * p.x, 2.5f * (1.0f - p.y));
        SCOPED_TRACE(fmt::format("{}/{} at {}, {}", nameS, nameT, p.x, p.y));
        EXPECT_VEC3_NEAR(albedoModulation(scene, scene.materials[0], pointAt(scene, p.x, p.y)),
                         texelLinear(wrappedTexel(t.x, nameS), wrappedTexel(t.y, nameT)), kTight);
      }
    }
  // Bilinear with clamp: far beyond the right edge, the right column's texels exactly.
  Texture texture;
  texture.image = Image(2, 1);
  texture.image.at(0, 0) = Rgb(0.2f);
  texture.image.at(1, 0) = Rgb(0.8f);
  texture.finish("test");
  EXPECT_VEC3_NEAR(texture.sample(Vec2(0.0f, 0.5f)), Rgb(0.5f), kTight);  // repeat: the two columns blend
  texture.sampling.wrapU = TextureWrap::ClampToEdge;
  EXPECT_VEC3_NEAR(texture.sample(Vec2(0.0f, 0.5f)), Rgb(0.2f), kTight);
  EXPECT_VEC3_NEAR(texture.sample(Vec2(7.3f, 0.5f)), Rgb(0.8f), kTight);
  EXPECT_VEC3_NEAR(texture.sampleLod(Vec2(7.3f, 0.5f), 0.5f), Rgb(0.5f * 0.8f + 0.5f * 0.5f), kTight);  // level 1 = mean
  texture.sampling.wrapU = TextureWrap::MirroredRepeat;
  EXPECT_VEC3_NEAR(texture.sample(Vec2(1.25f, 0.5f)), Rgb(0.8f), kTight);  // the right column, mirrored
  EXPECT_VEC3_NEAR(texture.sample(Vec2(1.75f, 0.5f)), Rgb(0.2f), kTight);
  // A minFilter without mip levels: the renderers read level 0 at any distance.
  texture.sampling = TextureSampling{};
  texture.sampling.mipmaps = false;
  EXPECT_EQ(texture.sampleLod(Vec2(0.25f, 0.5f), 3.0f), texture.sample(Vec2(0.25f, 0.5f)));
}

// texCoord 1 on the base colour reads TEXCOORD_1 (here TEXCOORD_0 / 2), and the loader keeps the
// second set only where a material reads it.
TEST(GltfTexturing, TexCoordOneReadsTheSecondSet) {
  const fs::path dir = scratch("texcoord1");
  const std::string material = R"({"pbrMetallicRoughness": {"metallicFactor": 0, "baseColorTexture": {"index": 0, "texCoord": 1}}})";
  const Scene scene = loadScene(writeQuad(dir, material, R"(, "TEXCOORD_1": 2)", "", kNearest));
  ASSERT_EQ(scene.meshes[0].uvs1.size(), 4u);
  for (const Vec2 p : {Vec2(0.3f, 0.1f), Vec2(0.9f, 0.6f), Vec2(0.1f, 0.8f)}) {
    const Vec2 t(0.5f * p.x, 0.5f * (1.0f - p.y));
    EXPECT_VEC3_NEAR(albedoModulation(scene, scene.materials[0], pointAt(scene, p.x, p.y)),
                     texelLinear(wrappedTexel(t.x, "repeat"), wrappedTexel(t.y, "repeat")), kTight);
  }
  // The path tracer's model at a hit takes the same texel times the factor.
  const SurfaceHit hit = surfaceAt(scene, 0, 0, Vec2(0.2f, 0.1f));  // position (0.3, 0.1)
  EXPECT_VEC3_NEAR(diffuseAlbedo(bsdfAt(scene, hit)), texelLinear(wrappedTexel(0.15f, "repeat"), wrappedTexel(0.45f, "repeat")),
                   kTight);
  const Scene unused = loadScene(writeQuad(dir, R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})",
                                           R"(, "TEXCOORD_1": 2)"));
  EXPECT_TRUE(unused.meshes[0].uvs1.empty());
}

// COLOR_0 multiplies the base colour at every hit: the path tracer's model, and the albedo the
// bake and both renderers read (diffuseAlbedoAt goes through the same albedoModulation).
TEST(GltfTexturing, VertexColorScalesTheAlbedo) {
  const fs::path dir = scratch("color0");
  const std::string material = R"({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1], "metallicFactor": 0}})";
  const Scene plain = loadScene(writeQuad(dir, material));
  EXPECT_FALSE(plain.materials[0].vertexColored);
  const Scene coloured = loadScene(writeQuad(dir, material, R"(, "COLOR_0": 3)"));
  ASSERT_TRUE(coloured.materials[0].vertexColored);
  const SurfaceHit hit = surfaceAt(coloured, 0, 1, Vec2(0.3f, 0.4f));
  EXPECT_VEC3_NEAR(diffuseAlbedo(bsdfAt(coloured, hit)), Rgb(0.8f * 0.5f, 0.6f * 1.0f, 0.4f * 0.25f), kTight);
  EXPECT_VEC3_NEAR(diffuseAlbedo(bsdfAt(plain, hit)), Rgb(0.8f, 0.6f, 0.4f), kTight);
}

// COLOR_0's alpha multiplies the base colour's alpha: an alpha-masked material's coverage
// (alpha = y on the quad here, × baseColorFactor.a); OPAQUE ignores it, as it does alpha.
TEST(GltfTexturing, VertexAlphaMultipliesTheMaskCoverage) {
  const fs::path dir = scratch("color0_alpha");
  auto coverage = [](const Scene& scene, float x, float y) {
    return x >= y ? coverageAt(scene, 0, 0, Vec2(x - y, y)) : coverageAt(scene, 0, 1, Vec2(x, y - x));
  };
  const Scene masked = loadScene(writeQuad(
      dir, R"({"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.8]}})", R"(, "COLOR_0": 5)"));
  ASSERT_TRUE(masked.materials[0].isMasked());
  EXPECT_FALSE(masked.materials[0].vertexColored);  // white: the albedo stays constant
  for (const Vec2 p : {Vec2(0.6f, 0.3f), Vec2(0.2f, 0.7f), Vec2(0.9f, 0.9f)})
    EXPECT_NEAR(coverage(masked, p.x, p.y), 0.8f * p.y, kTight) << p.x << "," << p.y;
  const Scene opaque = loadScene(writeQuad(dir, R"({"pbrMetallicRoughness": {}})", R"(, "COLOR_0": 5)"));
  EXPECT_FALSE(opaque.materials[0].isMasked());
  EXPECT_TRUE(opaque.meshes[0].alphas.empty());
  // RGB colours have no alpha: a MASK material keeps its factor's coverage.
  const Scene rgb = loadScene(writeQuad(
      dir, R"({"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.8]}})", R"(, "COLOR_0": 3)"));
  EXPECT_TRUE(rgb.meshes[0].alphas.empty());
  EXPECT_NEAR(coverage(rgb, 0.6f, 0.3f), 0.8f, kTight);
}

// A metallicRoughnessTexture sets the model at each hit: B × metallicFactor is the metalness,
// G × roughnessFactor the roughness (raw values, no sRGB decoding); at fractional metalness
// glTF's mix of a dielectric and a metal (bsdf.h gltfMetallicRoughnessModel).
TEST(GltfTexturing, MetallicRoughnessTexturePerHit) {
  const fs::path dir = scratch("mr");
  const Scene scene = loadScene(writeQuad(dir,
      R"({"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.5, 0.3, 1], "metallicFactor": 0.5, "roughnessFactor": 0.8,
          "metallicRoughnessTexture": {"index": 0}}})", "", "", kNearest));
  const Material& material = scene.materials[0];
  ASSERT_GE(material.metallicRoughness.texture, 0);
  for (const Vec2 p : {Vec2(0.3f, 0.1f), Vec2(0.9f, 0.6f), Vec2(0.1f, 0.8f)}) {
    const Rgb texel = texelRaw(wrappedTexel(p.x, "repeat"), wrappedTexel(1.0f - p.y, "repeat"));
    const Bsdf expected = gltfMetallicRoughnessModel(Rgb(0.9f, 0.5f, 0.3f), 0.5f * texel.b, 0.8f * texel.g);
    const SurfaceHit hit = p.x >= p.y ? surfaceAt(scene, 0, 0, Vec2(p.x - p.y, p.y)) : surfaceAt(scene, 0, 1, Vec2(p.x, p.y - p.x));
    const Bsdf got = bsdfAt(scene, hit);
    ASSERT_EQ(got.index(), expected.index());
    std::visit([&](const auto& want) {
      using Model = std::decay_t<decltype(want)>;
      if constexpr (std::is_same_v<Model, GgxBsdf> || std::is_same_v<Model, GltfPbrBsdf>) {
        const Model& at = std::get<Model>(got);
        EXPECT_NEAR(at.alpha, want.alpha, kTight);
        EXPECT_VEC3_NEAR(at.f0, want.f0, kTight);
        EXPECT_VEC3_NEAR(at.diffuse, want.diffuse, kTight);
      } else {
        ADD_FAILURE() << "a metallic-roughness material made a " << modelName(want);
      }
    }, expected);
  }
}

// emissiveTexture: emissiveFactor × KHR_materials_emissive_strength × the sRGB-decoded texel,
// read through the slot's texCoord and KHR_texture_transform — the one rule the path tracer,
// the light sampler and the bake read (emissionModulation) and the renderers' albedo point
// carries. A black factor emits nothing, so the texture is not even kept.
TEST(GltfTexturing, EmissiveTextureMultipliesTheFactor) {
  const fs::path dir = scratch("emissive");
  const Scene scene = loadScene(writeQuad(dir,
      R"({"name": "panel", "emissiveFactor": [1, 0.5, 0.25],
          "emissiveTexture": {"index": 0, "texCoord": 1, "extensions": {"KHR_texture_transform": {"scale": [2, 2]}}},
          "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}}})",
      R"(, "TEXCOORD_1": 2)", R"("extensionsUsed": ["KHR_texture_transform", "KHR_materials_emissive_strength"],)", kNearest));
  const Material& material = scene.materials[0];
  ASSERT_GE(material.emissionTexture, 0);
  EXPECT_EQ(scene.textures[size_t(material.emissionTexture)].decode, ImageDecode::Colour);
  EXPECT_VEC3_NEAR(material.emission, Rgb(4.0f, 2.0f, 1.0f), kTight);
  for (const Vec2 p : {Vec2(0.3f, 0.1f), Vec2(0.9f, 0.6f), Vec2(0.1f, 0.8f), Vec2(0.6f, 0.35f)}) {
    // TEXCOORD_1 is half of TEXCOORD_0 (glTF's (x, 1 − y)), scaled by 2: the texel under (x, 1 − y).
    const Rgb expected = texelLinear(wrappedTexel(p.x, "repeat"), wrappedTexel(1.0f - p.y, "repeat"));
    const bool lower = p.x >= p.y;
    const Vec2 b = lower ? Vec2(p.x - p.y, p.y) : Vec2(p.x, p.y - p.x);
    SCOPED_TRACE(fmt::format("at {}, {}", p.x, p.y));
    EXPECT_VEC3_NEAR(emissionModulation(scene, material, 0, lower ? 0 : 1, b), expected, kTight);
    EXPECT_VEC3_NEAR(pointAt(scene, p.x, p.y).emission, expected, kTight);
  }
  const Scene dark = loadScene(writeQuad(dir, R"({"emissiveTexture": {"index": 0}})"));
  EXPECT_EQ(dark.materials[0].emissionTexture, -1);
  EXPECT_FALSE(dark.materials[0].isEmissive());
  EXPECT_TRUE(dark.textures.empty());
}

TEST(GltfTexturing, ExtensionsRequiredAndUsed) {
  const fs::path dir = scratch("extensions");
  const std::string material = R"({"pbrMetallicRoughness": {"metallicFactor": 0}})";
  expectError([&] {
    loadScene(writeQuad(dir, material, "", R"("extensionsUsed": ["KHR_materials_anisotropy"], "extensionsRequired": ["KHR_materials_anisotropy"],)"));
  }, {"quad.gltf", "requires", "KHR_materials_anisotropy"});
  // The layers this loader reads may be required.
  loadScene(writeQuad(dir, material, "",
                      R"("extensionsUsed": ["KHR_materials_sheen", "KHR_materials_clearcoat", "KHR_materials_specular"],
                         "extensionsRequired": ["KHR_materials_sheen", "KHR_materials_clearcoat", "KHR_materials_specular"],)"));
  const std::string log = logOf([&] {
    loadScene(writeQuad(dir, material, "",
                        R"("extensionsUsed": ["KHR_materials_anisotropy", "KHR_materials_iridescence", "KHR_materials_sheen", "KHR_texture_transform"],)"));
  });
  EXPECT_EQ(occurrences(log, "ignoring glTF extension"), 1u) << log;
  EXPECT_NE(log.find("KHR_materials_anisotropy, KHR_materials_iridescence"), std::string::npos) << log;
  EXPECT_EQ(log.find("KHR_texture_transform"), std::string::npos) << log;
  EXPECT_EQ(log.find("KHR_materials_sheen"), std::string::npos) << log;
}

// KHR_materials_specular, _clearcoat and _sheen: the factors make a GltfPbrBsdf (gltfPbrFromInputs,
// KHR_materials_ior's ior included); the textures make it per hit, each slot with its channel,
// decoding, texCoord and transform; Material::bsdf keeps the factors × each texture's mean.
TEST(GltfTexturing, LayerExtensionsFactorsAndTexturesPerHit) {
  const fs::path dir = scratch("layers");
  const Scene factors = loadScene(writeQuad(dir, R"({"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.5, 0.3, 1],
      "metallicFactor": 0.25, "roughnessFactor": 0.6}, "extensions": {
      "KHR_materials_ior": {"ior": 2.0},
      "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1, 0.5, 0.25]},
      "KHR_materials_clearcoat": {"clearcoatFactor": 0.7, "clearcoatRoughnessFactor": 0.2},
      "KHR_materials_sheen": {"sheenColorFactor": [0.3, 0.2, 0.1], "sheenRoughnessFactor": 0.4}}})"));
  const GltfPbrBsdf expected = gltfPbrFromInputs({.baseColor = Rgb(0.9f, 0.5f, 0.3f), .metallic = 0.25f,
                                                  .roughness = 0.6f, .ior = 2.0f, .specular = 0.5f,
                                                  .specularColor = Rgb(1.0f, 0.5f, 0.25f), .clearcoat = 0.7f,
                                                  .clearcoatRoughness = 0.2f, .sheenColor = Rgb(0.3f, 0.2f, 0.1f),
                                                  .sheenRoughness = 0.4f});
  const auto& got = std::get<GltfPbrBsdf>(factors.materials[0].bsdf);
  EXPECT_VEC3_NEAR(got.f0, expected.f0, kTight);
  EXPECT_NEAR(got.f90, expected.f90, kTight);
  EXPECT_VEC3_NEAR(got.diffuse, expected.diffuse, kTight);
  EXPECT_NEAR(got.clearcoat, 0.7f, kTight);
  EXPECT_NEAR(got.clearcoatAlpha, 0.04f, kTight);
  EXPECT_VEC3_NEAR(got.sheenColor, Rgb(0.3f, 0.2f, 0.1f), kTight);
  EXPECT_NEAR(got.sheenRoughness, 0.4f, kTight);
  EXPECT_FALSE(factors.materials[0].layers.any());

  // Textures (the 4×4 RGB test image, no alpha channel: the A slots stay at their factor).
  const Scene textured = loadScene(writeQuad(dir, R"({"pbrMetallicRoughness": {"metallicFactor": 0}, "extensions": {
      "KHR_materials_specular": {"specularColorTexture": {"index": 0}, "specularTexture": {"index": 0}},
      "KHR_materials_clearcoat": {"clearcoatFactor": 1, "clearcoatTexture": {"index": 0},
                                  "clearcoatRoughnessFactor": 1, "clearcoatRoughnessTexture": {"index": 0, "texCoord": 1}},
      "KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1], "sheenColorTexture": {"index": 0,
          "extensions": {"KHR_texture_transform": {"offset": [0.5, 0]}}}}}})",
      R"(, "TEXCOORD_1": 2)", "", kNearest));
  const Material& material = textured.materials[0];
  ASSERT_TRUE(material.layers.any());
  EXPECT_LT(material.layers.texture[PbrLayerMaps::kSpecular], 0);  // no alpha: 1 everywhere
  EXPECT_EQ(material.layers.mapping[PbrLayerMaps::kClearcoatRoughness].uvSet, 1);
  for (const Vec2 p : {Vec2(0.3f, 0.1f), Vec2(0.9f, 0.6f), Vec2(0.1f, 0.8f)}) {
    const int x = wrappedTexel(p.x, "repeat"), y = wrappedTexel(1.0f - p.y, "repeat");
    // TEXCOORD_1 is TEXCOORD_0 / 2; the sheen's transform moves u by half the image.
    const int x1 = wrappedTexel(0.5f * p.x, "repeat"), y1 = wrappedTexel(0.5f * (1.0f - p.y), "repeat");
    const int xs = wrappedTexel(p.x + 0.5f, "repeat");
    const GltfPbrBsdf want = gltfPbrFromInputs({.baseColor = Rgb(1.0f), .metallic = 0.0f, .roughness = 1.0f,
                                                .specularColor = texelLinear(x, y), .clearcoat = texelRaw(x, y).r,
                                                .clearcoatRoughness = texelRaw(x1, y1).g,
                                                .sheenColor = texelLinear(xs, y), .sheenRoughness = 0.0f});
    const SurfaceHit hit = p.x >= p.y ? surfaceAt(textured, 0, 0, Vec2(p.x - p.y, p.y)) : surfaceAt(textured, 0, 1, Vec2(p.x, p.y - p.x));
    const GltfPbrBsdf at = std::get<GltfPbrBsdf>(bsdfAt(textured, hit));
    EXPECT_VEC3_NEAR(at.f0, want.f0, kTight);
    EXPECT_NEAR(at.clearcoat, want.clearcoat, kTight);
    EXPECT_NEAR(at.clearcoatAlpha, want.clearcoatAlpha, kTight);
    EXPECT_VEC3_NEAR(at.sheenColor, want.sheenColor, kTight);
  }
  // A metallic-roughness texture on a layered material keeps the layers at every hit.
  const Scene withMr = loadScene(writeQuad(dir, R"({"pbrMetallicRoughness": {"metallicFactor": 0.5, "roughnessFactor": 0.8,
      "metallicRoughnessTexture": {"index": 0}}, "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 0.6}}})",
      "", "", kNearest));
  {
    const Vec2 p(0.3f, 0.1f);
    const Rgb t = texelRaw(wrappedTexel(p.x, "repeat"), wrappedTexel(1.0f - p.y, "repeat"));
    const GltfPbrBsdf at = std::get<GltfPbrBsdf>(bsdfAt(withMr, surfaceAt(withMr, 0, 0, Vec2(p.x - p.y, p.y))));
    EXPECT_NEAR(at.clearcoat, 0.6f, kTight);
    EXPECT_NEAR(at.alpha, ggxAlphaFromRoughness(0.8f * t.g), kTight);
  }
  // Material::bsdf: the factors × each texture's mean (the clearcoat's R mean here).
  float meanR = 0.0f;
  for (int x = 0; x < kSide; ++x)
    for (int y = 0; y < kSide; ++y) meanR += texelRaw(x, y).r / float(kSide * kSide);
  EXPECT_NEAR(std::get<GltfPbrBsdf>(material.bsdf).clearcoat, meanR, kTight);
}

TEST(GltfTexturing, LayerExtensionErrorsNameTheMaterial) {
  const fs::path dir = scratch("layer_errors");
  expectError([&] {
    loadScene(writeQuad(dir, R"({"name": "velvet", "extensions": {"KHR_materials_sheen": {"sheenColorTexture": {"index": 4}}}})"));
  }, {"quad.gltf", "material 'velvet'", "sheenColorTexture", "texture 4"});
  expectError([&] {
    loadScene(writeQuad(dir, R"({"name": "lacquer", "extensions": {"KHR_materials_clearcoat": {"clearcoatTexture": {"index": 0, "texCoord": 1}}}})"));
  }, {"quad.gltf", "mesh 'quad'", "material 'lacquer'", "TEXCOORD_1"});
  expectError([&] {
    loadScene(writeQuad(dir, R"({"name": "lacquer", "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1.5}}})"));
  }, {"quad.gltf", "material 'lacquer'", "clearcoatFactor", "[0, 1]"});
  expectError([&] {
    loadScene(writeQuad(dir, R"({"name": "velvet", "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1, 2]}}})"));
  }, {"quad.gltf", "material 'velvet'", "sheenColorFactor"});
  expectError([&] {
    loadScene(writeQuad(dir, R"({"name": "tinted", "extensions": {"KHR_materials_specular": {"specularTexture": {"texCoord": 0}}}})"));
  }, {"quad.gltf", "material 'tinted'", "specularTexture", "index"});
  const std::string log = logOf([&] {
    loadScene(writeQuad(dir, R"({"name": "lacquer", "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1,
        "clearcoatNormalTexture": {"index": 0}}}})"));
  });
  EXPECT_NE(log.find("clearcoatNormalTexture is not supported"), std::string::npos) << log;
}

TEST(GltfTexturing, BadTextureReferencesNameTheMaterialOrMesh) {
  const fs::path dir = scratch("bad");
  expectError([&] { loadScene(writeQuad(dir, R"({"name": "paint", "pbrMetallicRoughness": {"baseColorTexture": {"index": 3}}})")); },
              {"quad.gltf", "material 'paint'", "baseColorTexture", "texture 3"});
  expectError([&] { loadScene(writeQuad(dir, R"({"name": "glow", "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 4}})")); },
              {"quad.gltf", "material 'glow'", "emissiveTexture", "texture 4"});
  expectError([&] {
    loadScene(writeQuad(dir, R"({"name": "glow", "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 0, "texCoord": 1}})"));
  }, {"quad.gltf", "mesh 'quad'", "material 'glow'", "TEXCOORD_1"});
  expectError([&] { loadScene(writeQuad(dir, R"({"name": "paint", "occlusionTexture": {"index": 9}})")); },
              {"quad.gltf", "material 'paint'", "occlusionTexture", "texture 9"});
  expectError([&] {
    loadScene(writeQuad(dir, R"({"name": "paint", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}}})"));
  }, {"quad.gltf", "mesh 'quad'", "material 'paint'", "TEXCOORD_1"});
  expectError([&] {
    loadScene(writeQuad(dir, R"({"name": "paint", "normalTexture": {"index": 0, "texCoord": 2}})"));
  }, {"quad.gltf", "material 'paint'", "normalTexture", "TEXCOORD_2"});
  expectError([&] { loadScene(writeQuad(dir, R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}})", "", "", R"({"wrapS": 7})")); },
              {"quad.gltf", "sampler 0", "wrapS"});
}

}  // namespace
}  // namespace pl
