// Tests of the .plf file: XXH64 against reference vectors, a round trip of every field, and
// one test per way a file can be bad (each must be refused with a message naming the file
// and the problem, never a crash).
#include "plf/plf_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <random>

#include "core/error.h"
#include "core/hash.h"
#include "scene/scene.h"
#include "support/light_parameters.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

// --- A light field exercising every field ------------------------------------------------

/// A 2×2 PNG (75 bytes) of the repository's test data.
const std::string kCheckerPng = std::string(PLENOPTIC_TEST_DATA_DIR) + "/scene/textured/mat/checker.png";

LightField makeTestLightField() {
  LightField lf;
  Scene& s = lf.scene;
  s.sourcePath = "tests/handmade.json";
  Mesh quad;
  quad.name = "floor";
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
  quad.normals = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
  quad.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  quad.triangles = {{0, 2, 1}, {0, 3, 2}};
  quad.materials = {0, 0};
  Mesh mixed;
  mixed.name = "mixed";
  mixed.positions = {{0, 1, 0}, {1, 1, 0}, {0, 2, 0}, {2, 2, 2}, {3, 2, 2}};
  mixed.triangles = {{0, 1, 2}, {2, 3, 4}, {0, 3, 4}};
  mixed.materials = {1, 2, 3};
  s.meshes = {quad, mixed};

  Material lambert{"white", LambertBsdf{Rgb(0.7f, 0.6f, 0.5f)}, 0, Rgb(0.0f), false};
  Material mirror{"mirror", MirrorBsdf{Rgb(0.9f, 0.8f, 0.95f), true}, -1, Rgb(0.0f), false};
  Material phong{"phong", BlinnPhongBsdf{Rgb(0.3f, 0.2f, 0.1f), Rgb(0.2f, 0.25f, 0.3f), 123.5f}, -1,
                 Rgb(1.0f, 2.0f, 3.0f), true};
  Material ggx{"ggx", GgxBsdf{Rgb(0.1f), Rgb(0.04f, 0.05f, 0.06f), 0.33f}, -1, Rgb(17.0f, 12.0f, 4.0f), false};
  DielectricBsdf water{1.33f, Rgb(0.9f, 0.95f, 1.0f), 0.04f, false, Rgb(0.1f, 0.05f, 0.02f)};
  Material glass{"glass", water, -1, Rgb(0.0f), false};
  s.materials = {lambert, mirror, phong, ggx, glass};

  Texture texture;
  texture.path = "textures/checker.png";
  texture.image = Image(3, 2);
  for (size_t i = 0; i < texture.image.pixels.size(); ++i) texture.image.pixels[i] = Rgb(float(i), 0.5f, -1.0f);
  texture.average = Rgb(2.5f, 0.5f, -1.0f);
  // A texture from a PNG file: stored as the file's bytes, decoded on load.
  Texture png = loadTextureFile(kCheckerPng);
  png.finish(s.sourcePath);  // its average, as Scene::finalize computes it
  s.textures = {texture, png};

  s.lights = {PointLight{{1, 2, 3}, {4, 5, 6}}, SpotLight{{0, 5, 0}, {0, -1, 0}, {7, 8, 9}, 0.2f, 0.4f},
              DirectionalLight{{0.6f, -0.8f, 0.0f}, {1.5f, 2.5f, 3.5f}}};
  CameraDesc front;
  front.name = "front";
  front.eye = {0.5f, 0.5f, 3.0f};
  front.target = {0.5f, 0.5f, 0.0f};
  front.fovYDegrees = 35.0f;
  CameraDesc lens = front;
  lens.name = "lens";
  lens.fNumber = 2.8f;
  lens.focusDistance = 3.0f;
  lens.focalLengthMm = 50.0f;
  lens.aspectRatio = 1.5f;
  s.cameras = {front, lens};
  s.environment.constant = Rgb(0.1f, 0.2f, 0.3f);
  LatLongMap sky;
  sky.image = Image(8, 4);
  for (size_t i = 0; i < sky.image.pixels.size(); ++i) sky.image.pixels[i] = Rgb(float(i), 1.0f, 0.5f * float(i));
  s.environment.map = std::make_shared<const EnvironmentMap>(sky, 2.5f, 30.0f);
  s.settings.width = 320;
  s.settings.spp = 1024;
  s.settings.camera = "lens";

  Chart diffuse;
  diffuse.material = 0;
  diffuse.kind = ChartKind::Diffuse;
  diffuse.origin = {0, 0, 1};
  diffuse.axisU = {1, 0, 0};
  diffuse.axisV = {0, 0, -1};
  diffuse.normal = {0, 1, 0};
  diffuse.tixelSize = 0.25f;
  diffuse.resU = 4;
  diffuse.resV = 4;
  diffuse.dirRes = 1;
  Chart mirrorChart = diffuse;
  mirrorChart.material = 1;
  mirrorChart.kind = ChartKind::Specular;
  mirrorChart.dirRes = 0;
  mirrorChart.firstTixel = 16;
  mirrorChart.firstValue = 16;
  Chart glossy = diffuse;
  glossy.material = 2;
  glossy.kind = ChartKind::Glossy;
  glossy.resU = 2;
  glossy.resV = 3;
  glossy.dirRes = 4;
  glossy.firstTixel = 32;
  glossy.firstValue = 16;
  lf.charts = {diffuse, mirrorChart, glossy};
  lf.triangleChart = {{0, 0}, {1, 2, 2}};
  lf.values.resize(16 + 2 * 3 * 16);
  for (size_t i = 0; i < lf.values.size(); ++i) lf.values[i] = Rgb(float(i), float(i) * 0.5f, 1.0f / float(i + 1));

  lf.settings.preset = "draft";
  lf.settings.tixelsPerUnit = 12.5f;
  lf.settings.maxTixelsPerChartSide = 33;
  lf.settings.tixelsAcrossScene = 21.5f;
  lf.settings.gatherDirections = 77;
  lf.settings.glossyDirRes = 6;
  lf.settings.tolerance = 2.5e-4f;
  lf.settings.maxIterations = 91;
  lf.settings.mirrorDepth = 3;
  lf.settings.areaLightSamples = 5;
  lf.settings.seed = 0x123456789abcdefull;
  lf.stats.seconds = 1.25;
  lf.stats.visibilitySeconds = 0.5;
  lf.stats.propagationSeconds = 0.625;
  lf.stats.iterations = 17;
  lf.stats.residual = 3.5e-5;
  lf.stats.tixels = 38;
  lf.stats.values = lf.values.size();
  lf.stats.visibilityRays = 123456789012ull;
  lf.stats.peakRssBytes = 987654321;
  lf.stats.reusedVisibility = true;
  return lf;
}

/// A fresh directory per test, removed afterwards.
class PlfFileTest : public test_support::TempDirTest {
 protected:
  /// path(name); the tests' own local variables are called `path`.
  std::string file(const std::string& name) const { return path(name); }

  static std::vector<unsigned char> readBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  static void writeBytes(const std::string& path, const std::vector<unsigned char>& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  }

  /// Expects reading `path` to throw pl::Error whose message contains every fragment.
  static void expectRefused(const std::string& path, const std::vector<std::string>& fragments) {
    for (int mode = 0; mode < 2; ++mode) {  // both the full reader and the info reader
      try {
        if (mode == 0)
          readLightField(path);
        else
          readLightFieldInfo(path);
        ADD_FAILURE() << "reading " << path << " succeeded, expected: " << fragments.front();
      } catch (const Error& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(path), std::string::npos) << message;
        for (const std::string& fragment : fragments)
          EXPECT_NE(message.find(fragment), std::string::npos) << "'" << fragment << "' not in: " << message;
      }
    }
  }

  // Layout facts from plf_file.h, for locating and re-signing sections in a valid file.
  struct Section {
    std::string id;
    uint64_t offset, size;
  };
  static std::vector<Section> sections(const std::vector<unsigned char>& bytes) {
    uint32_t count;
    std::memcpy(&count, bytes.data() + 12, 4);
    std::vector<Section> result;
    for (uint32_t i = 0; i < count; ++i) {
      const unsigned char* e = bytes.data() + kPlfHeaderSize + i * kPlfSectionEntrySize;
      Section s{std::string(reinterpret_cast<const char*>(e), 4), 0, 0};
      std::memcpy(&s.offset, e + 8, 8);
      std::memcpy(&s.size, e + 16, 8);
      result.push_back(s);
    }
    return result;
  }
  /// Recomputes the checksums of every section and of the header after a deliberate edit,
  /// so the reader's structural checks (not its checksums) must catch the edit.
  static void resign(std::vector<unsigned char>& bytes) {
    const auto table = sections(bytes);
    for (size_t i = 0; i < table.size(); ++i) {
      if (table[i].size > bytes.size() || table[i].offset > bytes.size() - table[i].size) continue;  // edited size
      const uint64_t hash = xxh64(bytes.data() + table[i].offset, table[i].size);
      std::memcpy(bytes.data() + kPlfHeaderSize + i * kPlfSectionEntrySize + 32, &hash, 8);
    }
    Xxh64Stream stream;
    stream.update(bytes.data(), 24);
    stream.update(bytes.data() + kPlfHeaderSize, table.size() * kPlfSectionEntrySize);
    const uint64_t hash = stream.digest();
    std::memcpy(bytes.data() + 24, &hash, 8);
  }
  /// Writes to `badName` the file at `goodPath` with chart record `chart`'s CHRT kind byte
  /// given bits `set` and cleared of bits `clear` (re-signed), and expects it refused with
  /// `fragments`.
  void expectKindByteRefused(const std::string& goodPath, uint64_t chart, uint8_t set, uint8_t clear,
                             const std::string& badName, const std::vector<std::string>& fragments) const {
    auto bytes = readBytes(goodPath);
    constexpr uint64_t kChartRecord = 4 + 1 + 48 + 4 + 12 + 16;
    static_assert(kChartRecord == 85, "the CHRT record size");
    const uint64_t kindAt = sections(bytes)[1].offset + 8 + chart * kChartRecord + 4;  // after the count and material
    bytes[kindAt] = uint8_t((bytes[kindAt] | set) & ~clear);
    resign(bytes);
    writeBytes(file(badName), bytes);
    expectRefused(file(badName), fragments);
  }

  /// The valid file at `path`, whose scene section must be larger than `plainSceneSize` (an
  /// optional block is there), with the byte `fromEnd` bytes before the end of that section set
  /// to `value` and re-signed, written as `name`: the reader must refuse it with `fragments`.
  /// The SCNE section's size in `lf` written as it is (plain.plf): the layout a scene without
  /// an optional block has, for expectRefusedWithSceneByte.
  uint64_t sceneSectionSize(const LightField& lf) const {
    writeLightField(file("plain.plf"), lf);
    return sections(readBytes(file("plain.plf")))[0].size;
  }
  void expectRefusedWithSceneByte(const std::string& path, uint64_t plainSceneSize, uint64_t fromEnd, uint8_t value,
                                  const std::string& name, const std::vector<std::string>& fragments) const {
    auto bytes = readBytes(path);
    const auto table = sections(bytes);
    EXPECT_GT(table[0].size, plainSceneSize);
    bytes[table[0].offset + table[0].size - fromEnd] = value;
    resign(bytes);
    writeBytes(file(name), bytes);
    expectRefused(file(name), fragments);
  }

  fs::path dir_;
};

using test_support::lightParameterFloats;

void expectSameRgb(const Rgb& a, const Rgb& b) {
  EXPECT_EQ(a.r, b.r);
  EXPECT_EQ(a.g, b.g);
  EXPECT_EQ(a.b, b.b);
}

// Every light type (light/lights.h) is stored through its parameters() hook: one of each,
// parameters all different, comes back as the same type with the same parameters, bit for bit.
TEST_F(PlfFileTest, EveryLightTypeRoundTrips) {
  LightField original = makeTestLightField();
  original.scene.lights.clear();
  original.sunMaskLightCount = 0;
  original.sunMasks.clear();
  for (size_t index = 0; index < std::variant_size_v<Light>; ++index)
    original.scene.lights.push_back(test_support::lightWithDistinctParameters(index));
  const std::string path = file("lights.plf");
  writeLightField(path, original);
  const LightField copy = readLightField(path);
  ASSERT_EQ(copy.scene.lights.size(), original.scene.lights.size());
  for (size_t i = 0; i < original.scene.lights.size(); ++i) {
    EXPECT_EQ(copy.scene.lights[i].index(), i);
    EXPECT_EQ(lightParameterFloats(copy.scene.lights[i]), lightParameterFloats(original.scene.lights[i]));
  }
}

TEST_F(PlfFileTest, RoundTripPreservesEveryField) {
  const LightField original = makeTestLightField();
  const std::string path = file("round.plf");
  writeLightField(path, original);
  const LightField copy = readLightField(path);

  const Scene &a = original.scene, &b = copy.scene;
  EXPECT_EQ(b.sourcePath, a.sourcePath);
  ASSERT_EQ(b.meshes.size(), a.meshes.size());
  for (size_t m = 0; m < a.meshes.size(); ++m) {
    EXPECT_EQ(b.meshes[m].name, a.meshes[m].name);
    EXPECT_EQ(b.meshes[m].positions, a.meshes[m].positions);
    EXPECT_GT(b.meshes[m].positions.capacity(), b.meshes[m].positions.size()) << "Embree padding";
    EXPECT_EQ(b.meshes[m].normals, a.meshes[m].normals);
    EXPECT_EQ(b.meshes[m].uvs, a.meshes[m].uvs);
    EXPECT_EQ(b.meshes[m].triangles, a.meshes[m].triangles);
    EXPECT_EQ(b.meshes[m].materials, a.meshes[m].materials);
  }
  ASSERT_EQ(b.materials.size(), a.materials.size());
  for (size_t i = 0; i < a.materials.size(); ++i) {
    const Material &ma = a.materials[i], &mb = b.materials[i];
    EXPECT_EQ(mb.name, ma.name);
    ASSERT_EQ(mb.bsdf.index(), ma.bsdf.index());
    EXPECT_EQ(mb.albedoTexture, ma.albedoTexture);
    expectSameRgb(mb.emission, ma.emission);
    EXPECT_EQ(mb.twoSidedEmission, ma.twoSidedEmission);
  }
  EXPECT_EQ(std::get<LambertBsdf>(b.materials[0].bsdf).albedo, std::get<LambertBsdf>(a.materials[0].bsdf).albedo);
  const auto &mirrorA = std::get<MirrorBsdf>(a.materials[1].bsdf), &mirrorB = std::get<MirrorBsdf>(b.materials[1].bsdf);
  EXPECT_EQ(mirrorB.reflectance, mirrorA.reflectance);
  EXPECT_EQ(mirrorB.fresnel, mirrorA.fresnel);
  const auto &phongA = std::get<BlinnPhongBsdf>(a.materials[2].bsdf),
             &phongB = std::get<BlinnPhongBsdf>(b.materials[2].bsdf);
  EXPECT_EQ(phongB.diffuse, phongA.diffuse);
  EXPECT_EQ(phongB.specular, phongA.specular);
  EXPECT_EQ(phongB.exponent, phongA.exponent);
  const auto &ggxA = std::get<GgxBsdf>(a.materials[3].bsdf), &ggxB = std::get<GgxBsdf>(b.materials[3].bsdf);
  EXPECT_EQ(ggxB.diffuse, ggxA.diffuse);
  EXPECT_EQ(ggxB.f0, ggxA.f0);
  EXPECT_EQ(ggxB.alpha, ggxA.alpha);
  const auto &glassA = std::get<DielectricBsdf>(a.materials[4].bsdf),
             &glassB = std::get<DielectricBsdf>(b.materials[4].bsdf);
  EXPECT_EQ(glassB.ior, glassA.ior);
  EXPECT_EQ(glassB.transmittance, glassA.transmittance);
  EXPECT_EQ(glassB.alpha, glassA.alpha);
  EXPECT_EQ(glassB.thin, glassA.thin);
  EXPECT_EQ(glassB.absorption, glassA.absorption);

  ASSERT_EQ(b.textures.size(), 2u);
  EXPECT_EQ(b.textures[0].path, a.textures[0].path);
  EXPECT_EQ(b.textures[0].image.width, 3);
  EXPECT_EQ(b.textures[0].image.height, 2);
  EXPECT_EQ(b.textures[0].image.pixels, a.textures[0].image.pixels);
  EXPECT_EQ(b.textures[0].average, a.textures[0].average);
  EXPECT_FALSE(b.textures[0].encoded);  // float pixels stay float pixels
  // The PNG texture: the file's bytes, and the pixels they decode to, exactly.
  EXPECT_EQ(b.textures[1].path, a.textures[1].path);
  ASSERT_TRUE(b.textures[1].encoded);
  EXPECT_EQ(*b.textures[1].encoded, readBytes(kCheckerPng));
  EXPECT_EQ(b.textures[1].image.width, 2);
  EXPECT_EQ(b.textures[1].image.pixels, a.textures[1].image.pixels);
  EXPECT_EQ(b.textures[1].average, a.textures[1].average);

  ASSERT_EQ(b.lights.size(), 3u);
  for (size_t i = 0; i < a.lights.size(); ++i) {
    EXPECT_EQ(b.lights[i].index(), a.lights[i].index());
    EXPECT_EQ(lightParameterFloats(b.lights[i]), lightParameterFloats(a.lights[i]));
  }

  ASSERT_EQ(b.cameras.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const CameraDesc &ca = a.cameras[i], &cb = b.cameras[i];
    EXPECT_EQ(cb.name, ca.name);
    EXPECT_EQ(cb.eye, ca.eye);
    EXPECT_EQ(cb.target, ca.target);
    EXPECT_EQ(cb.up, ca.up);
    EXPECT_EQ(cb.fovYDegrees, ca.fovYDegrees);
    EXPECT_EQ(cb.fNumber, ca.fNumber);
    EXPECT_EQ(cb.focusDistance, ca.focusDistance);
    EXPECT_EQ(cb.focalLengthMm, ca.focalLengthMm);
    EXPECT_EQ(cb.aspectRatio, ca.aspectRatio);
  }
  EXPECT_EQ(b.environment.constant, a.environment.constant);
  ASSERT_TRUE(b.environment.map);
  EXPECT_EQ(b.environment.map->map().image.pixels, a.environment.map->map().image.pixels);
  EXPECT_EQ(b.environment.map->map().width(), 8);
  EXPECT_EQ(b.environment.map->scale(), 2.5f);
  EXPECT_EQ(b.environment.map->rotationDegrees(), 30.0f);
  for (const Vec3& dir : {Vec3(0, 1, 0), glm::normalize(Vec3(1, -0.3f, 0.4f))})
    EXPECT_EQ(b.environment.radiance(dir), a.environment.radiance(dir));
  EXPECT_EQ(b.settings.width, a.settings.width);
  EXPECT_EQ(b.settings.height, a.settings.height);
  EXPECT_FALSE(b.settings.height.has_value());
  EXPECT_EQ(b.settings.spp, a.settings.spp);
  EXPECT_EQ(b.settings.camera, a.settings.camera);

  ASSERT_EQ(copy.charts.size(), original.charts.size());
  for (size_t i = 0; i < original.charts.size(); ++i) {
    const Chart &ca = original.charts[i], &cb = copy.charts[i];
    EXPECT_EQ(cb.material, ca.material);
    EXPECT_EQ(cb.kind, ca.kind);
    EXPECT_EQ(cb.origin, ca.origin);
    EXPECT_EQ(cb.axisU, ca.axisU);
    EXPECT_EQ(cb.axisV, ca.axisV);
    EXPECT_EQ(cb.normal, ca.normal);
    EXPECT_EQ(cb.tixelSize, ca.tixelSize);
    EXPECT_EQ(cb.resU, ca.resU);
    EXPECT_EQ(cb.resV, ca.resV);
    EXPECT_EQ(cb.dirRes, ca.dirRes);
    EXPECT_EQ(cb.firstTixel, ca.firstTixel);
    EXPECT_EQ(cb.firstValue, ca.firstValue);
    EXPECT_EQ(cb.sides, ca.sides);
    EXPECT_EQ(cb.isBack, ca.isBack);
  }
  EXPECT_EQ(copy.triangleChart, original.triangleChart);
  EXPECT_EQ(copy.values, original.values);  // bit-exact: float32 stored as is

  const BakeSettings &sa2 = original.settings, &sb2 = copy.settings;
  EXPECT_EQ(sb2.preset, sa2.preset);
  EXPECT_EQ(sb2.tixelsPerUnit, sa2.tixelsPerUnit);
  EXPECT_EQ(sb2.maxTixelsPerChartSide, sa2.maxTixelsPerChartSide);
  EXPECT_EQ(sb2.tixelsAcrossScene, sa2.tixelsAcrossScene);
  EXPECT_EQ(sb2.gatherDirections, sa2.gatherDirections);
  EXPECT_EQ(sb2.glossyDirRes, sa2.glossyDirRes);
  EXPECT_EQ(sb2.tolerance, sa2.tolerance);
  EXPECT_EQ(sb2.maxIterations, sa2.maxIterations);
  EXPECT_EQ(sb2.mirrorDepth, sa2.mirrorDepth);
  EXPECT_EQ(sb2.areaLightSamples, sa2.areaLightSamples);
  EXPECT_EQ(sb2.seed, sa2.seed);
  const BakeStats &ta = original.stats, &tb = copy.stats;
  EXPECT_EQ(tb.seconds, ta.seconds);
  EXPECT_EQ(tb.visibilitySeconds, ta.visibilitySeconds);
  EXPECT_EQ(tb.propagationSeconds, ta.propagationSeconds);
  EXPECT_EQ(tb.iterations, ta.iterations);
  EXPECT_EQ(tb.residual, ta.residual);
  EXPECT_EQ(tb.tixels, ta.tixels);
  EXPECT_EQ(tb.values, ta.values);
  EXPECT_EQ(tb.visibilityRays, ta.visibilityRays);
  EXPECT_EQ(tb.peakRssBytes, ta.peakRssBytes);
  EXPECT_EQ(tb.reusedVisibility, ta.reusedVisibility);
}

// The glTF model (version 6: its dielectric Fresnel after the other parameters) round-trips
// every field, and a version-5 file's glTF model (written by the version-5 writer: a quad of
// {"type": "ggx", "diffuse": [0.6, 0.3, 0.2], "f0": 0.3, "roughness": 0.5, "f90": 0.8}, draft
// at the smallest sizes) reads with the diffuse coupled to the whole lobe, what it meant then.
TEST_F(PlfFileTest, GltfModelRoundTripsAndVersion5MeansTheLobesOwnFresnel) {
  LightField lf = makeTestLightField();
  const GltfPbrBsdf half = gltfPbrFromInputs({.baseColor = Rgb(0.9f, 0.6f, 0.3f), .metallic = 0.5f, .roughness = 0.4f,
                                              .specular = 0.7f, .clearcoat = 0.25f, .sheenColor = Rgb(0.1f)});
  ASSERT_NE(half.dielectricF0, half.f0);
  lf.scene.materials[3].bsdf = half;
  const std::string path = file("gltf-pbr.plf");
  writeLightField(path, lf);
  const LightField copy = readLightField(path);
  const auto& back = std::get<GltfPbrBsdf>(copy.scene.materials[3].bsdf);
  std::vector<float> want, got;
  GltfPbrBsdf::parameters(half, [&](const auto& f) {
    if constexpr (std::is_same_v<std::decay_t<decltype(f)>, Rgb>) want.insert(want.end(), {f.r, f.g, f.b});
    else want.push_back(float(f));
  });
  GltfPbrBsdf::parameters(back, [&](const auto& f) {
    if constexpr (std::is_same_v<std::decay_t<decltype(f)>, Rgb>) got.insert(got.end(), {f.r, f.g, f.b});
    else got.push_back(float(f));
  });
  EXPECT_EQ(got, want);

  const std::string v5 = std::string(PLENOPTIC_TEST_DATA_DIR) + "/render/gltf-pbr-v5.plf";
  EXPECT_EQ(readLightFieldInfo(v5).version, 5u);
  const LightField old = readLightField(v5);
  const auto it = std::find_if(old.scene.materials.begin(), old.scene.materials.end(),
                               [](const Material& m) { return std::holds_alternative<GltfPbrBsdf>(m.bsdf); });
  ASSERT_NE(it, old.scene.materials.end());
  const auto& coupled = std::get<GltfPbrBsdf>(it->bsdf);
  EXPECT_EQ(coupled.f0, Rgb(0.3f));
  EXPECT_EQ(coupled.f90, 0.8f);
  EXPECT_EQ(coupled.dielectricF0, coupled.f0);
  EXPECT_EQ(coupled.dielectricF90, coupled.f90);
  EXPECT_FLOAT_EQ(coupled.alpha, 0.25f);
  EXPECT_EQ(coupled.diffuse, Rgb(0.6f, 0.3f, 0.2f));
  // Rewritten, it is a current file of the same model and values.
  writeLightField(file("gltf-pbr-v6.plf"), old);
  const LightField again = readLightField(file("gltf-pbr-v6.plf"));
  EXPECT_EQ(readLightFieldInfo(file("gltf-pbr-v6.plf")).version, kPlfVersion);
  EXPECT_EQ(std::get<GltfPbrBsdf>(again.scene.materials[size_t(it - old.scene.materials.begin())].bsdf).dielectricF0,
            coupled.f0);
  EXPECT_EQ(again.values, old.values);
}

TEST_F(PlfFileTest, InfoSummarisesWithoutLoadingValues) {
  const LightField lf = makeTestLightField();
  const std::string path = file("info.plf");
  writeLightField(path, lf);
  const PlfInfo info = readLightFieldInfo(path);
  EXPECT_EQ(info.version, kPlfVersion);
  EXPECT_EQ(info.fileBytes, fs::file_size(path));
  EXPECT_TRUE(info.checksumsVerified);
  EXPECT_EQ(info.sceneSource, "tests/handmade.json");
  EXPECT_EQ(info.meshes, 2u);
  EXPECT_EQ(info.triangles, 5u);
  EXPECT_EQ(info.vertices, 9u);
  EXPECT_EQ(info.materials, 5u);
  EXPECT_EQ(info.materialModels, (std::vector<std::string>{"lambert", "mirror", "blinn-phong", "ggx", "rough-dielectric"}));
  EXPECT_EQ(info.textures, 2u);
  EXPECT_EQ(info.lights, 3u);
  EXPECT_EQ(info.cameraNames, (std::vector<std::string>{"front", "lens"}));
  EXPECT_EQ(info.environmentMapWidth, 8u);
  EXPECT_EQ(info.environmentMapHeight, 4u);
  EXPECT_EQ(info.environmentMapScale, 2.5f);
  EXPECT_EQ(info.charts, 3u);
  EXPECT_EQ(info.diffuseCharts, 1u);
  EXPECT_EQ(info.glossyCharts, 1u);
  EXPECT_EQ(info.specularCharts, 1u);
  EXPECT_EQ(info.tixels, 16u + 16u + 6u);
  EXPECT_EQ(info.values, lf.values.size());
  EXPECT_EQ(info.settings.preset, "draft");
  EXPECT_EQ(info.stats.iterations, 17u);
  ASSERT_EQ(info.sections.size(), 5u);
  uint64_t previousEnd = kPlfHeaderSize + 5 * kPlfSectionEntrySize;
  for (const PlfSectionInfo& s : info.sections) {
    EXPECT_EQ(s.offset % 64, 0u) << s.id;
    EXPECT_GE(s.offset, previousEnd) << s.id;
    previousEnd = s.offset + s.storedSize;
  }
  EXPECT_EQ(info.sections[3].id, "VALS");
  EXPECT_EQ(info.sections[3].storedSize, lf.values.size() * 12);
  EXPECT_EQ(previousEnd, info.fileBytes);
}

TEST_F(PlfFileTest, InfoVerifiesLargeSectionsChunkByChunk) {
  // 200 000 values = 2.4 MB: the info reader checksums VALS in 1 MiB chunks (three here), so
  // a flipped bit in the last chunk must still be found, and --no-verify must skip it.
  LightField lf = makeTestLightField();
  lf.charts[2].resU = 2;
  lf.charts[2].resV = 3;
  lf.values.resize(200000, Rgb(0.25f));
  const std::string path = file("large.plf");
  writeLightField(path, lf);
  EXPECT_TRUE(readLightFieldInfo(path).checksumsVerified);
  auto bytes = readBytes(path);
  const Section values = sections(bytes)[3];
  ASSERT_EQ(values.id, "VALS");
  ASSERT_GT(values.size, uint64_t(2) << 20);
  bytes[values.offset + values.size - 5] ^= 0x80;
  writeBytes(path, bytes);
  expectRefused(path, {"checksum mismatch", "(VALS)"});
  const PlfInfo unverified = readLightFieldInfo(path, false);
  EXPECT_FALSE(unverified.checksumsVerified);
  EXPECT_EQ(unverified.values, 200000u);
}

TEST_F(PlfFileTest, OverwritesAtomicallyAndLeavesNoTemporaryFiles) {
  const std::string path = file("out.plf");
  writeBytes(path, {'o', 'l', 'd'});
  writeLightField(path, makeTestLightField());
  EXPECT_NO_THROW(readLightField(path));
  EXPECT_EQ(fileCount(), 1u);
}

TEST_F(PlfFileTest, FailedWriteRemovesItsTemporaryFile) {
  // A directory where the file should go: refused (the atomic writer, core/file_io.h, checks
  // before writing; that a temporary is removed after a failure half-way is tested in
  // core_test), the error names the target, and nothing is left behind.
  const std::string path = file("taken.plf");
  fs::create_directories(path);
  try {
    writeLightField(path, makeTestLightField());
    ADD_FAILURE() << "writing over a directory succeeded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_EQ(fileCount(), 1u) << "only the directory itself may remain";
  EXPECT_THROW(writeLightField(file("no/such/dir/x.plf"), makeTestLightField()), Error);
}

TEST_F(PlfFileTest, RefusesMissingFile) { expectRefused(file("absent.plf"), {"cannot open", "No such file"}); }

TEST_F(PlfFileTest, RefusesEmptyFile) {
  writeBytes(file("empty.plf"), {});
  expectRefused(file("empty.plf"), {"empty file"});
}

TEST_F(PlfFileTest, RefusesWrongMagic) {
  writeBytes(file("text.plf"), {'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd', '\n'});
  expectRefused(file("text.plf"), {"not a plenoptic light field"});
  const std::string path = file("flipped.plf");
  writeLightField(path, makeTestLightField());
  auto bytes = readBytes(path);
  bytes[1] ^= 0x20;  // "PlF"
  writeBytes(path, bytes);
  expectRefused(path, {"not a plenoptic light field"});
}

TEST_F(PlfFileTest, RefusesOtherVersionNamingBoth) {
  const std::string path = file("v7.plf");
  writeLightField(path, makeTestLightField());
  auto bytes = readBytes(path);
  const uint32_t version = 7;
  std::memcpy(bytes.data() + 8, &version, 4);
  writeBytes(path, bytes);
  expectRefused(path, {"unsupported .plf format version 7", "reads versions 1 to " + std::to_string(kPlfVersion)});
}

TEST_F(PlfFileTest, RefusesTruncationNamingTheSection) {
  const std::string path = file("whole.plf");
  writeLightField(path, makeTestLightField());
  const auto whole = readBytes(path);
  const auto table = sections(whole);
  struct Cut {
    uint64_t at;
    std::vector<std::string> fragments;
  };
  std::vector<Cut> cuts = {{3, {"truncated", "header"}},
                           {10, {"truncated", "header"}},
                           {31, {"truncated", "header"}},
                           {kPlfHeaderSize + 50, {"truncated", "section table"}}};
  for (const Section& s : table) {
    // Cut in the middle of each section and one byte before its end.
    const std::string expected = fmt::format("needs bytes [{}, {})", s.offset, s.offset + s.size);
    cuts.push_back({s.offset + s.size / 2, {"truncated", "section " + s.id, expected,
                                            fmt::format("of {} bytes present", s.size)}});
    cuts.push_back({s.offset + s.size - 1, {"truncated", "section " + s.id, expected}});
  }
  for (const Cut& cut : cuts) {
    SCOPED_TRACE(fmt::format("cut at {}", cut.at));
    const std::string cutPath = file(fmt::format("cut{}.plf", cut.at));
    writeBytes(cutPath, std::vector<unsigned char>(whole.begin(), whole.begin() + std::ptrdiff_t(cut.at)));
    expectRefused(cutPath, cut.fragments);
  }
  // Extra bytes appended are refused too: the header states the size.
  auto longer = whole;
  longer.push_back(0);
  writeBytes(file("longer.plf"), longer);
  expectRefused(file("longer.plf"), {"unexpected bytes after the end"});
}

TEST_F(PlfFileTest, RefusesAFlippedByteInEverySection) {
  const std::string path = file("good.plf");
  writeLightField(path, makeTestLightField());
  const auto good = readBytes(path);
  for (const Section& s : sections(good)) {
    for (uint64_t at : {s.offset, s.offset + s.size / 2, s.offset + s.size - 1}) {
      SCOPED_TRACE(fmt::format("{} byte {}", s.id, at));
      auto bad = good;
      bad[at] ^= 0x01;
      const std::string badPath = file("bad.plf");
      writeBytes(badPath, bad);
      expectRefused(badPath, {"checksum mismatch", "(" + s.id + ")"});
    }
  }
  // The header and the table are covered by the header hash …
  for (uint64_t at : {uint64_t(16), uint64_t(kPlfHeaderSize + 20), uint64_t(kPlfHeaderSize + 3 * kPlfSectionEntrySize + 33)}) {
    auto bad = good;
    bad[at] ^= 0x40;
    writeBytes(file("badheader.plf"), bad);
    expectRefused(file("badheader.plf"), {"corrupt header"});
  }
  // … and the padding between sections must be zero.
  // The table (5 entries) ends at byte 272 and the first section starts 64-byte aligned at
  // 320, so there is always padding right after the table.
  const auto table = sections(good);
  const uint64_t tableEnd = kPlfHeaderSize + table.size() * kPlfSectionEntrySize;
  ASSERT_GT(table[0].offset, tableEnd);
  auto bad = good;
  bad[tableEnd + 1] = 0xff;
  writeBytes(file("badpadding.plf"), bad);
  expectRefused(file("badpadding.plf"), {"padding"});
}

TEST_F(PlfFileTest, RefusesAbsurdCountsWithoutAllocating) {
  const std::string path = file("good.plf");
  writeLightField(path, makeTestLightField());
  const auto good = readBytes(path);
  const auto table = sections(good);

  // SCNE starts with the source path (u32 length + bytes), then the u64 mesh count. A count
  // of 2^60 meshes with valid checksums must be refused by the bounds check, not by
  // std::bad_alloc or a crash.
  {
    auto bad = good;
    const uint64_t meshCountAt = table[0].offset + 4 + std::strlen("tests/handmade.json");
    const uint64_t absurd = uint64_t(1) << 60;
    std::memcpy(bad.data() + meshCountAt, &absurd, 8);
    resign(bad);
    writeBytes(file("meshes.plf"), bad);
    expectRefused(file("meshes.plf"), {"corrupt scene section", "meshes", "bytes remain"});
  }
  // The same for the number of charts (first field of CHRT).
  {
    auto bad = good;
    const uint64_t absurd = ~uint64_t(0);
    std::memcpy(bad.data() + table[1].offset, &absurd, 8);
    resign(bad);
    writeBytes(file("charts.plf"), bad);
    expectRefused(file("charts.plf"), {"corrupt charts section", "charts", "bytes remain"});
  }
  // A section table entry claiming more bytes than the file holds.
  {
    auto bad = good;
    const uint64_t absurd = uint64_t(1) << 50;
    std::memcpy(bad.data() + kPlfHeaderSize + 3 * kPlfSectionEntrySize + 16, &absurd, 8);
    std::memcpy(bad.data() + kPlfHeaderSize + 3 * kPlfSectionEntrySize + 24, &absurd, 8);
    resign(bad);
    writeBytes(file("values.plf"), bad);
    expectRefused(file("values.plf"), {"section VALS", "outside"});
  }
  // A section count far beyond any real file.
  {
    auto bad = good;
    const uint32_t absurd = 1u << 30;
    std::memcpy(bad.data() + 12, &absurd, 4);
    writeBytes(file("count.plf"), bad);
    expectRefused(file("count.plf"), {"corrupt header", "sections"});
  }
}

TEST_F(PlfFileTest, RefusesACorruptEmbeddedImageEvenWithValidChecksums) {
  const std::string path = file("good.plf");
  writeLightField(path, makeTestLightField());
  const auto good = readBytes(path);
  const auto table = sections(good);
  const std::vector<unsigned char> png = readBytes(kCheckerPng);
  // The PNG's bytes lie in SCNE as they were in the file.
  const auto at = std::search(good.begin() + long(table[0].offset), good.begin() + long(table[0].offset + table[0].size),
                              png.begin(), png.end());
  ASSERT_NE(at, good.begin() + long(table[0].offset + table[0].size));
  const size_t pngAt = size_t(at - good.begin());
  auto expectLoadRefused = [&](const std::vector<unsigned char>& bad, const std::string& name,
                               const std::vector<std::string>& fragments) {
    writeBytes(file(name), bad);
    try {
      readLightField(file(name));
      ADD_FAILURE() << name << ": a corrupt embedded image was accepted";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(file(name)), std::string::npos) << message;
      for (const std::string& fragment : fragments)
        EXPECT_NE(message.find(fragment), std::string::npos) << "'" << fragment << "' not in: " << message;
    }
  };
  // Its image data damaged (the IDAT chunk's compressed bytes zeroed): a decoding error naming
  // the file and the texture, never a crash or garbage pixels.
  {
    auto bad = good;
    const auto idat = std::search(bad.begin() + long(pngAt), bad.begin() + long(pngAt + png.size()),
                                  std::begin("IDAT"), std::begin("IDAT") + 4);
    ASSERT_NE(idat, bad.begin() + long(pngAt + png.size()));
    std::fill(idat + 4, idat + 10, 0);
    resign(bad);
    expectLoadRefused(bad, "idat.plf", {"texture '" + kCheckerPng + "'", "embedded", "corrupt"});
  }
  // Its chunk structure cut (the last chunk's length made to run past the image's end).
  {
    auto bad = good;
    const uint32_t huge = 0x7fffffffu;
    std::memcpy(bad.data() + pngAt + png.size() - 12, &huge, 4);
    resign(bad);
    expectLoadRefused(bad, "chunk.plf", {"truncated PNG"});
  }
  // An unknown storage byte (the byte before the u64 size of the embedded file).
  {
    auto bad = good;
    bad[pngAt - 9] = 7;
    resign(bad);
    writeBytes(file("storage.plf"), bad);
    expectRefused(file("storage.plf"), {"corrupt scene section", "unknown storage 7"});
  }
}

TEST_F(PlfFileTest, RefusesOutOfRangeIndicesEvenWithValidChecksums) {
  const std::string path = file("good.plf");
  writeLightField(path, makeTestLightField());
  const auto good = readBytes(path);
  const auto table = sections(good);
  // TRCH: u64 mesh count, u64 triangle count of mesh 0, then its u32 chart indices.
  auto bad = good;
  const uint32_t chart = 3;  // only charts 0–2 exist
  std::memcpy(bad.data() + table[2].offset + 16, &chart, 4);
  resign(bad);
  writeBytes(file("trch.plf"), bad);
  try {
    readLightField(file("trch.plf"));
    ADD_FAILURE() << "out-of-range chart index accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("maps to chart 3 of 3"), std::string::npos) << e.what();
  }
  // CHRT: the glossy chart's firstValue moved past the end of the values.
  bad = good;
  const uint64_t chartRecord = 4 + 1 + 48 + 4 + 12 + 16;
  const uint64_t firstValueAt = table[1].offset + 8 + 2 * chartRecord + chartRecord - 8;
  const uint64_t firstValue = 1000;
  std::memcpy(bad.data() + firstValueAt, &firstValue, 8);
  resign(bad);
  writeBytes(file("chrt.plf"), bad);
  try {
    readLightField(file("chrt.plf"));
    ADD_FAILURE() << "out-of-range chart values accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("chart 2 needs values"), std::string::npos) << e.what();
  }
}

// makeTestLightField with its diffuse chart two-sided: the back record (chart 1) follows it,
// with values of its own after everything else (lightfield.h "Sides").
LightField makeTwoSidedLightField() {
  LightField lf = makeTestLightField();
  Chart front = lf.charts[0];
  front.sides = 2;
  Chart back = front;
  back.isBack = true;
  back.normal = -front.normal;
  back.firstTixel = lf.stats.tixels;
  back.firstValue = lf.values.size();
  for (uint64_t t = 0; t < back.tixelCount(); ++t) lf.values.push_back(Rgb(0.25f * float(t), 0.5f, 2.0f));
  lf.charts = {front, back, lf.charts[1], lf.charts[2]};
  lf.triangleChart = {{0, 0}, {2, 3, 3}};
  lf.stats.tixels += back.tixelCount();
  lf.stats.values = lf.values.size();
  return lf;
}

TEST_F(PlfFileTest, TwoSidedChartsRoundTripAndBrokenPairsAreRefused) {
  const LightField original = makeTwoSidedLightField();
  const std::string path = file("sides.plf");
  writeLightField(path, original);
  const LightField copy = readLightField(path);
  ASSERT_EQ(copy.charts.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(copy.charts[i].sides, original.charts[i].sides) << i;
    EXPECT_EQ(copy.charts[i].isBack, original.charts[i].isBack) << i;
    EXPECT_EQ(copy.charts[i].normal, original.charts[i].normal) << i;
    EXPECT_EQ(copy.charts[i].firstValue, original.charts[i].firstValue) << i;
  }
  EXPECT_EQ(copy.values, original.values);
  EXPECT_EQ(copy.triangleChart, original.triangleChart);

  const auto good = readBytes(path);
  const auto table = sections(good);
  const uint64_t chartRecord = 4 + 1 + 48 + 4 + 12 + 16;
  const uint64_t kindAt = table[1].offset + 8 + 4;  // record 0's kind byte
  // The back record's "back" bit cleared: a two-sided chart without its back side.
  auto bad = good;
  bad[kindAt + chartRecord] &= uint8_t(~0x40);
  resign(bad);
  writeBytes(file("noback.plf"), bad);
  expectRefused(file("noback.plf"), {"corrupt charts section", "two-sided chart 0 is not followed by its back side"});
  // A back record whose front is one-sided.
  bad = good;
  bad[kindAt] &= uint8_t(~0x80);
  resign(bad);
  writeBytes(file("nofront.plf"), bad);
  expectRefused(file("nofront.plf"), {"corrupt charts section", "chart 1 is a back side without a matching"});
  // A triangle mapped to the back record instead of the front.
  bad = good;
  const uint32_t backRecord = 1;
  std::memcpy(bad.data() + table[2].offset + 16, &backRecord, 4);
  resign(bad);
  writeBytes(file("trchback.plf"), bad);
  try {
    readLightField(file("trchback.plf"));
    ADD_FAILURE() << "a triangle mapped to a back record was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("maps to chart 1 of 4 (a back side, not a front chart)"), std::string::npos) << e.what();
  }
}

// Alpha masks and normal maps travel in SCNE's optional surface-detail block: every field and
// every texture's decoding come back; a value out of range in it is refused.
// Curved charts (CHRT kind byte bit 5): kept on diffuse and glossy charts; a curved specular
// chart or a curved rough-glass chart is corrupt (rough glass stays planar).
TEST_F(PlfFileTest, CurvedGlossyChartsRoundTripAndCurvedSpecularOrRoughGlassAreRefused) {
  LightField original = makeTestLightField();
  ASSERT_EQ(original.charts[0].kind, ChartKind::Diffuse);
  ASSERT_EQ(original.charts[1].kind, ChartKind::Specular);
  ASSERT_EQ(original.charts[2].kind, ChartKind::Glossy);
  original.charts[0].curved = true;
  original.charts[2].curved = true;
  const std::string path = file("curved.plf");
  writeLightField(path, original);
  const LightField copy = readLightField(path);
  ASSERT_EQ(copy.charts.size(), original.charts.size());
  for (size_t i = 0; i < copy.charts.size(); ++i) EXPECT_EQ(copy.charts[i].curved, original.charts[i].curved) << i;
  EXPECT_EQ(copy.values, original.values);
  EXPECT_EQ(readLightFieldInfo(path).curvedCharts, 2u);

  const auto good = readBytes(path);
  const auto table = sections(good);
  const uint64_t chartRecord = 4 + 1 + 48 + 4 + 12 + 16;
  const uint64_t recordsAt = table[1].offset + 8;  // record 0's material, then its kind byte
  // The mirror chart marked curved.
  auto bad = good;
  bad[recordsAt + chartRecord + 4] |= 0x20;
  resign(bad);
  writeBytes(file("curvedmirror.plf"), bad);
  expectRefused(file("curvedmirror.plf"), {"corrupt charts section", "chart 1 of kind 2 is marked curved"});
  // The curved glossy chart given the rough-glass material (4: GGX α 0.04, not thin).
  ASSERT_TRUE(hasTransmission(original.scene.materials[4].bsdf));
  bad = good;
  const uint32_t roughGlass = 4;
  std::memcpy(bad.data() + recordsAt + 2 * chartRecord, &roughGlass, 4);
  resign(bad);
  writeBytes(file("curvedglass.plf"), bad);
  expectRefused(file("curvedglass.plf"), {"corrupt charts section", "rough-glass chart 2 is marked curved"});
}

// Glossy charts that keep a diffuse value per tixel after their map (Chart::diffuseValue,
// CHRT bit 4, version 4): the flag and the longer value layout round-trip with every values
// encoding; the bit on a chart of another kind is refused.
TEST_F(PlfFileTest, GlossyDiffuseValuesRoundTripAndTheBitOnOtherKindsIsRefused) {
  LightField original = makeTestLightField();
  ASSERT_EQ(original.charts[2].kind, ChartKind::Glossy);
  original.charts[2].diffuseValue = true;  // 16 + 1 values per tixel
  original.values.resize(16 + 2 * 3 * 17);
  for (size_t i = 0; i < original.values.size(); ++i) original.values[i] = Rgb(float(i), 0.25f * float(i), 3.0f);
  for (const ValuesCodec codec : {ValuesCodec::Raw, ValuesCodec::Lossless}) {
    const std::string path = file("diffuse-value.plf");
    writeLightField(path, original, codec);
    const LightField copy = readLightField(path);
    ASSERT_EQ(copy.charts.size(), original.charts.size());
    for (size_t i = 0; i < copy.charts.size(); ++i) EXPECT_EQ(copy.charts[i].diffuseValue, original.charts[i].diffuseValue) << i;
    EXPECT_EQ(copy.values, original.values);
    EXPECT_EQ(readLightFieldInfo(path).version, kPlfVersion);
  }
  const std::string path = file("diffuse-value.plf");
  writeLightField(path, original);
  // The diffuse chart marked as having a diffuse value.
  expectKindByteRefused(path, 0, 0x10, 0, "diffuse-bit.plf",
                        {"corrupt charts section", "chart 0 of kind 0 is marked as having a diffuse value"});
}

// Normal-mapped glossy charts keep tilted irradiances after their diffuse value (CHRT bit 3,
// as on diffuse charts; lightfield.h "Normal-mapped diffuse charts"): the flags and the longer
// value layout round-trip with every values encoding; the bit on a glossy chart without a
// diffuse value, or on a specular chart, is refused.
TEST_F(PlfFileTest, GlossyTiltedIrradiancesRoundTripAndTheBitWithoutADiffuseValueIsRefused) {
  LightField original = makeTestLightField();
  ASSERT_EQ(original.charts[2].kind, ChartKind::Glossy);
  original.charts[2].diffuseValue = true;
  original.charts[2].directionalIrradiance = true;  // 16 + 1 + 3 values per tixel
  original.values.resize(16 + 2 * 3 * 20);
  for (size_t i = 0; i < original.values.size(); ++i) original.values[i] = Rgb(float(i), 0.25f * float(i), 3.0f);
  EXPECT_EQ(original.charts[2].tiltedIrradianceIndex(1, 0, 2), original.charts[2].firstValue + 20 + 16 + 1 + 2);
  for (const ValuesCodec codec : {ValuesCodec::Raw, ValuesCodec::Lossless}) {
    const std::string path = file("glossy-tilted.plf");
    writeLightField(path, original, codec);
    const LightField copy = readLightField(path);
    ASSERT_EQ(copy.charts.size(), original.charts.size());
    for (size_t i = 0; i < copy.charts.size(); ++i) {
      EXPECT_EQ(copy.charts[i].diffuseValue, original.charts[i].diffuseValue) << i;
      EXPECT_EQ(copy.charts[i].directionalIrradiance, original.charts[i].directionalIrradiance) << i;
    }
    EXPECT_EQ(copy.values, original.values);
  }
  const std::string path = file("glossy-tilted.plf");
  writeLightField(path, original);
  // The glossy chart without its diffuse value; the mirror chart with the bit.
  expectKindByteRefused(path, 2, 0, 0x10, "glossy-tilted-bit.plf",
                        {"corrupt charts section", "chart 2 of kind 1 without a diffuse value is marked as having tilted irradiances"});
  expectKindByteRefused(path, 1, 0x08, 0, "mirror-tilted-bit.plf",
                        {"corrupt charts section", "chart 1 of kind 2 without a diffuse value is marked as having tilted irradiances"});
}

TEST_F(PlfFileTest, RoundTripKeepsAlphaMasksNormalMapsAndTextureDecodings) {
  LightField original = makeTestLightField();
  Scene& s = original.scene;
  // The embedded PNG (stored as its file's bytes) as the mask, which the reader must decode as
  // coverage (its red channel: it has no alpha), not as colour; a float-pixel texture as the
  // normal map.
  const int base = int(s.textures.size());
  Texture mask = s.textures[1], normals = s.textures[0];
  ASSERT_TRUE(mask.encoded);
  ASSERT_FALSE(normals.encoded);
  mask.path = "textures/mask.png";
  mask.decode = ImageDecode::Coverage;
  mask.image = decodeLdrImage(*mask.encoded, "mask", ImageDecode::Coverage);
  normals.path = "textures/normals.png";
  normals.decode = ImageDecode::Data;
  s.textures.push_back(mask);
  s.textures.push_back(normals);
  s.materials[0].alphaTexture = base;
  s.materials[0].alphaFactor = 0.9f;
  s.materials[0].alphaCutoff = 0.3f;
  s.materials[2].normalTexture = base + 1;
  s.materials[2].normalScale = 0.7f;
  const std::string path = file("detail.plf");
  writeLightField(path, original);
  const LightField copy = readLightField(path);
  ASSERT_EQ(copy.scene.materials.size(), s.materials.size());
  for (size_t m = 0; m < s.materials.size(); ++m) {
    const Material &a = s.materials[m], &b = copy.scene.materials[m];
    EXPECT_EQ(b.alphaTexture, a.alphaTexture) << m;
    EXPECT_EQ(b.alphaFactor, a.alphaFactor) << m;
    EXPECT_EQ(b.alphaCutoff, a.alphaCutoff) << m;
    EXPECT_EQ(b.normalTexture, a.normalTexture) << m;
    EXPECT_EQ(b.normalScale, a.normalScale) << m;
  }
  ASSERT_EQ(copy.scene.textures.size(), size_t(base) + 2);
  EXPECT_EQ(copy.scene.textures[0].decode, ImageDecode::Colour);
  EXPECT_EQ(copy.scene.textures[size_t(base)].decode, ImageDecode::Coverage);
  EXPECT_EQ(copy.scene.textures[size_t(base) + 1].decode, ImageDecode::Data);
  EXPECT_EQ(copy.scene.textures[size_t(base)].image.pixels, mask.image.pixels);
  EXPECT_EQ(copy.scene.textures[size_t(base) + 1].image.pixels, normals.image.pixels);
  EXPECT_NE(copy.scene.textures[size_t(base)].image.pixels, s.textures[1].image.pixels);  // coverage ≠ colour

  // The block ends SCNE: 5 materials × 20 bytes, then one decoding byte per texture. Material 0's alpha
  // factor (4 bytes into its record) set to 2, and a decoding byte set to 9: both refused.
  const auto good = readBytes(path);
  const auto table = sections(good);
  const uint64_t blockEnd = table[0].offset + table[0].size;
  auto bad = good;
  const float two = 2.0f;
  std::memcpy(bad.data() + blockEnd - s.textures.size() - 5 * 20 + 4, &two, 4);
  resign(bad);
  writeBytes(file("alpha.plf"), bad);
  expectRefused(file("alpha.plf"), {"scene section", "material 'white' has alpha 2"});
  bad = good;
  bad[blockEnd - 1] = 9;
  resign(bad);
  writeBytes(file("decode.plf"), bad);
  expectRefused(file("decode.plf"), {"scene section", "unknown decoding 9"});
}

// The texturing block (version 5): second uv sets, vertex colours, texture mappings, a
// metallic-roughness map and samplings round-trip; a wrap mode out of range is refused; a scene
// without any of them has no block (its SCNE is the version-4 one).
TEST_F(PlfFileTest, RoundTripKeepsTexturing) {
  LightField original = makeTestLightField();
  Scene& s = original.scene;
  const uint64_t plainScene = sceneSectionSize(original);
  Mesh& quad = s.meshes[0];
  quad.uvs1 = {{0.5f, 0}, {1, 0.25f}, {1, 1}, {0, 0.5f}};
  quad.colors = {{1, 0.5f, 0.25f}, {0, 1, 1}, {0.5f, 0.5f, 0.5f}, {1, 1, 1}};
  Material& ggx = s.materials[3];
  ggx.albedoTexture = 1;
  ggx.albedoMapping.uvSet = 1;
  ggx.albedoMapping.linear = Mat2(Vec2(0.5f, 0.25f), Vec2(-0.25f, 2.0f));
  ggx.albedoMapping.offset = Vec2(0.1f, -3.0f);
  ggx.normalMapping.offset = Vec2(0.5f, 0.5f);
  ggx.metallicRoughness = {1, ggx.albedoMapping, Rgb(0.9f, 0.8f, 0.7f), 0.6f, 0.3f};
  s.textures[1].sampling = {TextureWrap::MirroredRepeat, TextureWrap::ClampToEdge, true, false};
  // A data texture without alpha masks or normal maps: its decoding must come back too.
  s.textures[1].decode = ImageDecode::Data;
  s.textures[1].image = decodeLdrImage(*s.textures[1].encoded, "png", ImageDecode::Data);
  const std::string path = file("texturing.plf");
  writeLightField(path, original);
  const LightField copy = readLightField(path);
  EXPECT_EQ(copy.scene.meshes[0].uvs1, quad.uvs1);
  EXPECT_EQ(copy.scene.meshes[0].colors, quad.colors);
  EXPECT_TRUE(copy.scene.materials[0].vertexColored);  // derived on load
  const Material& back = copy.scene.materials[3];
  EXPECT_EQ(back.albedoMapping.uvSet, 1);
  EXPECT_EQ(back.albedoMapping.linear, ggx.albedoMapping.linear);
  EXPECT_EQ(back.albedoMapping.offset, ggx.albedoMapping.offset);
  EXPECT_EQ(back.normalMapping.offset, ggx.normalMapping.offset);
  EXPECT_EQ(back.metallicRoughness.texture, 1);
  EXPECT_EQ(back.metallicRoughness.mapping.linear, ggx.albedoMapping.linear);
  EXPECT_EQ(back.metallicRoughness.baseColor, ggx.metallicRoughness.baseColor);
  EXPECT_EQ(back.metallicRoughness.metallic, 0.6f);
  EXPECT_EQ(back.metallicRoughness.roughness, 0.3f);
  EXPECT_TRUE(copy.scene.textures[1].sampling == s.textures[1].sampling);
  EXPECT_TRUE(copy.scene.textures[0].sampling.isDefault());
  EXPECT_EQ(copy.scene.textures[1].decode, ImageDecode::Data);
  EXPECT_EQ(copy.scene.textures[1].image.pixels, s.textures[1].image.pixels);

  // The block ends SCNE with 4 sampling bytes per texture: texture 1's wrapU set to 3 is refused.
  expectRefusedWithSceneByte(path, plainScene, 4, 3, "wrap.plf", {"scene section", "unknown sampling 3"});
}

// An emission texture and its mapping come back through the EMTX block, alone after the
// settings or after the texturing block; files without one keep their layout (the plain
// file's SCNE is shorter), and a bad mapping in the block is refused naming the material.
TEST_F(PlfFileTest, RoundTripKeepsEmissionTextures) {
  LightField original = makeTestLightField();
  Scene& s = original.scene;
  const uint64_t plainScene = sceneSectionSize(original);
  Material& lamp = s.materials[0];
  lamp.emission = Rgb(3.0f, 2.0f, 1.0f);
  lamp.emissionTexture = 1;
  lamp.emissionMapping.linear = Mat2(Vec2(2.0f, 0.0f), Vec2(0.5f, 1.0f));
  lamp.emissionMapping.offset = Vec2(0.25f, -1.0f);
  for (const bool texturing : {false, true}) {
    SCOPED_TRACE(texturing ? "after TXMP" : "alone");
    if (texturing) s.materials[3].albedoMapping.offset = Vec2(0.5f, 0.0f);  // a TXMP block too
    const std::string path = file("emission.plf");
    writeLightField(path, original);
    const LightField copy = readLightField(path);
    const Material& back = copy.scene.materials[0];
    EXPECT_EQ(back.emissionTexture, 1);
    EXPECT_EQ(back.emissionMapping.linear, lamp.emissionMapping.linear);
    EXPECT_EQ(back.emissionMapping.offset, lamp.emissionMapping.offset);
    EXPECT_EQ(back.emission, lamp.emission);
    for (size_t m = 1; m < copy.scene.materials.size(); ++m) EXPECT_EQ(copy.scene.materials[m].emissionTexture, -1);
    EXPECT_EQ(copy.scene.materials[3].albedoMapping.offset, s.materials[3].albedoMapping.offset);
    // The block ends with the last material's i32 texture, u8 uv set, 6 floats: uv set 7.
    expectRefusedWithSceneByte(path, plainScene, 25, 7, "emission_bad.plf",
                               {"scene section", "the emission texture reads uv set 7"});
  }
}

// Vertex alphas (glTF COLOR_0's alpha) come back through the VALP block, alone after the
// settings or after the other blocks; they make their materials masked again on load, and an
// alpha outside [0, 1] in the block is refused naming the mesh.
TEST_F(PlfFileTest, RoundTripKeepsVertexAlphas) {
  LightField original = makeTestLightField();
  Scene& s = original.scene;
  const uint64_t plainScene = sceneSectionSize(original);
  s.meshes[0].alphas = {0.0f, 0.25f, 1.0f, 0.5f};
  for (const bool others : {false, true}) {
    SCOPED_TRACE(others ? "after SDTL, TXMP and EMTX" : "alone");
    if (others) {
      s.materials[3].albedoMapping.offset = Vec2(0.5f, 0.0f);
      s.materials[0].emissionTexture = 1;
      s.materials[0].emission = Rgb(1.0f);
    }
    const std::string path = file("alphas.plf");
    writeLightField(path, original);
    const LightField copy = readLightField(path);
    EXPECT_EQ(copy.scene.meshes[0].alphas, s.meshes[0].alphas);
    EXPECT_TRUE(copy.scene.meshes[1].alphas.empty());
    for (const uint32_t m : copy.scene.meshes[0].materials) EXPECT_TRUE(copy.scene.materials[m].isMasked());
    EXPECT_EQ(copy.scene.materials[0].emissionTexture, others ? 1 : -1);
    // The block ends with mesh 0's last alpha (0.5f, its high byte 12 − 3 bytes before the
    // end) and mesh 1's empty count: 0x7f there makes it 1.7e38.
    expectRefusedWithSceneByte(path, plainScene, 9, 0x7f, "alphas_bad.plf",
                               {"scene section", "mesh", "vertex alpha 3", "outside [0, 1]"});
  }
}

// --- Sun masks (SMSK, version 3) -----------------------------------------------------------

// makeTestLightField's scene has one directional light (lights[2]) and no thin glass, so
// sunMaskLights gives {2}; `extraSuns` more directional lights give that many more masks per
// tixel. The masks are random bits (38 tixels × L).
LightField makeSunMaskedLightField(int extraSuns = 0) {
  LightField lf = makeTestLightField();
  for (int i = 0; i < extraSuns; ++i)
    lf.scene.lights.push_back(DirectionalLight{{0.0f, -1.0f, 0.1f * float(i)}, {1.0f, 0.5f, 0.25f}});
  lf.sunMaskLightCount = uint32_t(sunMaskLights(lf.scene).size());
  uint64_t tixels = 0;
  for (const Chart& c : lf.charts) tixels += c.tixelCount();
  std::mt19937 rng(1234);
  lf.sunMasks.resize(tixels * lf.sunMaskLightCount);
  for (SunMask& m : lf.sunMasks) m = SunMask(rng());
  return lf;
}

/// Index of the section table entry with this id (−1: none).
int sectionIndex(const std::vector<unsigned char>& bytes, const std::string& id) {
  uint32_t count;
  std::memcpy(&count, bytes.data() + 12, 4);
  for (uint32_t i = 0; i < count; ++i)
    if (std::memcmp(bytes.data() + kPlfHeaderSize + i * kPlfSectionEntrySize, id.data(), 4) == 0) return int(i);
  return -1;
}

TEST_F(PlfFileTest, SunMasksRoundTripWithEveryValuesEncoding) {
  for (int extraSuns : {0, 1}) {
    const LightField original = makeSunMaskedLightField(extraSuns);
    const uint32_t lights = uint32_t(1 + extraSuns);
    ASSERT_EQ(original.sunMaskLightCount, lights);
    ASSERT_EQ(original.sunMasks.size(), 38u * lights);
    // Every values codec: `plenoptic compress` rewrites a read LightField with another codec,
    // and the masks must come through unchanged.
    for (ValuesCodec codec : {ValuesCodec::Raw, ValuesCodec::Lossless, ValuesCodec::Hdr}) {
      SCOPED_TRACE(fmt::format("{} lights, codec {}", lights, uint32_t(codec)));
      const std::string path = file("masks.plf");
      writeLightField(path, original, codec);
      const LightField copy = readLightField(path);
      EXPECT_EQ(copy.sunMaskLightCount, lights);
      EXPECT_EQ(copy.sunMasks, original.sunMasks);
      const LightField recompressed = [&] {
        writeLightField(file("again.plf"), copy, ValuesCodec::Lossless);
        return readLightField(file("again.plf"));
      }();
      EXPECT_EQ(recompressed.sunMaskLightCount, lights);
      EXPECT_EQ(recompressed.sunMasks, original.sunMasks);

      // SMSK sits between VALS and META: 16 header bytes and 2 bytes per mask.
      const PlfInfo info = readLightFieldInfo(path);
      EXPECT_EQ(info.version, kPlfVersion);  // SMSK since version 3
      EXPECT_EQ(info.sunMaskLights, lights);
      EXPECT_TRUE(info.checksumsVerified);
      ASSERT_EQ(info.sections.size(), 6u);
      EXPECT_EQ(info.sections[3].id, "VALS");
      EXPECT_EQ(info.sections[4].id, "SMSK");
      EXPECT_EQ(info.sections[5].id, "META");
      EXPECT_EQ(info.sections[4].decodedSize, 16u + 38u * lights * 2u);
      EXPECT_EQ(info.sections[5].offset + info.sections[5].storedSize, info.fileBytes);
      // Compressed values come with zstd'ed sun masks (ZstdSectionsRoundTrip…); raw ones below.
      if (codec != ValuesCodec::Raw) {
        EXPECT_EQ(info.sections[4].encoding, kPlfSectionZstd);
        continue;
      }
      EXPECT_EQ(info.sections[4].encoding, 0u);
      EXPECT_EQ(info.sections[4].storedSize, info.sections[4].decodedSize);

      // The section's bytes: L, reserved 0, T, then the masks as they are in memory.
      const auto bytes = readBytes(path);
      const Section smsk = sections(bytes)[4];
      uint32_t storedLights = 0, reserved = 7;
      uint64_t storedTixels = 0;
      std::memcpy(&storedLights, bytes.data() + smsk.offset, 4);
      std::memcpy(&reserved, bytes.data() + smsk.offset + 4, 4);
      std::memcpy(&storedTixels, bytes.data() + smsk.offset + 8, 8);
      EXPECT_EQ(storedLights, lights);
      EXPECT_EQ(reserved, 0u);
      EXPECT_EQ(storedTixels, 38u);
      EXPECT_EQ(
          std::memcmp(bytes.data() + smsk.offset + 16, original.sunMasks.data(), original.sunMasks.size() * 2), 0);
    }
  }
}

// With compressed values, SCNE, CHRT, TRCH and SMSK are each one zstd frame (kPlfSectionZstd),
// META and `--compress none` files raw; everything reads back as it was written, and damage
// inside a frame (checksums re-signed, so zstd's own checks must catch it) or a decoded size
// the frame does not hold is an error naming the file and the section.
TEST_F(PlfFileTest, ZstdSectionsRoundTripAndDamageNamesTheSection) {
  const LightField original = makeSunMaskedLightField();
  const std::string path = file("zstd.plf");
  writeLightField(path, original, ValuesCodec::Hdr);
  const PlfInfo info = readLightFieldInfo(path);
  ASSERT_EQ(info.sections.size(), 6u);
  const std::pair<const char*, uint32_t> expected[] = {{"SCNE", kPlfSectionZstd}, {"CHRT", kPlfSectionZstd},
                                                       {"TRCH", kPlfSectionZstd}, {"VALS", uint32_t(ValuesCodec::Hdr)},
                                                       {"SMSK", kPlfSectionZstd}, {"META", 0u}};
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(info.sections[i].id, expected[i].first);
    EXPECT_EQ(info.sections[i].encoding, expected[i].second) << expected[i].first;
  }
  const LightField copy = readLightField(path);
  EXPECT_EQ(encodeSceneSection(copy.scene), encodeSceneSection(original.scene));
  ASSERT_EQ(copy.charts.size(), original.charts.size());
  for (size_t i = 0; i < copy.charts.size(); ++i) {
    EXPECT_EQ(copy.charts[i].resU, original.charts[i].resU);
    EXPECT_EQ(copy.charts[i].firstValue, original.charts[i].firstValue);
  }
  EXPECT_EQ(copy.triangleChart, original.triangleChart);
  EXPECT_EQ(copy.sunMasks, original.sunMasks);
  // The raw sections decode to the same bytes as a `none` file's.
  writeLightField(file("raw.plf"), original, ValuesCodec::Raw);
  const PlfInfo rawInfo = readLightFieldInfo(file("raw.plf"));
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(rawInfo.sections[i].encoding, 0u);
    if (i != 3) { EXPECT_EQ(info.sections[i].decodedSize, rawInfo.sections[i].storedSize) << info.sections[i].id; }
  }

  const auto good = readBytes(path);
  const std::pair<const char*, const char*> names[] = {
      {"SCNE", "scene section (SCNE)"}, {"CHRT", "charts section (CHRT)"},
      {"TRCH", "triangle charts section (TRCH)"}, {"SMSK", "sun masks section (SMSK)"}};
  for (const auto& [id, name] : names) {
    SCOPED_TRACE(id);
    const int index = sectionIndex(good, id);
    ASSERT_GE(index, 0);
    const Section section = sections(good)[size_t(index)];
    const uint64_t entryAt = kPlfHeaderSize + uint64_t(index) * kPlfSectionEntrySize;
    {  // a byte flipped inside the frame's payload, re-signed
      auto bad = good;
      bad[section.offset + section.size / 2] ^= 0x5a;
      resign(bad);
      writeBytes(file("flip.plf"), bad);
      expectRefused(file("flip.plf"), {name});
    }
    {  // not re-signed: the section checksum
      auto bad = good;
      bad[section.offset + section.size / 2] ^= 0x5a;
      writeBytes(file("sum.plf"), bad);
      expectRefused(file("sum.plf"), {"checksum mismatch"});
    }
    uint64_t decoded = 0;
    std::memcpy(&decoded, good.data() + entryAt + 24, 8);
    {  // a decoded size one byte more than the frame holds
      auto bad = good;
      const uint64_t more = decoded + 1;
      std::memcpy(bad.data() + entryAt + 24, &more, 8);
      resign(bad);
      writeBytes(file("size.plf"), bad);
      expectRefused(file("size.plf"), {name, "the zstd frame holds"});
    }
    {  // a decoded size no zstd frame of this size can hold: refused before any allocation
      auto bad = good;
      const uint64_t absurd = uint64_t(1) << 60;
      std::memcpy(bad.data() + entryAt + 24, &absurd, 8);
      resign(bad);
      writeBytes(file("absurd.plf"), bad);
      expectRefused(file("absurd.plf"), {"zstd section", id, "cannot decode"});
    }
  }
  {  // zstd is no encoding of the values
    auto bad = good;
    const uint64_t entryAt = kPlfHeaderSize + uint64_t(sectionIndex(good, "VALS")) * kPlfSectionEntrySize;
    std::memcpy(bad.data() + entryAt + 4, &kPlfSectionZstd, 4);
    resign(bad);
    writeBytes(file("vals.plf"), bad);
    expectRefused(file("vals.plf"), {"section VALS uses encoding 4"});
  }
}

TEST_F(PlfFileTest, LightFieldWithoutSunMasksHasNoSunMaskSection) {
  const LightField original = makeTestLightField();
  ASSERT_EQ(sunMaskLights(original.scene).size(), 1u);  // it could have masks, but has none
  ASSERT_EQ(original.sunMaskLightCount, 0u);
  const std::string path = file("nomasks.plf");
  writeLightField(path, original);
  const auto bytes = readBytes(path);
  EXPECT_EQ(sectionIndex(bytes, "SMSK"), -1);
  EXPECT_EQ(sections(bytes).size(), 5u);
  const LightField copy = readLightField(path);
  EXPECT_EQ(copy.sunMaskLightCount, 0u);
  EXPECT_TRUE(copy.sunMasks.empty());
  const PlfInfo info = readLightFieldInfo(path);
  EXPECT_EQ(info.version, kPlfVersion);
  EXPECT_EQ(info.sunMaskLights, 0u);
}

TEST_F(PlfFileTest, WriterRefusesSunMasksThatDoNotMatchTheLightField) {
  auto expectWriteRefused = [&](const LightField& lf, const std::vector<std::string>& fragments) {
    const std::string path = file("refused.plf");
    try {
      writeLightField(path, lf);
      ADD_FAILURE() << "written: " << fragments.front();
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      for (const std::string& fragment : fragments)
        EXPECT_NE(message.find(fragment), std::string::npos) << "'" << fragment << "' not in: " << message;
    }
    EXPECT_EQ(fileCount(), 0u) << "nothing may be written";
  };
  LightField lf = makeSunMaskedLightField();
  lf.sunMasks.pop_back();  // one tixel short
  expectWriteRefused(lf, {"holds 37 sun masks", "1 masked light × 38 tixels need 38"});
  lf = makeSunMaskedLightField();
  lf.sunMaskLightCount = 0;  // masks without a count
  expectWriteRefused(lf, {"holds 38 sun masks", "0 masked lights × 38 tixels need 0"});
  lf = makeSunMaskedLightField();
  lf.sunMaskLightCount = 2;  // more lights than the scene masks
  lf.sunMasks.resize(76);
  expectWriteRefused(lf, {"sun masks of 2 lights per tixel", "its scene has 1 masked light"});
}

TEST_F(PlfFileTest, RefusesBadSunMaskSectionsNamingTheFileAndSection) {
  const std::string path = file("good.plf");
  writeLightField(path, makeSunMaskedLightField());
  const auto good = readBytes(path);
  const int entry = sectionIndex(good, "SMSK");
  ASSERT_EQ(entry, 4);
  const Section smsk = sections(good)[size_t(entry)];
  ASSERT_EQ(smsk.size, 16u + 38u * 2u);
  const std::string section = "corrupt sun masks section (SMSK)";
  auto put32 = [](std::vector<unsigned char>& bytes, uint64_t at, uint32_t value) {
    std::memcpy(bytes.data() + at, &value, 4);
  };
  auto put64 = [](std::vector<unsigned char>& bytes, uint64_t at, uint64_t value) {
    std::memcpy(bytes.data() + at, &value, 8);
  };
  auto check = [&](std::vector<unsigned char> bad, const std::string& name, const std::vector<std::string>& fragments) {
    SCOPED_TRACE(name);
    writeBytes(file(name), bad);
    expectRefused(file(name), fragments);
  };
  const uint64_t entryAt = kPlfHeaderSize + uint64_t(entry) * kPlfSectionEntrySize;

  // The section one mask short (its last two bytes zeroed, so they read as padding).
  {
    auto bad = good;
    bad[smsk.offset + smsk.size - 1] = bad[smsk.offset + smsk.size - 2] = 0;
    put64(bad, entryAt + 16, smsk.size - 2);  // stored size
    put64(bad, entryAt + 24, smsk.size - 2);  // decoded size
    resign(bad);
    check(bad, "short.plf", {section, "the section has 90 bytes", "38 tixels × 1 light × 2 bytes need 92"});
  }
  // Shorter than its header.
  {
    auto bad = good;
    std::fill(bad.begin() + long(smsk.offset + 8), bad.begin() + long(smsk.offset + smsk.size), 0);
    put64(bad, entryAt + 16, 8);
    put64(bad, entryAt + 24, 8);
    resign(bad);
    check(bad, "header.plf", {section, "8 bytes, fewer than its 16-byte header"});
  }
  // A tixel count that does not match the section's size.
  {
    auto bad = good;
    put64(bad, smsk.offset + 8, 39);
    resign(bad);
    check(bad, "tixels.plf", {section, "the section has 92 bytes", "39 tixels × 1 light × 2 bytes need 94"});
  }
  // Two lights' masks (the size still matching: 19 tixels × 2), but the scene masks one.
  {
    auto bad = good;
    put32(bad, smsk.offset, 2);
    put64(bad, smsk.offset + 8, 19);
    resign(bad);
    check(bad, "lights.plf", {section, "masks of 2 lights per tixel", "the scene has 1 masked light"});
  }
  // Light counts outside 1..kMaxSunMaskLights.
  for (const uint32_t lights : {0u, kMaxSunMaskLights + 1}) {
    auto bad = good;
    put32(bad, smsk.offset, lights);
    resign(bad);
    check(bad, fmt::format("count{}.plf", lights),
          {section, fmt::format("light count {} (must be 1 to {})", lights, kMaxSunMaskLights)});
  }
  // The reserved field set.
  {
    auto bad = good;
    put32(bad, smsk.offset + 4, 1);
    resign(bad);
    check(bad, "reserved.plf", {section, "reserved field is 1, not 0"});
  }
  // The charts grown under the masks: the mirror chart (record 1) made 4×5 tixels instead of
  // 4×4 (specular: no values, so only the tixel count changes), 42 tixels for 38 masks.
  {
    auto bad = good;
    const uint64_t chartRecord = 4 + 1 + 48 + 4 + 12 + 16;
    const uint64_t resVAt = sections(good)[1].offset + 8 + chartRecord + 4 + 1 + 48 + 4 + 4;
    uint32_t resV = 0;
    std::memcpy(&resV, bad.data() + resVAt, 4);
    ASSERT_EQ(resV, 4u);
    put32(bad, resVAt, 5);
    resign(bad);
    check(bad, "chrt.plf", {section, "masks for 38 tixels, but the charts have 42 tixels"});
  }
  // A second SMSK entry (META's entry renamed: found while the table is read).
  {
    auto bad = good;
    const int meta = sectionIndex(good, "META");
    ASSERT_EQ(meta, 5);
    std::memcpy(bad.data() + kPlfHeaderSize + uint64_t(meta) * kPlfSectionEntrySize, "SMSK", 4);
    resign(bad);
    check(bad, "twice.plf", {"section SMSK appears twice"});
  }
  // SMSK in a file whose header says version 2 or 1: those versions have no such section.
  for (const uint32_t version : {2u, 1u}) {
    auto bad = good;
    put32(bad, 8, version);
    resign(bad);
    check(bad, fmt::format("v{}.plf", version), {fmt::format("unknown section 'SMSK' in a version {} file", version)});
  }
  // Damaged bytes (not re-signed) are a checksum mismatch, in the header fields too (the
  // header is checked before the masks are read, but the checksum decides the diagnosis).
  for (const uint64_t at : {smsk.offset, smsk.offset + 9, smsk.offset + smsk.size / 2, smsk.offset + smsk.size - 1}) {
    auto bad = good;
    bad[at] ^= 0x04;
    check(bad, fmt::format("flip{}.plf", at), {"checksum mismatch in the sun masks section (SMSK)"});
  }
  // And the untouched file still reads (the edits above were all that was wrong).
  EXPECT_EQ(readLightField(path).sunMasks, makeSunMaskedLightField().sunMasks);
}

TEST_F(PlfFileTest, VersionOneAndTwoFilesStillReadWithoutSunMasks) {
  // Files written by the version-1 and version-2 writers (tests/data/render, the quad of
  // render_cli_test.cpp; render_cli_test checks the rest of their contents).
  for (const uint32_t version : {1u, 2u}) {
    const std::string fixture = fmt::format("{}/render/quad-v{}.plf", PLENOPTIC_TEST_DATA_DIR, version);
    SCOPED_TRACE(fixture);
    const LightField lf = readLightField(fixture);
    EXPECT_EQ(lf.charts.size(), 1u);
    EXPECT_EQ(lf.sunMaskLightCount, 0u);
    EXPECT_TRUE(lf.sunMasks.empty());
    const PlfInfo info = readLightFieldInfo(fixture);
    EXPECT_EQ(info.version, version);
    EXPECT_EQ(info.sunMaskLights, 0u);
  }
  // A mask-free file is a version-2 file but for the version field: so labelled, it reads the
  // same (textures included, which version 1 stored differently).
  const LightField original = makeTestLightField();
  const std::string path = file("v2.plf");
  writeLightField(path, original);
  auto bytes = readBytes(path);
  const uint32_t two = 2;
  std::memcpy(bytes.data() + 8, &two, 4);
  resign(bytes);
  writeBytes(path, bytes);
  const LightField copy = readLightField(path);
  EXPECT_EQ(copy.values, original.values);
  EXPECT_EQ(copy.scene.textures.size(), original.scene.textures.size());
  EXPECT_EQ(copy.sunMaskLightCount, 0u);
  EXPECT_TRUE(copy.sunMasks.empty());
  EXPECT_EQ(readLightFieldInfo(path).version, 2u);
}

// A file whose checksums are right but whose scene breaks the scene checker (checkScene, the
// one Scene::finalize runs): an energy-creating material or a broken light is refused with a
// message naming the file, the section and the problem, by the full and the info reader.
TEST_F(PlfFileTest, RefusesAnInvalidMaterialOrLightInTheScene) {
  LightField bright = makeTestLightField();
  std::get<LambertBsdf>(bright.scene.materials[0].bsdf).albedo = Rgb(1.5f, 0.5f, 0.5f);  // reflects more than it receives
  writeLightField(file("albedo.plf"), bright);  // the writer stores what it is given
  expectRefused(file("albedo.plf"), {"scene section holds an invalid scene", "material 'white'", "Lambert albedo"});

  LightField spot = makeTestLightField();
  std::get<SpotLight>(spot.scene.lights[1]).innerAngle = 1.0f;  // wider than its outer angle 0.4
  writeLightField(file("spot.plf"), spot);
  expectRefused(file("spot.plf"), {"scene section holds an invalid scene", "spot light 1", "inner angle"});

  LightField nan = makeTestLightField();
  std::get<PointLight>(nan.scene.lights[0]).intensity.g = std::numeric_limits<float>::quiet_NaN();
  writeLightField(file("nan.plf"), nan);
  expectRefused(file("nan.plf"), {"scene section holds an invalid scene", "point light 0", "non-finite"});
}

}  // namespace
}  // namespace pl
