// Tests of the scene module: the built-in Cornell box, every loader on real files, per-hit
// surface data, the automatic camera, and one test per kind of bad input.
#include "core/error.h"
#include "core/rng.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <string>
#include <tuple>

#include "support/expect_error.h"
#include "support/expect_vec3.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

const std::string kMcGuireDir = std::string(PLENOPTIC_TEST_DATA_DIR) + "/cornell-mcguire/";
const std::string kDataDir = std::string(PLENOPTIC_TEST_DATA_DIR) + "/scene/";
// The fuzzing regression corpus (fuzz/fuzz_targets.h), one folder per target.
const std::string kFuzzCorpus = std::string(PLENOPTIC_TEST_DATA_DIR) + "/fuzz/";

// Float tolerance for values that went through a few float operations (products, sums of
// magnitude ≲ 10): a few ulps of float (6e-8 relative) at that scale.
constexpr float kTight = 1e-5f;

using test_support::expectError;

/// A fresh directory for files written by one test.
fs::path scratchDir(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) / ("pl_scene_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string writeFile(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

Vec3 triangleNormal(const Mesh& mesh, size_t t) {
  const UVec3 tri = mesh.triangles[t];
  return glm::normalize(glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x], mesh.positions[tri.z] - mesh.positions[tri.x]));
}
Vec3 triangleCentroid(const Mesh& mesh, size_t t) {
  const UVec3 tri = mesh.triangles[t];
  return (mesh.positions[tri.x] + mesh.positions[tri.y] + mesh.positions[tri.z]) / 3.0f;
}
float triangleArea(const Mesh& mesh, size_t t) {
  const UVec3 tri = mesh.triangles[t];
  return 0.5f * glm::length(glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x], mesh.positions[tri.z] - mesh.positions[tri.x]));
}
const Mesh& meshNamed(const Scene& scene, const std::string& name) {
  for (const Mesh& mesh : scene.meshes)
    if (mesh.name == name) return mesh;
  throw std::runtime_error("no mesh " + name);
}
const Material& materialNamed(const Scene& scene, const std::string& name) {
  for (const Material& material : scene.materials)
    if (material.name == name) return material;
  throw std::runtime_error("no material " + name);
}

// ---------------------------------------------------------------------------------------------
// Built-in Cornell box

TEST(CornellBox, GeometryMatchesTheMeasuredData) {
  const Scene scene = makeCornellBox();
  // 5 walls + light = 6 quads, 2 blocks × (4 sides + top) = 10 quads ⇒ 16 quads = 32 triangles.
  EXPECT_EQ(scene.triangleCount(), 32u);
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  // Published extremes: x up to 556.0 (ceiling/left wall), y 548.8, z 559.2.
  EXPECT_VEC3_NEAR(lo, Vec3(0.0f), 0.0f);
  EXPECT_VEC3_NEAR(hi, Vec3(556.0f, 548.8f, 559.2f), 0.0f);
  for (const Material& material : scene.materials)
    EXPECT_TRUE(std::holds_alternative<LambertBsdf>(material.bsdf)) << material.name;
}

TEST(CornellBox, LightIs130By105mmFacingDownJustBelowTheCeiling) {
  const Scene scene = makeCornellBox();
  double area = 0.0;
  Rgb emission(0.0f);
  for (const Mesh& mesh : scene.meshes)
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      const Material& material = scene.materials[mesh.materials[t]];
      if (!material.isEmissive()) continue;
      area += triangleArea(mesh, t);
      emission = material.emission;
      EXPECT_VEC3_NEAR(triangleNormal(mesh, t), Vec3(0.0f, -1.0f, 0.0f), kTight);  // emits downward
      const Vec3 c = triangleCentroid(mesh, t);
      EXPECT_LT(c.y, 548.8f);
      EXPECT_GT(c.y, 548.0f);
    }
  // 130 × 105 mm² = 13650 mm²; the corners are exact in float, the area to float rounding.
  EXPECT_NEAR(area, 130.0 * 105.0, 1e-2);
  EXPECT_VEC3_NEAR(emission, Rgb(18.387f, 13.9873f, 6.75357f), 0.0f);
}

TEST(CornellBox, WallsFaceInwardAndBlocksFaceOutward) {
  const Scene scene = makeCornellBox();
  const Mesh& room = meshNamed(scene, "room");
  const Vec3 inside(278.0f, 274.0f, 280.0f);
  ASSERT_EQ(room.triangles.size(), 10u);
  for (size_t t = 0; t < room.triangles.size(); ++t)
    EXPECT_GT(glm::dot(triangleNormal(room, t), inside - triangleCentroid(room, t)), 0.0f) << "room triangle " << t;
  // Blocks: short block triangles 0..9, tall block 10..19; faces point away from each centre.
  const Mesh& blocks = meshNamed(scene, "blocks");
  ASSERT_EQ(blocks.triangles.size(), 20u);
  const Vec3 shortCentre(186.0f, 82.5f, 169.0f), tallCentre(368.5f, 165.0f, 351.0f);
  for (size_t t = 0; t < 20; ++t) {
    const Vec3 centre = t < 10 ? shortCentre : tallCentre;
    EXPECT_GT(glm::dot(triangleNormal(blocks, t), triangleCentroid(blocks, t) - centre), 0.0f) << "block triangle " << t;
  }
  // The red wall is at x ≈ 552–556 (camera's left), the green one at x = 0.
  for (size_t t = 0; t < room.triangles.size(); ++t) {
    const std::string& name = scene.materials[room.materials[t]].name;
    if (name == "red") {
      EXPECT_GT(triangleCentroid(room, t).x, 549.0f);
    } else if (name == "green") {
      EXPECT_EQ(triangleCentroid(room, t).x, 0.0f);
    }
  }
}

TEST(CornellBox, CameraAndLookup) {
  const Scene scene = makeCornellBox();
  for (const char* name : {"default", "cornell"}) {
    const CameraDesc& camera = scene.camera(name);
    EXPECT_VEC3_NEAR(camera.eye, Vec3(278.0f, 273.0f, -800.0f), 0.0f);
    EXPECT_VEC3_NEAR(glm::normalize(camera.target - camera.eye), Vec3(0.0f, 0.0f, 1.0f), 0.0f);
    EXPECT_VEC3_NEAR(camera.up, Vec3(0.0f, 1.0f, 0.0f), 0.0f);
    // 2·atan(12.5 mm / 35 mm) in degrees.
    EXPECT_NEAR(camera.fovYDegrees, 2.0 * std::atan(12.5 / 35.0) * 180.0 / kPiD, 1e-4);
  }
  expectError([&] { scene.camera("nope"); }, {"cornell", "nope", "'default'", "'cornell'"});
  EXPECT_EQ(loadScene("cornell").triangleCount(), 32u);
}

// ---------------------------------------------------------------------------------------------
// McGuire's OBJ variants (CRLF line endings, as published)

size_t countFacesTriangulated(const std::string& path) {
  // Independent count of the file's triangles: an n-gon "f" line is n − 2 triangles.
  std::ifstream in(path);
  std::string line;
  size_t triangles = 0;
  while (std::getline(in, line)) {
    if (line.rfind("f ", 0) != 0) continue;
    std::istringstream tokens(line.substr(2));
    std::string token;
    size_t n = 0;
    while (tokens >> token) ++n;
    triangles += n - 2;
  }
  return triangles;
}

template <typename T>
bool hasModel(const Scene& scene) {
  for (const Material& material : scene.materials)
    if (std::holds_alternative<T>(material.bsdf)) return true;
  return false;
}

class McGuireVariant : public testing::TestWithParam<const char*> {};

TEST_P(McGuireVariant, LoadsWithEveryTriangleAndALight) {
  const std::string path = kMcGuireDir + "CornellBox-" + GetParam() + ".obj";
  const Scene scene = loadScene(path);
  // Every published triangle survives: none is degenerate in these files.
  EXPECT_EQ(scene.triangleCount(), countFacesTriangulated(path));
  EXPECT_GT(scene.triangleCount(), 0u);
  bool emissive = false;
  for (const Material& material : scene.materials) {
    emissive |= material.isEmissive();
    // CRLF must not leak into names.
    EXPECT_EQ(material.name.find('\r'), std::string::npos);
    // Every Blinn-Phong material conserves energy after the loader's rescaling.
    if (const auto* bp = std::get_if<BlinnPhongBsdf>(&material.bsdf)) {
      EXPECT_LE(maxComponent(bp->diffuse + bp->specular), 1.0f + 1e-6f) << material.name;
    }
  }
  EXPECT_TRUE(emissive);
  EXPECT_TRUE(materialNamed(scene, "light").isEmissive());
  // The light hangs from the ceiling: emissive triangles lie within 1 % of the box height
  // of its top, facing down.
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  for (const Mesh& mesh : scene.meshes)
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      if (scene.materials[mesh.materials[t]].isEmissive()) {
        EXPECT_GT(triangleCentroid(mesh, t).y, hi.y - 0.01f * (hi.y - lo.y));
        EXPECT_LT(triangleNormal(mesh, t).y, -0.99f);
      }
}

INSTANTIATE_TEST_SUITE_P(Scene, McGuireVariant, testing::Values("Original", "Glossy", "Mirror", "Sphere", "Water"));

TEST(McGuire, OriginalIsLambertWithPublishedLight) {
  const Scene scene = loadScene(kMcGuireDir + "CornellBox-Original.obj");
  EXPECT_EQ(scene.triangleCount(), 36u);  // 18 quads
  for (const Material& material : scene.materials) EXPECT_TRUE(std::holds_alternative<LambertBsdf>(material.bsdf));
  EXPECT_VEC3_NEAR(materialNamed(scene, "light").emission, Rgb(17.0f, 12.0f, 4.0f), 0.0f);
  EXPECT_VEC3_NEAR(std::get<LambertBsdf>(materialNamed(scene, "leftWall").bsdf).albedo, Rgb(0.63f, 0.065f, 0.05f), 0.0f);
}

TEST(McGuire, GlossyHasEnergyConservingBlinnPhong) {
  const Scene scene = loadScene(kMcGuireDir + "CornellBox-Glossy.obj");
  EXPECT_TRUE(hasModel<BlinnPhongBsdf>(scene));
  // floor: Kd 0.725 0.71 0.68 + Ks 0.3 exceeds 1 in red and green and is scaled there.
  const auto& floor = std::get<BlinnPhongBsdf>(materialNamed(scene, "floor").bsdf);
  EXPECT_NEAR(floor.diffuse.r, 0.725f / 1.025f, kTight);
  EXPECT_NEAR(floor.specular.r, 0.3f / 1.025f, kTight);
  EXPECT_NEAR(floor.diffuse.b, 0.68f, kTight);  // 0.98 ≤ 1: unchanged
  EXPECT_NEAR(floor.specular.b, 0.3f, kTight);
  EXPECT_EQ(floor.exponent, 80.0f);
}

TEST(McGuire, MirrorHasAFresnelMirror) {
  const Scene scene = loadScene(kMcGuireDir + "CornellBox-Mirror.obj");
  const auto* mirror = std::get_if<MirrorBsdf>(&materialNamed(scene, "tallBox").bsdf);
  ASSERT_NE(mirror, nullptr);
  EXPECT_TRUE(mirror->fresnel);  // illum 5
  EXPECT_VEC3_NEAR(mirror->reflectance, Rgb(0.95f), 0.0f);
}

TEST(McGuire, SphereHasAPlainMirrorAndAGlassSphere) {
  const Scene scene = loadScene(kMcGuireDir + "CornellBox-Sphere.obj");
  const auto* mirror = std::get_if<MirrorBsdf>(&materialNamed(scene, "leftSphere").bsdf);
  ASSERT_NE(mirror, nullptr);  // Ks 1 with Ns 1000, no illum
  EXPECT_FALSE(mirror->fresnel);
  // Ni 1.6 and Tf 0.95 without an illum: solid smooth glass.
  const auto* glass = std::get_if<DielectricBsdf>(&materialNamed(scene, "rightSphere").bsdf);
  ASSERT_NE(glass, nullptr);
  EXPECT_FLOAT_EQ(glass->ior, 1.6f);
  EXPECT_VEC3_NEAR(glass->transmittance, Rgb(0.95f), kTight);
  EXPECT_TRUE(glass->isSmooth());
  EXPECT_FALSE(glass->thin);
}

TEST(McGuire, WaterIsSmoothDielectric) {
  const Scene scene = loadScene(kMcGuireDir + "CornellBox-Water.obj");
  const auto* water = std::get_if<DielectricBsdf>(&materialNamed(scene, "water").bsdf);
  ASSERT_NE(water, nullptr);  // illum 7, Ni 1.33, Tf 0.1
  EXPECT_FLOAT_EQ(water->ior, 1.33f);
  EXPECT_VEC3_NEAR(water->transmittance, Rgb(0.1f), kTight);
  EXPECT_TRUE(std::holds_alternative<DielectricBsdf>(materialNamed(scene, "rightSphere").bsdf));  // illum 7, Ni 2.5
  EXPECT_TRUE(std::holds_alternative<LambertBsdf>(materialNamed(scene, "light").bsdf));  // illum 2 with Tf 1, d 1
}

// ---------------------------------------------------------------------------------------------
// OBJ with a texture

TEST(ObjLoader, TextureIsResolvedRelativeToTheMtlAndSampledBottomLeft) {
  const Scene scene = loadScene(kDataDir + "textured/quad.obj");
  ASSERT_EQ(scene.textures.size(), 1u);
  ASSERT_EQ(scene.triangleCount(), 2u);
  // Where the quad's diagonal falls is tinyobjloader's choice, so find the triangle and
  // barycentrics with uv = (0.25, 0.25) by solving uv = uv0 + b1·(uv1 − uv0) + b2·(uv2 − uv0).
  const Mesh& mesh = scene.meshes[0];
  const Vec2 wanted(0.25f, 0.25f);
  SurfaceHit hit;
  bool found = false;
  for (uint32_t t = 0; t < mesh.triangles.size() && !found; ++t) {
    const UVec3 tri = mesh.triangles[t];
    const glm::mat2 edges(mesh.uvs[tri.y] - mesh.uvs[tri.x], mesh.uvs[tri.z] - mesh.uvs[tri.x]);
    const Vec2 b = glm::inverse(edges) * (wanted - mesh.uvs[tri.x]);
    if (b.x >= 0.0f && b.y >= 0.0f && b.x + b.y <= 1.0f) {
      hit = surfaceAt(scene, 0, t, b);
      found = true;
    }
  }
  ASSERT_TRUE(found);
  EXPECT_NEAR(hit.uv.x, 0.25f, kTight);
  EXPECT_NEAR(hit.uv.y, 0.25f, kTight);
  // (0.25, 0.25) is the centre of the bottom-left texel: blue, exactly (sRGB 255 → 1).
  const Bsdf bsdf = bsdfAt(scene, hit);
  EXPECT_VEC3_NEAR(std::get<LambertBsdf>(bsdf).albedo, Rgb(0.0f, 0.0f, 1.0f), kTight);
}

TEST(ObjLoader, MtlMappingRules) {
  const fs::path dir = scratchDir("mapping");
  fs::copy_file(kDataDir + "checker.png", dir / "checker.png");
  writeFile(dir / "m.mtl",
            "newmtl chrome\r\nKd 0.5 0.5 0.5\r\nKs 0.8 0.8 0.8\r\nillum 3\r\n"  // illum 3: mirror
            "newmtl dark\nKd 0.01 0.01 0.01\nKs 0.6 0.6 0.6\nNs 2000\n"        // Kd≈0, Ks high, Ns high
            "newmtl satin\nKd 0.4 0.4 0.4\nKs 0.5 0.5 0.5\nNs 1000\n"          // Ks < 0.9: Blinn-Phong
            "newmtl lamp\nKd 0.2 0.2 0.2\nKe 5 4 3\n"                           // Lambert + emission
            "newmtl painted\nKd 0.5 0.25 1\nmap_Kd checker.png\n");              // texture × Kd
  std::string obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n";
  for (const char* name : {"chrome", "dark", "satin", "lamp", "painted"}) obj += std::string("usemtl ") + name + "\nf 1/1 2/2 3/3\n";
  const Scene scene = loadScene(writeFile(dir / "m.obj", obj));
  ASSERT_EQ(scene.triangleCount(), 5u);

  const auto& chrome = std::get<MirrorBsdf>(materialNamed(scene, "chrome").bsdf);
  EXPECT_FALSE(chrome.fresnel);
  EXPECT_VEC3_NEAR(chrome.reflectance, Rgb(0.8f), 0.0f);
  EXPECT_TRUE(std::holds_alternative<MirrorBsdf>(materialNamed(scene, "dark").bsdf));
  const auto& satin = std::get<BlinnPhongBsdf>(materialNamed(scene, "satin").bsdf);
  EXPECT_VEC3_NEAR(satin.diffuse, Rgb(0.4f), 0.0f);  // 0.4 + 0.5 ≤ 1: unscaled
  EXPECT_VEC3_NEAR(satin.specular, Rgb(0.5f), 0.0f);
  EXPECT_EQ(satin.exponent, 1000.0f);
  const Material& lamp = materialNamed(scene, "lamp");
  EXPECT_VEC3_NEAR(lamp.emission, Rgb(5.0f, 4.0f, 3.0f), 0.0f);
  EXPECT_VEC3_NEAR(std::get<LambertBsdf>(lamp.bsdf).albedo, Rgb(0.2f), 0.0f);

  // Texture × Kd: the triangle "painted" (index 4) at uv (0.25, 0.25) = b (0.25, 0.25) on
  // uvs (0,0), (1,0), (0,1) is the bottom-left texel, blue: albedo (0, 0, 1)·Kd.
  const SurfaceHit hit = surfaceAt(scene, 0, 4, Vec2(0.25f, 0.25f));
  EXPECT_EQ(scene.materials[hit.material].name, "painted");
  EXPECT_VEC3_NEAR(std::get<LambertBsdf>(bsdfAt(scene, hit)).albedo, Rgb(0.0f, 0.0f, 1.0f), kTight);
}

TEST(ObjLoader, GlassMappingAndRepeatedKeys) {
  const fs::path dir = scratchDir("glass");
  writeFile(dir / "g.mtl",
            // Keys given twice: tinyobjloader keeps the last.
            "newmtl water\nKd 0.01 0.01 0.01\nKs 0.3 0.3 0.3\nTf 0.5 0.5 0.5\nNi 1.2\nillum 7\nNi 1.33\nTf 0.9 0.8 0.7\n"
            "newmtl crystal\nKs 0.04 0.04 0.04\nNs 200\nNi 1.6\nTf 0.95 0.95 0.95\n"  // no illum: glass
            "newmtl pane\nKd 0.5 0.5 0.5\nd 0.25\n"                                   // d < 1: thin
            "newmtl plain\nillum 6\n"                                                 // no Ni, no Tf
            "newmtl lamp\nKd 0.78 0.78 0.78\nNi 1.5\nd 1.0\nTr 0.0\nTf 1 1 1\nillum 2\nKe 1 1 1\n");
  std::string obj = "mtllib g.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
  for (const char* name : {"water", "crystal", "pane", "plain", "lamp"}) obj += std::string("usemtl ") + name + "\nf 1 2 3\n";
  const Scene scene = loadScene(writeFile(dir / "g.obj", obj));
  const auto& water = std::get<DielectricBsdf>(materialNamed(scene, "water").bsdf);
  EXPECT_FLOAT_EQ(water.ior, 1.33f);
  EXPECT_VEC3_NEAR(water.transmittance, Rgb(0.9f, 0.8f, 0.7f), kTight);
  EXPECT_FALSE(water.thin);
  const auto& crystal = std::get<DielectricBsdf>(materialNamed(scene, "crystal").bsdf);
  EXPECT_FLOAT_EQ(crystal.ior, 1.6f);
  EXPECT_TRUE(crystal.isSmooth());
  const auto& pane = std::get<DielectricBsdf>(materialNamed(scene, "pane").bsdf);
  EXPECT_TRUE(pane.thin);
  EXPECT_FLOAT_EQ(pane.ior, 1.5f);
  EXPECT_VEC3_NEAR(pane.transmittance, Rgb(0.75f), kTight);  // (1 − d)·Tf, Tf absent = 1
  const auto& plain = std::get<DielectricBsdf>(materialNamed(scene, "plain").bsdf);
  EXPECT_FLOAT_EQ(plain.ior, 1.5f);
  EXPECT_VEC3_NEAR(plain.transmittance, Rgb(1.0f), 0.0f);
  EXPECT_TRUE(std::holds_alternative<LambertBsdf>(materialNamed(scene, "lamp").bsdf));
}

TEST(JsonScene, DielectricMaterials) {
  const fs::path dir = scratchDir("json_glass");
  writeFile(dir / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const Scene scene = loadScene(writeFile(dir / "g.json", R"({"materials": {
      "glass": {"type": "dielectric", "ior": 1.5, "transmittance": [0.9, 0.9, 0.8], "absorption": [0.1, 0.2, 0.3]},
      "frosted": {"type": "dielectric", "ior": 1.33, "roughness": 0.3},
      "window": {"type": "dielectric", "thin": true}},
    "meshes": [{"file": "tri.obj", "material": "glass"}, {"file": "tri.obj", "material": "frosted"},
               {"file": "tri.obj", "material": "window"}]})"));
  const auto& glass = std::get<DielectricBsdf>(materialNamed(scene, "glass").bsdf);
  EXPECT_FLOAT_EQ(glass.ior, 1.5f);
  EXPECT_VEC3_NEAR(glass.transmittance, Rgb(0.9f, 0.9f, 0.8f), kTight);
  EXPECT_VEC3_NEAR(glass.absorption, Rgb(0.1f, 0.2f, 0.3f), kTight);
  EXPECT_TRUE(glass.isSmooth());
  EXPECT_NEAR(std::get<DielectricBsdf>(materialNamed(scene, "frosted").bsdf).alpha, 0.09f, kTight);
  EXPECT_TRUE(std::get<DielectricBsdf>(materialNamed(scene, "window").bsdf).thin);
  const fs::path bad = dir / "bad.json";
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "dielectric", "thin": true, "roughness": 0.2}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "thin", "roughness"});
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "dielectric", "transmittance": 1.5}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "transmittance"});
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "dielectric", "ior": -1}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "index of refraction"});
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "dielectric", "absorption": -1}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "absorption"});
}

TEST(JsonScene, SubsurfaceMaterials) {
  const fs::path dir = scratchDir("json_sss");
  // A closed tetrahedron (wound outwards) and an open triangle.
  writeFile(dir / "tet.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  writeFile(dir / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const Scene scene = loadScene(writeFile(dir / "s.json", R"({"materials": {
      "marble": {"type": "subsurface", "albedo": [0.9, 0.8, 0.7], "radius": [0.3, 0.2, 0.1], "tixel_density": 2},
      "wax": {"type": "subsurface", "radius": 0.5}},
    "meshes": [{"file": "tet.obj", "material": "marble"}, {"file": "tri.obj", "material": "wax"}]})"));
  const auto& marble = std::get<SubsurfaceBsdf>(materialNamed(scene, "marble").bsdf);
  EXPECT_VEC3_NEAR(marble.albedo, Rgb(0.9f, 0.8f, 0.7f), kTight);
  EXPECT_VEC3_NEAR(marble.radius, Rgb(0.3f, 0.2f, 0.1f), kTight);
  const auto& wax = std::get<SubsurfaceBsdf>(materialNamed(scene, "wax").bsdf);
  EXPECT_VEC3_NEAR(wax.albedo, Rgb(0.8f), kTight);  // the default, as Lambert's
  EXPECT_VEC3_NEAR(wax.radius, Rgb(0.5f), kTight);
  // The closed tetrahedron has no open edge; the lone triangle (which loads with a warning
  // naming it) has three.
  ASSERT_EQ(scene.meshes.size(), 2u);
  EXPECT_EQ(openSubsurfaceEdges(scene, scene.meshes[0]), 0u);
  EXPECT_EQ(openSubsurfaceEdges(scene, scene.meshes[1]), 3u);

  const fs::path bad = dir / "bad.json";
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "subsurface", "albedo": 0.5}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "materials.w", "radius"});
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "subsurface", "albedo": 1, "radius": 1}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "'w'", "subsurface albedo", "[0, 1)"});
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "subsurface", "albedo": -0.5, "radius": 1}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "subsurface albedo"});
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "subsurface", "radius": [1, 0, 1]}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "'w'", "subsurface radius"});
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "subsurface", "radius": "big"}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "materials.w.radius"});
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "subsurface", "radius": 1, "ior": 1.4}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "materials.w", "unknown key 'ior'"});
}

// A ggx material with any glTF layer key is the layered model (bsdf.h GltfPbrBsdf); without,
// it stays GgxBsdf.
TEST(JsonScene, LayeredGgxMaterials) {
  const fs::path dir = scratchDir("json_layers");
  writeFile(dir / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const Scene scene = loadScene(writeFile(dir / "l.json", R"({"materials": {
      "lacquer": {"type": "ggx", "diffuse": 0.7, "roughness": 0.6, "clearcoat": 1, "clearcoat_roughness": 0.1},
      "velvet": {"type": "ggx", "diffuse": [0.5, 0.05, 0.05], "roughness": 0.9, "sheen": [1, 0.6, 0.6], "sheen_roughness": 0.4,
                 "f90": 0.5},
      "plain": {"type": "ggx", "diffuse": 0.5, "roughness": 0.5}},
    "meshes": [{"file": "tri.obj", "material": "lacquer"}, {"file": "tri.obj", "material": "velvet"},
               {"file": "tri.obj", "material": "plain"}]})"));
  const auto& lacquer = std::get<GltfPbrBsdf>(materialNamed(scene, "lacquer").bsdf);
  EXPECT_NEAR(lacquer.alpha, 0.36f, kTight);
  EXPECT_FLOAT_EQ(lacquer.clearcoat, 1.0f);
  EXPECT_NEAR(lacquer.clearcoatAlpha, 0.01f, kTight);
  EXPECT_EQ(lacquer.sheenColor, Rgb(0.0f));
  EXPECT_FLOAT_EQ(lacquer.f90, 1.0f);
  const auto& velvet = std::get<GltfPbrBsdf>(materialNamed(scene, "velvet").bsdf);
  EXPECT_VEC3_NEAR(velvet.sheenColor, Rgb(1.0f, 0.6f, 0.6f), kTight);
  EXPECT_FLOAT_EQ(velvet.sheenRoughness, 0.4f);
  EXPECT_FLOAT_EQ(velvet.f90, 0.5f);
  EXPECT_FLOAT_EQ(velvet.clearcoat, 0.0f);
  EXPECT_TRUE(std::holds_alternative<GgxBsdf>(materialNamed(scene, "plain").bsdf));
  const fs::path bad = dir / "bad.json";
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "ggx", "clearcoat": 2}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "clearcoat"});
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "ggx", "clearcoat_roughness": -1}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "clearcoat_roughness"});
  writeFile(bad, R"({"include_cornell": true, "materials": {"w": {"type": "ggx", "sheen": 1.5}}})");
  expectError([&] { loadScene(bad.string()); }, {"bad.json", "sheen"});
}

TEST(JsonScene, TixelDensityPerMaterial) {
  const fs::path dir = scratchDir("json_tixel_density");
  writeFile(dir / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const Scene scene = loadScene(writeFile(dir / "d.json", R"({"materials": {
      "fine": {"type": "lambert", "tixel_density": 4}, "plain": {"type": "lambert"}},
    "meshes": [{"file": "tri.obj", "material": "fine"}, {"file": "tri.obj", "material": "plain"}]})"));
  EXPECT_FLOAT_EQ(materialNamed(scene, "fine").tixelDensity, 4.0f);
  EXPECT_FLOAT_EQ(materialNamed(scene, "plain").tixelDensity, 1.0f);
  const fs::path bad = dir / "bad.json";
  for (const char* value : {"0", "-2", "\"x\""}) {
    writeFile(bad, std::string(R"({"include_cornell": true, "materials": {"w": {"type": "lambert", "tixel_density": )") +
                       value + "}}}");
    expectError([&] { loadScene(bad.string()); }, {"bad.json", "materials.w", "tixel_density"});
  }
}

/// A one-triangle glTF whose material carries `extensions` (a JSON object body).
std::string gltfTriangleWithMaterial(const fs::path& path, const std::string& extensions) {
  return writeFile(path, R"({"asset": {"version": "2.0"},
    "buffers": [{"byteLength": 44, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA="}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
                  {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
    "materials": [{"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 0.7, 1], "metallicFactor": 0,
                   "roughnessFactor": 0.5}, "extensions": {)" + extensions + R"(}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]})");
}

TEST(GltfLoader, TransmissionIorAndVolume) {
  const fs::path dir = scratchDir("gltf_glass");
  {
    // Transmission alone: a thin (smooth) sheet tinted by baseColor, default index 1.5.
    const Scene scene = loadScene(gltfTriangleWithMaterial(dir / "thin.gltf", R"("KHR_materials_transmission": {"transmissionFactor": 1})"));
    const auto& glass = std::get<DielectricBsdf>(materialNamed(scene, "glass").bsdf);
    EXPECT_TRUE(glass.thin);
    EXPECT_FLOAT_EQ(glass.ior, 1.5f);
    EXPECT_VEC3_NEAR(glass.transmittance, Rgb(0.9f, 0.8f, 0.7f), kTight);
  }
  {
    // With a volume: solid rough glass, absorption −ln(c)/d.
    const Scene scene = loadScene(gltfTriangleWithMaterial(dir / "solid.gltf",
        R"("KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_ior": {"ior": 1.33},
           "KHR_materials_volume": {"thicknessFactor": 0.2, "attenuationDistance": 2.0, "attenuationColor": [0.5, 0.25, 1.0]})"));
    const auto& glass = std::get<DielectricBsdf>(materialNamed(scene, "glass").bsdf);
    EXPECT_FALSE(glass.thin);
    EXPECT_FLOAT_EQ(glass.ior, 1.33f);
    EXPECT_FLOAT_EQ(glass.alpha, 0.25f);  // roughness 0.5²
    EXPECT_VEC3_NEAR(glass.absorption, Rgb(std::log(2.0f) / 2.0f, std::log(4.0f) / 2.0f, 0.0f), kTight);
  }
  {
    // thicknessFactor 0: thin again.
    const Scene scene = loadScene(gltfTriangleWithMaterial(dir / "zero.gltf",
        R"("KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_volume": {"thicknessFactor": 0})"));
    EXPECT_TRUE(std::get<DielectricBsdf>(materialNamed(scene, "glass").bsdf).thin);
  }
  expectError([&] {
    loadScene(gltfTriangleWithMaterial(dir / "bad.gltf",
        R"("KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_volume": {"thicknessFactor": 1, "attenuationDistance": -1})"));
  }, {"bad.gltf", "attenuationDistance"});
}

// ---------------------------------------------------------------------------------------------
// glTF

class GltfFile : public testing::TestWithParam<const char*> {};

TEST_P(GltfFile, HierarchyCamerasLightsAndMaterial) {
  const Scene scene = loadScene(kDataDir + GetParam());
  // The line primitive is skipped; the quad is 2 triangles.
  EXPECT_EQ(scene.triangleCount(), 2u);
  // World transform of the quad: Parent (T(0,1,0)·R_y(90°)) · Quad (T(0,0,−2)·S(2,1,1)).
  // A local point (x, y, 0) → (2x, y, −2) → R_y: (x,y,z) ↦ (z, y, −x) gives (−2, y, −2x)
  // → (−2, y + 1, −2x). So the quad spans x = −2, y ∈ [0, 2], z ∈ [−2, 2].
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  EXPECT_VEC3_NEAR(lo, Vec3(-2.0f, 0.0f, -2.0f), kTight);
  EXPECT_VEC3_NEAR(hi, Vec3(-2.0f, 2.0f, 2.0f), kTight);
  // Geometric normal: local +z ↦ (1, 0, 0). Shading normal: local (1,0,1)/√2 through the
  // inverse transpose of S(2,1,1) (= S(½,1,1)) ∝ (½, 0, 1), then R_y ↦ (1, 0, −½)/√1.25.
  // (Transforming it by S itself would give (1, 0, −2)/√5 instead.)
  const SurfaceHit hit = surfaceAt(scene, 0, 1, Vec2(0.25f, 0.5f));
  EXPECT_VEC3_NEAR(hit.geometricNormal, Vec3(1.0f, 0.0f, 0.0f), kTight);
  EXPECT_VEC3_NEAR(hit.shadingNormal, glm::normalize(Vec3(1.0f, 0.0f, -0.5f)), kTight);
  // Triangle 1 = (v0, v2, v3) with our (v-flipped) uvs (0,0), (1,1), (0,1):
  // uv = (b1, b1 + b2) = (0.25, 0.75), the centre of the image's top-left texel (red).
  EXPECT_NEAR(hit.uv.x, 0.25f, kTight);
  EXPECT_NEAR(hit.uv.y, 0.75f, kTight);

  // Material (metalness 0.25: glTF's mix of a dielectric and a metal, bsdf.h
  // gltfMetallicRoughnessModel): diffuse = 0.5·(1 − 0.25) = 0.375, f0 = 0.04 + 0.25·(0.5 −
  // 0.04) = 0.155, the diffuse under the dielectric's f0 0.04, alpha = 0.5² = 0.25, emission =
  // (1, 0.5, 0)·4.
  const Material& material = materialNamed(scene, "textured");
  const auto& ggx = std::get<GltfPbrBsdf>(material.bsdf);
  EXPECT_VEC3_NEAR(ggx.diffuse, Rgb(0.375f), kTight);
  EXPECT_VEC3_NEAR(ggx.f0, Rgb(0.155f), kTight);
  EXPECT_VEC3_NEAR(ggx.dielectricF0, Rgb(0.04f), kTight);
  EXPECT_NEAR(ggx.alpha, 0.25f, kTight);
  EXPECT_VEC3_NEAR(material.emission, Rgb(4.0f, 2.0f, 0.0f), kTight);
  const auto textured = std::get<GltfPbrBsdf>(bsdfAt(scene, hit));
  EXPECT_VEC3_NEAR(textured.diffuse, Rgb(0.375f, 0.0f, 0.0f), kTight);

  // Camera under Parent at local (0,0,5): eye (5, 1, 0), looking down local −z ↦ (−1, 0, 0).
  const CameraDesc& camera = scene.camera("Camera");
  EXPECT_VEC3_NEAR(camera.eye, Vec3(5.0f, 1.0f, 0.0f), kTight);
  EXPECT_VEC3_NEAR(glm::normalize(camera.target - camera.eye), Vec3(-1.0f, 0.0f, 0.0f), kTight);
  EXPECT_VEC3_NEAR(camera.up, Vec3(0.0f, 1.0f, 0.0f), kTight);
  EXPECT_NEAR(camera.fovYDegrees, 0.5f * 180.0f / kPi, 1e-4f);
  ASSERT_TRUE(camera.aspectRatio.has_value());
  EXPECT_NEAR(*camera.aspectRatio, 1.5f, kTight);

  // Lights: 683 cd → 1 W/sr and 1366 lx → 2 W/m² (683 lm/W).
  ASSERT_EQ(scene.lights.size(), 3u);
  const auto& point = std::get<PointLight>(scene.lights[0]);
  EXPECT_VEC3_NEAR(point.position, Vec3(0.0f, 3.0f, 0.0f), kTight);
  EXPECT_VEC3_NEAR(point.intensity, Rgb(1.0f, 0.5f, 0.25f), kTight);
  const auto& sun = std::get<DirectionalLight>(scene.lights[1]);
  EXPECT_VEC3_NEAR(sun.direction, Vec3(0.0f, 0.0f, -1.0f), kTight);
  EXPECT_VEC3_NEAR(sun.irradiance, Rgb(2.0f), kTight);
  // Spot: R_x(−90°) maps (x, y, z) ↦ (x, z, −y), so the node's −z axis becomes −y (down).
  const auto& spot = std::get<SpotLight>(scene.lights[2]);
  EXPECT_VEC3_NEAR(spot.position, Vec3(1.0f, 4.0f, 0.0f), kTight);
  EXPECT_VEC3_NEAR(spot.direction, Vec3(0.0f, -1.0f, 0.0f), kTight);
  EXPECT_VEC3_NEAR(spot.intensity, Rgb(2.0f), kTight);
  EXPECT_NEAR(spot.innerAngle, 0.2f, kTight);
  EXPECT_NEAR(spot.outerAngle, 0.4f, kTight);
}

INSTANTIATE_TEST_SUITE_P(Scene, GltfFile, testing::Values("quad.gltf", "quad.glb"));

// ---------------------------------------------------------------------------------------------
// JSON scene

TEST(JsonScene, CombinesFilesWithTransformsOverridesLightsCamerasAndEnvironment) {
  const Scene scene = loadScene(kDataDir + "scene.json");
  EXPECT_EQ(scene.triangleCount(), 4u);  // OBJ quad + glTF quad
  // OBJ quad (unit square in z = 0) under T(0,0,−1)·S(2): corners (0..2, 0..2, −1).
  const Mesh& obj = scene.meshes[0];
  Vec3 lo(kInfinity), hi(-kInfinity);
  for (const Vec3& p : obj.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  EXPECT_VEC3_NEAR(lo, Vec3(0.0f, 0.0f, -1.0f), kTight);
  EXPECT_VEC3_NEAR(hi, Vec3(2.0f, 2.0f, -1.0f), kTight);
  // Its "checker" material is replaced by the JSON one (albedo 0.5, with texture).
  const Material& checker = scene.materials[obj.materials[0]];
  EXPECT_EQ(checker.name, "checker");
  EXPECT_VEC3_NEAR(std::get<LambertBsdf>(checker.bsdf).albedo, Rgb(0.5f), 0.0f);
  ASSERT_GE(checker.albedoTexture, 0);
  // The glTF quad: forced to "gold" and moved by +10 in x (row-major matrix).
  const Mesh& gltf = scene.meshes[1];
  for (uint32_t material : gltf.materials) EXPECT_EQ(scene.materials[material].name, "gold");
  for (const Vec3& p : gltf.positions) EXPECT_NEAR(p.x, 8.0f, kTight);
  EXPECT_NEAR(std::get<GgxBsdf>(materialNamed(scene, "gold").bsdf).alpha, 0.09f, kTight);  // 0.3²
  // Lights: the glTF point and sun (appended with their file) + the JSON spot (direction
  // normalised, angles in radians).
  ASSERT_EQ(scene.lights.size(), 4u);
  EXPECT_VEC3_NEAR(std::get<PointLight>(scene.lights[0]).position, Vec3(10.0f, 3.0f, 0.0f), kTight);
  EXPECT_TRUE(std::holds_alternative<DirectionalLight>(scene.lights[1]));
  EXPECT_VEC3_NEAR(std::get<SpotLight>(scene.lights[2]).position, Vec3(11.0f, 4.0f, 0.0f), kTight);
  const auto& spot = std::get<SpotLight>(scene.lights[3]);
  EXPECT_VEC3_NEAR(spot.direction, Vec3(0.0f, -1.0f, 0.0f), kTight);
  EXPECT_NEAR(spot.outerAngle, 20.0f * kPi / 180.0f, kTight);
  // Cameras: the glTF one moved along, and the JSON one with its thin lens.
  EXPECT_VEC3_NEAR(scene.camera("Camera").eye, Vec3(15.0f, 1.0f, 0.0f), kTight);
  const CameraDesc& main = scene.camera("main");
  EXPECT_EQ(main.fovYDegrees, 45.0f);
  EXPECT_EQ(main.fNumber, 2.8f);
  EXPECT_EQ(main.focusDistance, 5.0f);
  EXPECT_VEC3_NEAR(scene.environment.constant, Rgb(0.1f, 0.2f, 0.3f), 0.0f);
  EXPECT_EQ(scene.settings.width, 320);
  EXPECT_EQ(scene.settings.height, 240);
  EXPECT_EQ(scene.settings.spp, 16);
  EXPECT_EQ(scene.settings.camera, "main");
}

TEST(JsonScene, MirroringTransformKeepsTheFrontSide) {
  // The OBJ quad faces +z. Mirroring x (det = −1) would flip the winding's normal to −z unless
  // the loader swaps the winding; the front must stay +z, and vertex x coordinates negate.
  const fs::path dir = scratchDir("mirror_transform");
  const std::string path = writeFile(dir / "m.json", "{\"meshes\": [{\"file\": \"" + kDataDir +
                                                         "textured/quad.obj\", \"transform\": {\"scale\": [-1, 1, 1]}}]}");
  const Scene scene = loadScene(path);
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  EXPECT_VEC3_NEAR(lo, Vec3(-1.0f, 0.0f, 0.0f), 0.0f);
  EXPECT_VEC3_NEAR(hi, Vec3(0.0f, 1.0f, 0.0f), 0.0f);
  for (uint32_t t = 0; t < scene.meshes[0].triangles.size(); ++t)
    EXPECT_VEC3_NEAR(surfaceAt(scene, 0, t, Vec2(0.25f)).geometricNormal, Vec3(0, 0, 1), kTight);
}

TEST(JsonScene, IncludeCornell) {
  const fs::path dir = scratchDir("include_cornell");
  const std::string path = writeFile(dir / "c.json", R"({"include_cornell": true, "environment": {"color": 0.5}})");
  const Scene scene = loadScene(path);
  EXPECT_EQ(scene.triangleCount(), 32u);
  EXPECT_NO_THROW(scene.camera("cornell"));
  EXPECT_VEC3_NEAR(scene.environment.constant, Rgb(0.5f), 0.0f);
}

// ---------------------------------------------------------------------------------------------
// Surface data, automatic camera

Scene oneTriangle() {
  Scene scene;
  scene.sourcePath = "triangle";
  scene.materials.push_back({.name = "grey"});
  Mesh mesh;
  mesh.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  mesh.triangles = {UVec3(0, 1, 2)};
  mesh.materials = {0};
  scene.meshes.push_back(mesh);
  return scene;
}

TEST(SurfaceAt, PositionNormalsAndUv) {
  Scene scene = oneTriangle();
  // Vertex normals tilted, deliberately pointing to the back side and not unit length:
  // finalize() normalises them, surfaceAt() flips the interpolated one to the front.
  scene.meshes[0].normals = {Vec3(0, 0, -2), Vec3(1, 0, -1), Vec3(0, 0, -3)};
  scene.meshes[0].uvs = {Vec2(0, 0), Vec2(2, 0), Vec2(0, 4)};
  scene.finalize();
  const SurfaceHit hit = surfaceAt(scene, 0, 0, Vec2(0.5f, 0.25f));
  EXPECT_VEC3_NEAR(hit.position, Vec3(0.5f, 0.25f, 0.0f), kTight);
  EXPECT_VEC3_NEAR(hit.geometricNormal, Vec3(0, 0, 1), kTight);
  // Interpolated: 0.25·(0,0,−1) + 0.5·(1,0,−1)/√2 + 0.25·(0,0,−1), normalised, flipped.
  const Vec3 n = 0.25f * Vec3(0, 0, -1) + 0.5f * Vec3(1, 0, -1) / std::sqrt(2.0f) + 0.25f * Vec3(0, 0, -1);
  EXPECT_VEC3_NEAR(hit.shadingNormal, -glm::normalize(n), kTight);
  EXPECT_VEC3_NEAR(Vec3(hit.uv, 0.0f), Vec3(1.0f, 1.0f, 0.0f), kTight);  // 0.5·(2,0) + 0.25·(0,4)
  EXPECT_EQ(hit.material, 0u);
}

TEST(SurfaceAt, OpposingNormalsFallBackToGeometric) {
  Scene scene = oneTriangle();
  scene.meshes[0].normals = {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 0, 0)};
  scene.finalize();
  // b0 = b1 = 0.5: the two vertex normals cancel exactly.
  const SurfaceHit hit = surfaceAt(scene, 0, 0, Vec2(0.5f, 0.0f));
  EXPECT_VEC3_NEAR(hit.shadingNormal, Vec3(0, 0, 1), 0.0f);
}

TEST(Finalize, DropsDegenerateTrianglesAndPadsVertices) {
  Scene scene = oneTriangle();
  Mesh& mesh = scene.meshes[0];
  mesh.positions.push_back(Vec3(2, 0, 0));  // collinear with vertices 0 and 1
  mesh.triangles.push_back(UVec3(0, 1, 3));
  mesh.triangles.push_back(UVec3(0, 0, 2));  // repeated vertex
  mesh.materials = {0, 0, 0};
  scene.finalize();
  EXPECT_EQ(scene.triangleCount(), 1u);
  EXPECT_GE(scene.meshes[0].positions.capacity(), scene.meshes[0].positions.size() + 1);
}

TEST(AutomaticCamera, FramesTheBoundingBox) {
  const Scene scene = makeCornellBox();
  const CameraDesc camera = scene.automaticCamera();
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  const Vec3 view = glm::normalize(camera.target - camera.eye);
  EXPECT_VEC3_NEAR(view, Vec3(0, 0, -1), kTight);  // looks along −z
  EXPECT_VEC3_NEAR(camera.target, 0.5f * (lo + hi), 1e-3f);
  // Every corner of the box lies inside the cone of half-angle fov/2 around the view axis
  // (a fortiori inside the vertical field of view), and the bounding sphere touches it:
  // |eye − centre|·sin(fov/2) = radius (to float rounding of values ~1e3: 1e-3 relative).
  const float halfFov = glm::radians(camera.fovYDegrees) * 0.5f;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z);
    const float angle = std::acos(glm::dot(glm::normalize(p - camera.eye), view));
    EXPECT_LE(angle, halfFov) << "corner " << corner;
  }
  const float radius = 0.5f * glm::length(hi - lo);
  EXPECT_NEAR(glm::length(camera.target - camera.eye) * std::sin(halfFov), radius, 1e-3f * radius);
}

// ---------------------------------------------------------------------------------------------
// Bad input: one test per kind; each message names the file.

TEST(BadInput, MissingFile) {
  expectError([] { loadScene("/nonexistent/dir/box.obj"); }, {"/nonexistent/dir/box.obj", "no such file"});
}

TEST(BadInput, UnknownExtensionListsSupportedFormats) {
  const fs::path dir = scratchDir("ext");
  const std::string path = writeFile(dir / "scene.fbx", "x");
  expectError([&] { loadScene(path); }, {"scene.fbx", ".obj", ".gltf", ".glb", ".json"});
}

TEST(BadInput, MalformedObjNonNumericCoordinate) {
  const fs::path dir = scratchDir("obj_nan_text");
  const std::string path = writeFile(dir / "bad.obj", "v 0 0 0\r\nv 1 zero 0\r\nv 0 1 0\r\nf 1 2 3\r\n");
  expectError([&] { loadScene(path); }, {"bad.obj:2", "zero"});
}

TEST(BadInput, MalformedObjIndexOutOfRange) {
  const fs::path dir = scratchDir("obj_index");
  const std::string path = writeFile(dir / "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  expectError([&] { loadScene(path); }, {"bad.obj:4", "out of range"});
}

TEST(BadInput, MalformedMtl) {
  const fs::path dir = scratchDir("mtl");
  writeFile(dir / "bad.mtl", "newmtl a\nKd 0.5 abc 0.5\n");
  const std::string path = writeFile(dir / "m.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  expectError([&] { loadScene(path); }, {"bad.mtl:2", "abc"});
}

TEST(BadInput, MissingTexture) {
  const fs::path dir = scratchDir("tex");
  writeFile(dir / "t.mtl", "newmtl a\nKd 1 1 1\nmap_Kd nothere.png\n");
  const std::string path = writeFile(dir / "t.obj", "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  expectError([&] { loadScene(path); }, {"nothere.png", "not found"});
}

TEST(BadInput, MissingGltfTexture) {
  const fs::path dir = scratchDir("gltf_tex");
  fs::copy_file(kDataDir + "quad.gltf", dir / "quad.gltf");  // without its checker.png
  expectError([&] { loadScene((dir / "quad.gltf").string()); }, {"quad.gltf", "checker.png", "not found"});
}

TEST(BadInput, MissingMtlIsOnlyAWarning) {
  const fs::path dir = scratchDir("nomtl");
  const std::string path = writeFile(dir / "t.obj", "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  const Scene scene = loadScene(path);
  ASSERT_EQ(scene.triangleCount(), 1u);
  const Material& material = scene.materials[scene.meshes[0].materials[0]];
  EXPECT_VEC3_NEAR(std::get<LambertBsdf>(material.bsdf).albedo, Rgb(0.8f), 0.0f);
}

TEST(BadInput, MalformedGltf) {
  const fs::path dir = scratchDir("gltf");
  const std::string text = writeFile(dir / "bad.gltf", R"({"asset": {"version": "2.0"}, "nodes": [)");
  expectError([&] { loadScene(text); }, {"bad.gltf"});
  const std::string binary = writeFile(dir / "bad.glb", "glTF\x02\x00\x00\x00garbage");
  expectError([&] { loadScene(binary); }, {"bad.glb"});
}

TEST(BadInput, GltfIndexOutOfRange) {
  // A valid glTF whose only triangle refers to vertex 7 of 3.
  const fs::path dir = scratchDir("gltf_index");
  // 3 float3 positions (36 bytes) followed by 3 uint16 indices 0, 1, 7 (6 bytes, padded to 8).
  const std::string blob =
      "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAcAAAA=";  // base64 of the above
  const std::string path = writeFile(dir / "index.gltf", R"({"asset": {"version": "2.0"},
    "buffers": [{"byteLength": 44, "uri": "data:application/octet-stream;base64,)" + blob + R"("}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]})");
  expectError([&] { loadScene(path); }, {"index.gltf", "vertex 7"});
}

TEST(BadInput, MalformedJson) {
  const fs::path dir = scratchDir("json");
  const std::string path = writeFile(dir / "bad.json", R"({"meshes": [ {"file": "a.obj"} )");
  expectError([&] { loadScene(path); }, {"bad.json", "malformed JSON"});
}

TEST(BadInput, NanVertex) {
  const fs::path dir = scratchDir("nan");
  const std::string path = writeFile(dir / "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  expectError([&] { loadScene(path); }, {"nan.obj:2", "'nan' is not a finite number"});
  // The same check in Scene::finalize() for scenes built by code or other loaders.
  Scene scene = oneTriangle();
  scene.sourcePath = "built.scene";
  scene.meshes[0].positions[1].y = std::numeric_limits<float>::quiet_NaN();
  expectError([&] { scene.finalize(); }, {"built.scene", "vertex 1 is not finite"});
  Scene infinite = oneTriangle();
  infinite.meshes[0].positions[2].z = kInfinity;
  expectError([&] { infinite.finalize(); }, {"triangle", "vertex 2 is not finite"});
}

TEST(BadInput, MeshWithNoTriangles) {
  const fs::path dir = scratchDir("empty");
  const std::string path = writeFile(dir / "empty.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  expectError([&] { loadScene(path); }, {"empty.obj", "no triangles"});
  // Only degenerate triangles is the same problem, said differently.
  const std::string flat = writeFile(dir / "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  expectError([&] { loadScene(flat); }, {"flat.obj", "degenerate"});
}

TEST(BadInput, UnknownMaterialModel) {
  const fs::path dir = scratchDir("material");
  const std::string path = writeFile(dir / "m.json", R"({"include_cornell": true,
      "materials": {"shiny": {"type": "phong", "albedo": [1, 1, 1]}}})");
  expectError([&] { loadScene(path); }, {"m.json", "materials.shiny", "phong"});
}

TEST(BadInput, JsonTyposAndDanglingNamesAreErrors) {
  const fs::path dir = scratchDir("json_typos");
  const std::string key = writeFile(dir / "k.json", R"({"include_cornell": true, "camras": []})");
  expectError([&] { loadScene(key); }, {"k.json", "unknown key 'camras'"});
  const std::string camera = writeFile(dir / "c.json", R"({"include_cornell": true, "settings": {"camera": "top"}})");
  expectError([&] { loadScene(camera); }, {"c.json", "no camera named 'top'", "'cornell'"});
  const std::string type = writeFile(dir / "t.json", R"({"include_cornell": true, "lights": [{"type": "point", "position": "up"}]})");
  expectError([&] { loadScene(type); }, {"t.json", "lights[0].position"});
}

TEST(BadInput, EmptyFaceIndexFieldsAreErrorsWithTheLine) {
  // tinyobjloader reads an empty texture or normal index as index 0 of an empty array (a
  // crash before the validator refused these): "v/" "v/vt/" and "v//" name an element
  // without an index; only the "v//vn" form may leave the texture coordinate empty.
  expectError([] { loadScene(kFuzzCorpus + "obj/empty_texcoord_index.obj"); },
              {"empty_texcoord_index.obj:2", "empty texture coordinate index in '1/'"});
  expectError([] { loadScene(kFuzzCorpus + "obj/empty_texcoord_index_middle.obj"); },
              {"empty_texcoord_index_middle.obj:4", "empty texture coordinate index in '2/'"});
  expectError([] { loadScene(kFuzzCorpus + "obj/empty_normal_index.obj"); },
              {"empty_normal_index.obj:2", "empty normal index in '1//'"});
  const fs::path dir = scratchDir("empty_index");
  const std::string trailing = writeFile(dir / "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1/ 2 3\n");
  expectError([&] { loadScene(trailing); }, {"t.obj:5", "empty normal index in '1/1/'"});
  // v//vn stays valid.
  const std::string normals = writeFile(dir / "n.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n");
  EXPECT_EQ(loadScene(normals).triangleCount(), 1u);
}

TEST(BadInput, PathComponentsLongerThanTheSystemAllowsAreCleanErrors) {
  // std::filesystem::exists throws on ENAMETOOLONG; every referenced file goes through
  // inputFileProblem instead, which gives the system's reason.
  const std::string tooLong(300, 'a');
  const fs::path dir = scratchDir("long_names");
  const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl m\nf 1/1 2/1 3/1\n";
  // A material library that cannot be opened is a warning, as a missing one is.
  const std::string mtllib = writeFile(dir / "lib.obj", "mtllib " + tooLong + ".mtl\n" + triangle);
  EXPECT_EQ(loadScene(mtllib).triangleCount(), 1u);
  writeFile(dir / "tex.mtl", "newmtl m\nKd 1 1 1\nmap_Kd " + tooLong + ".png\n");
  const std::string texture = writeFile(dir / "tex.obj", "mtllib tex.mtl\n" + triangle);
  expectError([&] { loadScene(texture); }, {"tex.mtl", "material 'm'", "File name too long"});
  const std::string json = writeFile(dir / "t.json", R"({"include_cornell": true,
      "materials": {"m": {"type": "lambert", "texture": ")" + tooLong + R"(.png"}}})");
  expectError([&] { loadScene(json); }, {"t.json", "materials.m", "File name too long"});
  const std::string environment = writeFile(dir / "e.json", R"({"include_cornell": true,
      "environment": {"file": ")" + tooLong + R"(/{face}.hdr"}})");
  expectError([&] { loadScene(environment); }, {"e.json", "environment.file"});
  std::ifstream in(kDataDir + "quad.gltf", std::ios::binary);
  std::string gltf((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t uri = gltf.find("checker.png");
  ASSERT_NE(uri, std::string::npos);
  gltf.replace(uri, 11, tooLong + ".png");
  const std::string longUri = writeFile(dir / "quad.gltf", gltf);
  expectError([&] { loadScene(longUri); }, {"quad.gltf", "File name too long"});
}

TEST(BadInput, GlbOnWhichTinygltfThrowsIsAnInvalidFile) {
  // A GLB buffer of byteLength 0 beside a BIN chunk: tinygltf throws std::out_of_range.
  expectError([] { loadScene(kFuzzCorpus + "gltf/zero_length_buffer.glb"); },
              {"zero_length_buffer.glb", "not a valid glTF file"});
  // Found by fuzz_gltf: an embedded PNG whose buffer view runs past its buffer (tinygltf read
  // past the end; ASan saw a use-after-free).
  expectError([] { loadScene(kFuzzCorpus + "gltf/image-view-past-buffer-end.glb"); },
              {"image-view-past-buffer-end.glb", "buffer view 5 runs past the end of its buffer"});
}

TEST(BadInput, JsonNumberBeyondADoubleIsAMalformedFile) {
  // nlohmann::json throws out_of_range (not parse_error) for 1e400.
  expectError([] { loadScene(kFuzzCorpus + "json_scene/number_overflow.json"); }, {"number_overflow.json", "malformed JSON", "1e400"});
}

/// Loads prefixes of `source`, saved as `name` (every length up to 48 bytes, where the headers
/// are, then 48 lengths spread over the rest): each must load or throw pl::Error naming the
/// file — never crash or throw anything else.
void loadEveryPrefix(const std::string& source, const std::string& name) {
  std::ifstream in(source, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(bytes.empty());
  const fs::path dir = scratchDir("prefix_" + name);
  if (fs::exists(fs::path(source).parent_path() / "checker.png"))
    fs::copy_file(fs::path(source).parent_path() / "checker.png", dir / "checker.png");
  const std::string path = (dir / name).string();
  size_t loaded = 0, rejected = 0;
  const size_t step = std::max<size_t>(1, bytes.size() / 48);
  for (size_t length = 0; length < bytes.size(); length += length < 48 ? 1 : step) {
    writeFile(path, bytes.substr(0, length));
    try {
      loadScene(path);
      ++loaded;
    } catch (const Error& e) {
      ++rejected;
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << name << " truncated to " << length << " bytes threw a non-pl::Error: " << e.what();
    }
  }
  EXPECT_GT(rejected, 0u);
}

TEST(BadInput, TruncatedFilesAreRejectedCleanly) {
  loadEveryPrefix(kDataDir + "quad.glb", "quad.glb");
  loadEveryPrefix(kDataDir + "quad.gltf", "quad.gltf");
  loadEveryPrefix(kDataDir + "scene.json", "scene.json");
  loadEveryPrefix(kMcGuireDir + "CornellBox-Original.obj", "CornellBox-Original.obj");
}

TEST(BadInput, MutatedGltfNumbersAreRejectedCleanly) {
  // Replaces each number of quad.gltf in turn by values that break indices, counts, offsets
  // and enums (-1, 7, 2^32, 1e30); each variant must load or throw pl::Error naming the file.
  std::ifstream in(kDataDir + "quad.gltf", std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const fs::path dir = scratchDir("mutated_gltf");
  fs::copy_file(kDataDir + "checker.png", dir / "checker.png");
  const std::string path = (dir / "mutated.gltf").string();
  const std::regex number(R"(([:\[,]\s*)(-?[0-9]+(\.[0-9]+)?))");
  size_t variants = 0, rejected = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), number); it != std::sregex_iterator(); ++it) {
    const std::smatch& match = *it;
    const size_t begin = size_t(match.position(2)), length = size_t(match.length(2));
    for (const char* replacement : {"-1", "7", "4294967296", "1e30"}) {
      writeFile(path, text.substr(0, begin) + replacement + text.substr(begin + length));
      ++variants;
      try {
        loadScene(path);
      } catch (const Error& e) {
        ++rejected;
        EXPECT_NE(std::string(e.what()).find("mutated.gltf"), std::string::npos) << e.what();
      } catch (const std::exception& e) {
        ADD_FAILURE() << "number at byte " << begin << " → " << replacement << ": non-pl::Error " << e.what();
      }
    }
  }
  EXPECT_GT(variants, 100u);
  EXPECT_GT(rejected, variants / 4);
}

TEST(JsonScene, SameNamedMaterialsReplaceInPlaceAndKeepTheLayout) {
  // A JSON material named like a loaded one replaces it where it stands, so the material list
  // (and with it the light-field bake's visibility hash) is the same as without the override.
  const fs::path dir = scratchDir("override");
  const Scene plain = makeCornellBox();
  const Scene recoloured = loadScene(writeFile(dir / "blue.json", R"({"include_cornell": true,
      "materials": {"light": {"type": "lambert", "albedo": 0.78, "emission": [4, 12, 17]},
                    "unused": {"type": "mirror"}}})"));
  ASSERT_EQ(recoloured.materials.size(), plain.materials.size());
  for (size_t m = 0; m < plain.materials.size(); ++m) {
    EXPECT_EQ(recoloured.materials[m].name, plain.materials[m].name);
    if (plain.materials[m].name == "light") {
      EXPECT_EQ(recoloured.materials[m].emission, Rgb(4, 12, 17));
    } else {
      EXPECT_EQ(recoloured.materials[m].emission, plain.materials[m].emission);
    }
  }
  for (size_t i = 0; i < plain.meshes.size(); ++i) EXPECT_EQ(recoloured.meshes[i].materials, plain.meshes[i].materials);
}

TEST(BadInput, EnergyCreatingMaterials) {
  const fs::path dir = scratchDir("energy");
  const std::string bright = writeFile(dir / "b.json", R"({"include_cornell": true,
      "materials": {"hot": {"type": "lambert", "albedo": [1.2, 0.5, 0.5]}}})");
  expectError([&] { loadScene(bright); }, {"b.json", "'hot'", "outside [0, 1]"});
  const std::string sum = writeFile(dir / "s.json", R"({"include_cornell": true,
      "materials": {"shiny": {"type": "blinn-phong", "diffuse": 0.7, "specular": 0.4}}})");
  expectError([&] { loadScene(sum); }, {"s.json", "'shiny'", "diffuse + specular <= 1"});
}

TEST(BadInput, JsonMeshFileProblemsNameBothFiles) {
  const fs::path dir = scratchDir("json_mesh");
  const std::string path = writeFile(dir / "s.json", R"({"meshes": [{"file": "missing.obj"}]})");
  expectError([&] { loadScene(path); }, {"s.json", "meshes[0]", "missing.obj", "no such file"});
}

// ---------------------------------------------------------------------------------------------
// Surface detail: alpha masks and normal maps

/// oneTriangle() with uvs = positions' xy (dp/du = +x, dp/dv = +y) and a constant normal map
/// holding `texel` (raw values, as ImageDecode::Data gives them).
Scene normalMappedTriangle(Rgb texel, float scale, bool mirroredU = false) {
  Scene scene = oneTriangle();
  scene.meshes[0].uvs = {Vec2(0, 0), Vec2(mirroredU ? -1.0f : 1.0f, 0), Vec2(0, 1)};
  Texture map;
  map.path = "constant normal map";
  map.decode = ImageDecode::Data;
  map.image = Image(1, 1, texel);
  scene.textures.push_back(map);
  scene.materials[0].normalTexture = 0;
  scene.materials[0].normalScale = scale;
  scene.finalize();
  return scene;
}

TEST(NormalMap, FlatMapChangesNothing) {
  const Scene scene = normalMappedTriangle(Rgb(0.5f, 0.5f, 1.0f), 1.0f);
  const SurfaceHit hit = surfaceAt(scene, 0, 0, Vec2(0.3f, 0.3f));
  EXPECT_EQ(hit.shadingNormal, Vec3(0, 0, 1));  // 2·0.5 − 1 = 0 exactly: no tilt at all
}

// m = 2t − 1 = (sin a, 0, cos a) tilts the normal by a towards the tangent (+u = +x here);
// normalScale s multiplies x: tan(tilt) = s·tan a. Mirrored uvs (u running along −x) tilt
// towards −x: the tangent follows +u.
TEST(NormalMap, TiltedMapTiltsTheShadingNormalByTheExpectedAngle) {
  const float a = glm::radians(30.0f);
  const Rgb texel(0.5f * (std::sin(a) + 1.0f), 0.5f, 0.5f * (std::cos(a) + 1.0f));
  for (const float scale : {1.0f, 2.0f})
    for (const bool mirrored : {false, true}) {
      const Scene scene = normalMappedTriangle(texel, scale, mirrored);
      const Vec3 n = surfaceAt(scene, 0, 0, Vec2(0.2f, 0.3f)).shadingNormal;
      const float expected = std::atan(scale * std::tan(a));
      EXPECT_NEAR(std::acos(std::clamp(n.z, -1.0f, 1.0f)), expected, 1e-5f) << "scale " << scale;
      EXPECT_NEAR(n.y, 0.0f, 1e-6f);                                // no tilt along v
      EXPECT_NEAR(n.x, (mirrored ? -1.0f : 1.0f) * std::sin(expected), 1e-5f) << "mirrored " << mirrored;
    }
  // +y of the map tilts along +v (OpenGL / glTF convention).
  const Scene up = normalMappedTriangle(Rgb(0.5f, 0.5f * (std::sin(a) + 1.0f), 0.5f * (std::cos(a) + 1.0f)), 1.0f);
  EXPECT_NEAR(surfaceAt(up, 0, 0, Vec2(0.2f, 0.3f)).shadingNormal.y, std::sin(a), 1e-5f);
}

// The sidedness rule holds with a normal map: the mapped normal stays on the geometric
// normal's side (a map pointing behind the surface falls back to the unmapped normal), and
// seen from the back scatteringFrame turns the mapped normal with the geometric one.
TEST(NormalMap, SidednessRuleStillHolds) {
  const Scene behind = normalMappedTriangle(Rgb(1.0f, 0.5f, 0.0f), 1.0f);  // m = (1, 0, −1)
  EXPECT_EQ(surfaceAt(behind, 0, 0, Vec2(0.2f, 0.3f)).shadingNormal, Vec3(0, 0, 1));
  const Scene steep = normalMappedTriangle(Rgb(1.0f, 0.5f, 0.6f), 1.0f);  // m = (1, 0, 0.2)
  const SurfaceHit hit = surfaceAt(steep, 0, 0, Vec2(0.2f, 0.3f));
  EXPECT_GT(glm::dot(hit.shadingNormal, hit.geometricNormal), 0.0f);
  EXPECT_VEC3_NEAR(hit.shadingNormal, glm::normalize(Vec3(1.0f, 0.0f, 0.2f)), kTight);
  const Vec3 woBack = glm::normalize(Vec3(0.1f, 0.2f, -1.0f));
  const ScatteringFrame back = scatteringFrame(hit, woBack, LambertBsdf{});
  EXPECT_VEC3_NEAR(back.frame.n, -hit.shadingNormal, 0.0f);
  EXPECT_VEC3_NEAR(back.geometricNormal, -hit.geometricNormal, 0.0f);
  EXPECT_TRUE(usableSide(woBack, back.woLocal, back.geometricNormal, LambertBsdf{}));
}

TEST(ObjLoader, AlphaMasksAndNormalMaps) {
  const fs::path dir = scratchDir("detail");
  for (const char* file : {"mask_rgba.png", "mask_grey.png", "normal_tilt.png"}) fs::copy_file(kDataDir + file, dir / file);
  writeFile(dir / "m.mtl",
            "newmtl leaf\nKd 1 1 1\nmap_Kd mask_rgba.png\nmap_d mask_rgba.png\nmap_bump -bm 0.5 normal_tilt.png\n"
            "newmtl grey\nKd 1 1 1\nd 0.8\nmap_d mask_grey.png\nbump mask_grey.png\n"
            "newmtl norm\nKd 1 1 1\nnorm normal_tilt.png\n");
  std::string obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n";
  for (const char* name : {"leaf", "grey", "norm"}) obj += std::string("usemtl ") + name + "\nf 1/1 2/2 3/3\n";
  const Scene scene = loadScene(writeFile(dir / "m.obj", obj));

  // map_Kd and map_d name one RGBA file: two textures, sRGB colour and the alpha channel.
  const Material& leaf = materialNamed(scene, "leaf");
  ASSERT_GE(leaf.albedoTexture, 0);
  ASSERT_GE(leaf.alphaTexture, 0);
  const Texture& colour = scene.textures[size_t(leaf.albedoTexture)];
  const Texture& alpha = scene.textures[size_t(leaf.alphaTexture)];
  EXPECT_EQ(colour.decode, ImageDecode::Colour);
  EXPECT_EQ(alpha.decode, ImageDecode::Coverage);
  EXPECT_VEC3_NEAR(colour.image.at(1, 0), Rgb(0, 1, 0), 0.0f);
  for (const auto& [x, y, a] : {std::tuple{0, 0, 0}, {1, 0, 64}, {0, 1, 192}, {1, 1, 255}})
    EXPECT_EQ(alpha.image.at(x, y), Rgb(float(a) / 255.0f)) << x << "," << y;
  EXPECT_EQ(leaf.alphaCutoff, 0.5f);
  EXPECT_EQ(leaf.alphaFactor, 1.0f);
  EXPECT_TRUE(std::holds_alternative<LambertBsdf>(leaf.bsdf));  // not thin glass: d is a mask here
  // map_bump with -bm: a normal map read raw (192/255, not sRGB-decoded), scale 0.5.
  ASSERT_GE(leaf.normalTexture, 0);
  const Texture& normals = scene.textures[size_t(leaf.normalTexture)];
  EXPECT_EQ(normals.decode, ImageDecode::Data);
  EXPECT_VEC3_NEAR(normals.image.at(0, 0), Rgb(192.0f, 128.0f, 224.0f) / 255.0f, 0.0f);
  EXPECT_EQ(leaf.normalScale, 0.5f);

  // A grey map_d: coverage is its channel, times d. A grey bump map is a height map: ignored.
  const Material& grey = materialNamed(scene, "grey");
  ASSERT_GE(grey.alphaTexture, 0);
  EXPECT_VEC3_NEAR(scene.textures[size_t(grey.alphaTexture)].image.at(0, 1), Rgb(128.0f / 255.0f), 0.0f);
  EXPECT_NEAR(grey.alphaFactor, 0.8f, 1e-6f);
  EXPECT_EQ(grey.normalTexture, -1);
  // norm: a normal map, scale 1.
  const Material& norm = materialNamed(scene, "norm");
  EXPECT_GE(norm.normalTexture, 0);
  EXPECT_EQ(norm.normalScale, 1.0f);

  // coverageAt: barycentrics (0.25, 0.25) on uvs (0,0), (1,0), (0,1) are uv (0.25, 0.25), the
  // centre of the bottom-left texel (alpha 192; grey 128 in mask_grey.png).
  const Vec2 b(0.25f, 0.25f);
  EXPECT_NEAR(coverageAt(scene, 0, 0, b), 192.0f / 255.0f, 1e-6f);
  EXPECT_NEAR(coverageAt(scene, 0, 1, b), 0.8f * 128.0f / 255.0f, 1e-6f);
  EXPECT_EQ(coverageAt(scene, 0, 2, b), 1.0f);  // unmasked
}

TEST(GltfLoader, AlphaModesAndNormalTexture) {
  std::ifstream in(kDataDir + "quad.gltf", std::ios::binary);
  const std::string original((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string anchor = "\"name\": \"textured\",";
  ASSERT_NE(original.find(anchor), std::string::npos);
  auto withMaterialKeys = [&](const std::string& keys, const char* image, const std::string& name) {
    const fs::path dir = scratchDir("gltf_alpha_" + name);
    fs::copy_file(kDataDir + image, dir / "checker.png");
    std::string text = original;
    text.replace(text.find(anchor), anchor.size(), anchor + keys);
    return loadScene(writeFile(dir / "quad.gltf", text));
  };
  // MASK on an RGBA baseColorTexture: coverage = factor alpha (1) × the image's alpha.
  {
    const Scene scene = withMaterialKeys(R"("alphaMode": "MASK", "alphaCutoff": 0.3,
        "normalTexture": {"index": 0, "scale": 2},)", "mask_rgba.png", "rgba");
    const Material& m = materialNamed(scene, "textured");
    EXPECT_NEAR(m.alphaCutoff, 0.3f, 1e-7f);
    ASSERT_GE(m.alphaTexture, 0);
    EXPECT_EQ(scene.textures[size_t(m.alphaTexture)].decode, ImageDecode::Coverage);
    EXPECT_VEC3_NEAR(scene.textures[size_t(m.alphaTexture)].image.at(1, 0), Rgb(64.0f / 255.0f), 0.0f);
    ASSERT_GE(m.normalTexture, 0);
    EXPECT_EQ(scene.textures[size_t(m.normalTexture)].decode, ImageDecode::Data);
    EXPECT_EQ(m.normalScale, 2.0f);
    EXPECT_NE(m.normalTexture, m.albedoTexture);  // one image, three decodings
  }
  // MASK on an RGB texture (no alpha channel): the factor alone; cutoff defaults to 0.5.
  {
    const Scene scene = withMaterialKeys(R"("alphaMode": "MASK",)", "checker.png", "rgb");
    const Material& m = materialNamed(scene, "textured");
    EXPECT_EQ(m.alphaTexture, -1);
    EXPECT_EQ(m.alphaCutoff, 0.5f);
    EXPECT_FALSE(m.isMasked());  // baseColorFactor alpha 1 ≥ 0.5
  }
  // BLEND is read as MASK at 0.5; OPAQUE (the default) ignores alpha.
  EXPECT_GE(materialNamed(withMaterialKeys(R"("alphaMode": "BLEND",)", "mask_rgba.png", "blend"), "textured").alphaTexture, 0);
  EXPECT_EQ(materialNamed(withMaterialKeys("", "mask_rgba.png", "opaque"), "textured").alphaTexture, -1);
  expectError([&] { withMaterialKeys(R"("alphaMode": "CLIP",)", "checker.png", "bad"); }, {"quad.gltf", "alphaMode 'CLIP'"});
}

/// Copies the textured quad (OBJ, MTL, checker) into `dir` and returns a writer of dir/s.json:
/// the quad with Lambert material `material` given the keys it is called with; it returns the path.
std::function<std::string(const std::string&)> quadSceneWriter(const fs::path& dir, const std::string& material) {
  fs::create_directories(dir / "textured" / "mat");
  for (const char* f : {"textured/quad.obj", "textured/mat/quad.mtl", "textured/mat/checker.png"}) fs::copy_file(kDataDir + f, dir / f);
  return [dir, material](const std::string& keys) {
    return writeFile(dir / "s.json", R"({"meshes": [{"file": "textured/quad.obj", "material": ")" + material +
                                         R"("}], "materials": {")" + material + R"(": {"type": "lambert", )" + keys + "}}}");
  };
}

TEST(JsonScene, AlphaAndNormalTextures) {
  const fs::path dir = scratchDir("json_detail");
  fs::copy_file(kDataDir + "mask_rgba.png", dir / "mask.png");
  fs::copy_file(kDataDir + "normal_tilt.png", dir / "n.png");
  const auto scene = quadSceneWriter(dir, "leaf");
  const Scene loaded = loadScene(scene(R"("alpha_texture": "mask.png", "alpha_cutoff": 0.2,
      "normal_texture": "n.png", "normal_scale": 0.5)"));
  const Material& leaf = materialNamed(loaded, "leaf");
  ASSERT_GE(leaf.alphaTexture, 0);
  EXPECT_EQ(loaded.textures[size_t(leaf.alphaTexture)].decode, ImageDecode::Coverage);
  EXPECT_NEAR(leaf.alphaCutoff, 0.2f, 1e-7f);
  ASSERT_GE(leaf.normalTexture, 0);
  EXPECT_EQ(loaded.textures[size_t(leaf.normalTexture)].decode, ImageDecode::Data);
  EXPECT_EQ(leaf.normalScale, 0.5f);

  // Bad input: each a clean error naming the file and the key.
  expectError([&] { loadScene(scene(R"("alpha_texture": "gone.png")")); }, {"s.json", "alpha_texture", "gone.png", "not found"});
  expectError([&] { loadScene(scene(R"("alpha_texture": "mask.png", "alpha_cutoff": 1.5)")); }, {"s.json", "alpha_cutoff"});
  expectError([&] { loadScene(scene(R"("alpha_cutoff": 0.3)")); }, {"s.json", "alpha_cutoff needs an alpha_texture"});
  std::ifstream mask(dir / "mask.png", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(mask)), std::istreambuf_iterator<char>());
  writeFile(dir / "cut.png", bytes.substr(0, 40));  // cut inside the IDAT chunk
  expectError([&] { loadScene(scene(R"("alpha_texture": "cut.png")")); }, {"cut.png", "truncated"});
}

// "emission_texture": an sRGB colour texture multiplying "emission" (emissionModulation); it
// needs an emission to multiply, and a missing file is an error naming the material's key.
TEST(JsonScene, EmissionTexture) {
  const fs::path dir = scratchDir("json_emission");
  const auto scene = quadSceneWriter(dir, "lamp");
  fs::copy_file(kDataDir + "textured/mat/checker.png", dir / "glow.png");
  const Scene loaded = loadScene(scene(R"("emission": [2, 3, 4], "emission_texture": "glow.png")"));
  const Material& lamp = materialNamed(loaded, "lamp");
  ASSERT_GE(lamp.emissionTexture, 0);
  const Texture& glow = loaded.textures[size_t(lamp.emissionTexture)];
  EXPECT_EQ(glow.decode, ImageDecode::Colour);
  const Vec2 b(0.2f, 0.3f);
  EXPECT_VEC3_NEAR(emissionModulation(loaded, lamp, 0, 0, b), glow.sample(uvAt(loaded.meshes[0], 0, b)), 0.0f);
  EXPECT_VEC3_NEAR(emissionModulation(loaded, materialNamed(loadScene(scene(R"("emission": 1)")), "lamp"), 0, 0, b), Rgb(1.0f),
                   0.0f);

  expectError([&] { loadScene(scene(R"("emission": 1, "emission_texture": "gone.png")")); },
              {"s.json", "materials.lamp.emission_texture", "gone.png", "not found"});
  expectError([&] { loadScene(scene(R"("emission_texture": "glow.png")")); },
              {"s.json", "materials.lamp", "emission_texture needs a non-black \"emission\""});
}

TEST(BadInput, MissingOrCorruptAlphaAndNormalTexturesInMtl) {
  const fs::path dir = scratchDir("detail_bad");
  writeFile(dir / "t.mtl", "newmtl a\nKd 1 1 1\nmap_d nothere.png\n");
  const std::string path = writeFile(dir / "t.obj", "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  expectError([&] { loadScene(path); }, {"t.mtl", "map_d", "nothere.png", "not found"});
  writeFile(dir / "t.mtl", "newmtl a\nKd 1 1 1\nnorm broken.png\n");
  writeFile(dir / "broken.png", "not a png at all");
  expectError([&] { loadScene(path); }, {"broken.png", "not a PNG"});
}

}  // namespace
}  // namespace pl
