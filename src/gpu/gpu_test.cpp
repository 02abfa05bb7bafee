// The GPU renderer (gpu.h) against the CPU fast renderer (realtime.h) on the same light field
// and camera, its shader lookup against the C++ one on random inputs, and its refusals. On a
// machine without a GPU this runs on Mesa's llvmpipe through surfaceless EGL (the bootstrap
// installs it), so a missing context is a failure here, not a skip.
#include "gpu/gpu.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <fstream>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "accel/accel.h"
#include "bake/bake.h"
#include "bsdf/ggx_lobe.h"
#include "camera/camera.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "gpu/gpu_highlights.h"
#include "image/compare.h"
#include "image/display.h"
#include "image/tonemap.h"
#include "lightfield/lookup.h"
#include "plf/plf_file.h"
#include "realtime/realtime.h"
#include "support/cli_test_support.h"
#include "support/mask_texture.h"
#include "support/metallic_roughness_box.h"
#include "support/random_light_field.h"
#include "support/random_texture.h"
#include "support/sky_map.h"
#include "support/sphere_mesh.h"

namespace pl {
namespace {

const std::string kMcGuire = std::string(PLENOPTIC_TEST_DATA_DIR) + "/cornell-mcguire/";

using test_support::randomLightField;

CameraDesc firstCamera(const Scene& scene) { return scene.cameras.empty() ? scene.automaticCamera() : scene.cameras.front(); }

/// A view from inside the box into a corner at an angle (grazing lookups, walls seen from
/// near and far).
CameraDesc insideCamera(const Scene& scene) {
  CameraDesc inside = firstCamera(scene);
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  inside.eye = lo + Vec3(0.8f, 0.7f, 0.6f) * (hi - lo);
  inside.target = lo + Vec3(0.05f, 0.1f, 0.1f) * (hi - lo);
  inside.fovYDegrees = 70.0f;
  return inside;
}

class GpuRendererTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::string why;
    ASSERT_TRUE(gpuAvailable(&why)) << why;
  }
  ThreadPool pool_{2};
};

/// The GPU and the CPU fast renderer's images of `lf` from `desc` at width × height: relMSE
/// ≤ 1e-4 and mean luminance within 0.1 %. Only pixels whose visible triangle differs between
/// rasterisation and ray casting (a silhouette pixel centre within float rounding of an edge)
/// may differ by more than rounding.
///
/// With glass, `branchPixels` > 0: at most that fraction of the pixels may differ by more than
/// 1e-3 (relative), and the relMSE bound is not applied. followSpecular draws glass's branch
/// from a hash of the arriving ray's bits; past the first interface that ray starts at the
/// hit point of the previous one, rebuilt from its barycentrics, which the GPU traversal and
/// Embree (its own arithmetic, an approximate reciprocal) compute a few ulp apart. The two
/// renderers then draw independent branches there, and a pixel whose chain draws differently
/// (probability 2F(1 − F) per such interface) shows another, equally likely path: the same
/// picture in expectation (the mean bound holds), not pixel for pixel.
void expectSameAsFastRenderer(const LightField& lf, GpuRenderer& gpu, const Camera& camera,
                              const RenderSettings& settings = {}, double branchPixels = 0.0) {
  const int width = camera.width(), height = camera.height();
  const Accel accel(lf.scene);
  const FastRenderer fast(lf, accel);
  const Image expected = fast.render(camera, settings);
  Image image;
  gpu.render(camera, settings, image);
  ASSERT_EQ(image.width, width);
  ASSERT_EQ(image.height, height);
  const ImageComparison c = compareImages(image, expected);
  size_t differing = 0;
  for (size_t i = 0; i < image.pixels.size(); ++i)
    differing += glm::length(image.pixels[i] - expected.pixels[i]) > 1e-3f * (1.0f + glm::length(expected.pixels[i]));
  EXPECT_EQ(c.nonFinitePixels, 0u);
  if (branchPixels > 0.0)
    EXPECT_LE(double(differing), branchPixels * double(image.pixels.size()));
  else
    EXPECT_LE(c.relMseAverage, 1e-4) << "max |difference| " << c.maxAbsError << " at (" << c.maxErrorX << ", " << c.maxErrorY << ")";
  EXPECT_NEAR(c.meanLuminanceRatio, 1.0, 1e-3);
  std::printf("%dx%d: relMSE %.3g, mean luminance ratio %.6f, max |difference| %.3g, %zu pixels differ by more than 1e-3\n",
              width, height, c.relMseAverage, c.meanLuminanceRatio, c.maxAbsError, differing);
}
void expectSameAsFastRenderer(const LightField& lf, GpuRenderer& gpu, const CameraDesc& desc, int width, int height,
                              bool vignetting = false, const RenderSettings& settings = {}, double branchPixels = 0.0) {
  expectSameAsFastRenderer(lf, gpu, Camera(desc, width, height, vignetting), settings, branchPixels);
}

TEST_F(GpuRendererTest, MatchesFastRendererOnCornellBox) {
  const LightField lf = randomLightField(makeCornellBox(), 1);
  GpuRenderer gpu(lf);
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 48);
  expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 80, 60);
  // Vignetting (cos⁴θ camera weights), and a second size on the same renderer (new targets).
  expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 48, 64, true);
}

// Several samples per pixel: the same film points (pixelSample's ZSobol sequence) as the CPU
// renderer, averaged; a change of seed moves them.
TEST_F(GpuRendererTest, MultiSampleMatchesFastRenderer) {
  RenderSettings settings;
  settings.samplesPerPixel = 4;
  settings.seed = 0x123456789abcdefULL;  // both halves of the 64-bit seed matter
  const LightField box = randomLightField(makeCornellBox(), 12);
  GpuRenderer gpu(box);
  ASSERT_EQ(gpu.unsupportedSetting(settings, Camera(firstCamera(box.scene), 8, 8)), "")
      << "the driver lacks GL_ARB_gpu_shader_int64";
  expectSameAsFastRenderer(box, gpu, firstCamera(box.scene), 64, 48, false, settings);
  expectSameAsFastRenderer(box, gpu, insideCamera(box.scene), 48, 40, true, settings);
  const LightField glossy = randomLightField(loadScene(kMcGuire + "CornellBox-Glossy.obj"), 13);
  GpuRenderer glossyGpu(glossy);
  settings.samplesPerPixel = 3;
  settings.seed = 7;
  expectSameAsFastRenderer(glossy, glossyGpu, insideCamera(glossy.scene), 64, 48, false, settings);
  // The samples are jittered: 4 of them differ from the pixel centre's one, and the seed moves them.
  const Camera camera(insideCamera(glossy.scene), 32, 24);
  Image centre, jittered, reseeded;
  glossyGpu.render(camera, RenderSettings{}, centre);
  glossyGpu.render(camera, settings, jittered);
  settings.seed = 8;
  glossyGpu.render(camera, settings, reseeded);
  EXPECT_GT(compareImages(jittered, centre).relMseAverage, 1e-6);
  EXPECT_GT(compareImages(jittered, reseeded).relMseAverage, 1e-6);
}

/// The world point at film point `film` (pixel units) of `camera`, on the plane `depth` in
/// front of its eye (along its forward axis).
Vec3 filmPlanePoint(const Camera& camera, float depth, Vec2 film) {
  const float sx = (2.0f * film.x / float(camera.width()) - 1.0f) * camera.tanHalfFovY() * camera.aspect();
  const float sy = (1.0f - 2.0f * film.y / float(camera.height())) * camera.tanHalfFovY();
  return camera.eye() + depth * (camera.forward() + sx * camera.right() + sy * camera.up());
}
/// Appends the triangle of `mesh`'s vertices v (material 0), wound to face `camera`.
void addFacingTriangle(Mesh& mesh, const Camera& camera, UVec3 v) {
  const Vec3 normal = glm::cross(mesh.positions[v.y] - mesh.positions[v.x], mesh.positions[v.z] - mesh.positions[v.x]);
  mesh.triangles.push_back(glm::dot(normal, camera.forward()) < 0.0f ? v : UVec3(v.x, v.z, v.y));
  mesh.materials.push_back(0);
}

// Triangles far smaller than a pixel, each with an edge a few thousandths of a pixel inside
// a pixel centre: the rasteriser, which snaps vertices to a sub-pixel grid (1/256 pixel on
// llvmpipe), may leave that centre out, and no other texel centre of the 3×3 around it holds
// the triangle, yet the CPU renderer's ray through the centre hits it. The GPU renderer casts
// such pixels' rays through its BVH (a vertex nearer than the surface behind marks them), so
// it sees the specks where the CPU renderer does — with one sample per pixel and several.
TEST_F(GpuRendererTest, MatchesFastRendererOnSubPixelTriangles) {
  Scene scene = makeCornellBox();
  const int width = 64, height = 48;
  const Camera camera(firstCamera(scene), width, height);
  Mesh specks;
  specks.name = "specks";
  Pcg32 rng(91, 3);
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i) {
      const Vec2 centre(float(i) + 0.5f, float(j) + 0.5f);
      // An edge 0.2 pixel long, 0.0003 to 0.0015 pixel from the centre, on one of its four
      // sides (the rasteriser's tie rule keeps some sides' samples), the apex 0.25 pixel
      // across the centre from it.
      const float offset = 0.0003f + 0.0012f * rng.uniform();
      const int side = (i + 2 * j) % 4;
      const Vec2 along = side % 2 == 0 ? Vec2(1.0f, 0.0f) : Vec2(0.0f, 1.0f);
      const Vec2 across = (side < 2 ? 1.0f : -1.0f) * Vec2(along.y, along.x);
      const Vec2 a = centre + offset * across - 0.1f * along, b = centre + offset * across + 0.1f * along,
                 c = centre - 0.25f * across;
      const uint32_t first = uint32_t(specks.positions.size());
      for (const Vec2& p : {a, b, c}) specks.positions.push_back(filmPlanePoint(camera, 400.0f, p));
      addFacingTriangle(specks, camera, UVec3(first, first + 1, first + 2));
    }
  scene.meshes.push_back(std::move(specks));
  scene.finalize();
  const LightField lf = randomLightField(std::move(scene), 92);
  GpuRenderer gpu(lf);
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), width, height);
  RenderSettings four;
  four.samplesPerPixel = 4;
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), width, height, false, four);
}

// A mesh of triangles about four pixels across filling the view: most pixels lie within a
// pixel of an edge or a vertex, where the 3×3 id texels hold two triangles or a fan of
// triangles around one vertex. The resolve pass answers those from the ids (the ray tested
// against them) rather than casting them through the BVH — the same picture as the CPU
// renderer, with a small share of the rays cast.
TEST_F(GpuRendererTest, EdgesAndFansAreAnsweredFromTheIds) {
  Scene scene = makeCornellBox();
  const int width = 64, height = 48;
  const Camera camera(firstCamera(scene), width, height);
  Mesh grid;
  grid.name = "grid";
  const float spacing = 4.37f;  // pixels; no edge through a pixel centre
  const int columns = int(float(width) / spacing) + 3, rows = int(float(height) / spacing) + 3;
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i)  // in front of the box, on a plane facing the eye
      grid.positions.push_back(filmPlanePoint(camera, 300.0f, Vec2((float(i) - 1.0f) * spacing + 0.31f, (float(j) - 1.0f) * spacing + 0.23f)));
  for (int j = 0; j + 1 < rows; ++j)
    for (int i = 0; i + 1 < columns; ++i) {
      const uint32_t a = uint32_t(j * columns + i), b = a + 1, c = a + uint32_t(columns), d = c + 1;
      addFacingTriangle(grid, camera, UVec3(a, b, d));  // every interior vertex in six triangles
      addFacingTriangle(grid, camera, UVec3(a, d, c));
    }
  scene.meshes.push_back(std::move(grid));
  scene.finalize();
  const LightField lf = randomLightField(std::move(scene), 93);
  GpuRenderer gpu(lf);
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), width, height);
  ASSERT_TRUE(gpu.lastBvhRayShare().has_value());
  // The grid casts none here (0 %); answering edges alone casts 68 % (every pixel within a
  // pixel of a vertex). 10 % leaves room for vertices a driver marks in front of the plane
  // they lie on (depth rounding), which are cast, and still fails if fans are not answered.
  std::printf("camera rays cast through the BVH: %.1f %%\n", 100.0 * *gpu.lastBvhRayShare());
  EXPECT_LT(*gpu.lastBvhRayShare(), 0.1);
}

// An environment map (rotated, scaled, over a constant) seen past the box, through the open
// front and all around, with one and three samples per pixel.
TEST_F(GpuRendererTest, EnvironmentMapBackgroundMatchesFastRenderer) {
  Scene scene = makeCornellBox();
  scene.environment.constant = Rgb(0.05f, 0.1f, 0.2f);
  scene.environment.map = std::make_shared<const EnvironmentMap>(test_support::skyWithSun(30.0f));
  const LightField lf = randomLightField(std::move(scene), 14);
  EXPECT_EQ(gpuUnsupportedFeature(lf), "");
  GpuRenderer gpu(lf);
  CameraDesc wide = firstCamera(lf.scene);
  wide.fovYDegrees = 100.0f;
  expectSameAsFastRenderer(lf, gpu, wide, 64, 48, true);
  CameraDesc away = wide;  // looking out of the box's open side: sky all around
  away.target = wide.eye + (wide.eye - wide.target);
  expectSameAsFastRenderer(lf, gpu, away, 64, 48);
  CameraDesc up = away;  // the zenith and the sun's side (the map's poles and rows)
  up.target = wide.eye + Vec3(1.0f, 1000.0f, 1.0f);
  expectSameAsFastRenderer(lf, gpu, up, 48, 36);
  RenderSettings three;
  three.samplesPerPixel = 3;
  expectSameAsFastRenderer(lf, gpu, wide, 48, 36, false, three);
}

TEST_F(GpuRendererTest, MatchesFastRendererOnGlossyCornellBox) {
  const LightField lf = randomLightField(loadScene(kMcGuire + "CornellBox-Glossy.obj"), 2);
  ASSERT_GT(std::count_if(lf.charts.begin(), lf.charts.end(), [](const Chart& c) { return c.kind == ChartKind::Glossy; }), 0);
  GpuRenderer gpu(lf);
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 48);
  expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 80, 60);
}

TEST_F(GpuRendererTest, MatchesFastRendererOnOriginalCornellBox) {
  const LightField lf = randomLightField(loadScene(kMcGuire + "CornellBox-Original.obj"), 3);
  GpuRenderer gpu(lf);
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 48);
}

// Baked light fields (draft preset: a smooth bake, as users render), built-in box and glossy box.
TEST_F(GpuRendererTest, MatchesFastRendererOnDraftBakes) {
  for (const std::string& name : {std::string("cornell"), kMcGuire + "CornellBox-Glossy.obj"}) {
    SCOPED_TRACE(name);
    const LightField lf = bake(loadScene(name), bakePreset("draft"));
    GpuRenderer gpu(lf);
    expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 48);
    expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 64, 48);
  }
}

/// `scene` with surface detail on every material: planar uvs spanning about three texture
/// repeats (so every wrap mode wraps), albedo textures — 8-bit (packed) with the default
/// sampling, float rows mirrored in u and clamped in v, nearest-filtered 8-bit — on the
/// materials in turn (`lambertOnly`: only Lambertian ones), vertex colours on every other mesh,
/// and an emission texture on the emitters.
Scene withPlanarUvs(Scene scene) {
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  const float scale = 3.0f / std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  for (Mesh& mesh : scene.meshes) {
    mesh.uvs.clear();
    for (const Vec3& p : mesh.positions) mesh.uvs.push_back(scale * Vec2(p.x + 0.7f * p.z, p.y - 0.4f * p.z));
  }
  return scene;
}
Scene withSurfaceDetail(Scene scene, bool lambertOnly) {
  scene = withPlanarUvs(std::move(scene));
  Pcg32 rng(21, 4);
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    Mesh& mesh = scene.meshes[m];
    if (m % 2 == 1) {
      mesh.colors.clear();
      for (size_t v = 0; v < mesh.positions.size(); ++v) mesh.colors.push_back(Rgb(rng.uniform(), rng.uniform(), rng.uniform()));
    }
  }
  scene.textures.push_back(test_support::randomTexture(13, 9, true, 1));
  scene.textures.push_back(test_support::randomTexture(64, 48, false, 2));
  scene.textures.back().sampling.wrapU = TextureWrap::MirroredRepeat;
  scene.textures.back().sampling.wrapV = TextureWrap::ClampToEdge;
  scene.textures.push_back(test_support::randomTexture(16, 16, true, 3));
  scene.textures.back().sampling.nearest = true;
  scene.textures.push_back(test_support::randomTexture(5, 7, true, 4));  // emission
  int next = 0;
  for (Material& m : scene.materials) {
    if (m.isEmissive()) {
      m.emissionTexture = 3;
    } else if (!lambertOnly || std::holds_alternative<LambertBsdf>(m.bsdf)) {
      m.albedoTexture = next;
      next = (next + 1) % 3;
    }
  }
  return scene;
}

// Albedo textures with the CPU renderer's level of detail (minified and magnified, every wrap
// mode, nearest), vertex colours and emission textures, on diffuse charts and on glossy charts'
// diffuse part; 1 and 4 samples per pixel and texture LOD off.
TEST_F(GpuRendererTest, MatchesFastRendererWithTexturesAndVertexColours) {
  const LightField box = randomLightField(withSurfaceDetail(makeCornellBox(), false), 31);
  ASSERT_EQ(gpuUnsupportedFeature(box), "");
  ASSERT_FALSE(box.scene.textures[0].packed.empty());
  ASSERT_TRUE(box.scene.textures[1].packed.empty());
  GpuRenderer gpu(box);
  RenderSettings four, off;
  four.samplesPerPixel = 4;
  off.textureLod = false;
  expectSameAsFastRenderer(box, gpu, firstCamera(box.scene), 64, 48);
  expectSameAsFastRenderer(box, gpu, insideCamera(box.scene), 80, 60, true);
  expectSameAsFastRenderer(box, gpu, firstCamera(box.scene), 48, 36, false, four);
  expectSameAsFastRenderer(box, gpu, insideCamera(box.scene), 64, 48, false, off);
  // The detail is drawn at all: without it the picture differs.
  const LightField plain = randomLightField(makeCornellBox(), 31);
  GpuRenderer plainGpu(plain);
  const Camera camera(firstCamera(box.scene), 32, 24);
  Image textured, untextured;
  gpu.render(camera, RenderSettings{}, textured);
  plainGpu.render(camera, RenderSettings{}, untextured);
  EXPECT_GT(compareImages(textured, untextured).relMseAverage, 1e-2);

  // Subsurface materials' diffuse charts take their albedo from the textures as Lambert's do.
  Scene translucent = makeCornellBox();
  for (Material& m : translucent.materials)
    if (const auto* lambert = std::get_if<LambertBsdf>(&m.bsdf); lambert != nullptr && m.name == "green")
      m.bsdf = SubsurfaceBsdf{lambert->albedo, Rgb(20.0f)};
  const LightField subsurface = randomLightField(withSurfaceDetail(std::move(translucent), false), 33);
  ASSERT_EQ(gpuUnsupportedFeature(subsurface), "");
  GpuRenderer subsurfaceGpu(subsurface);
  expectSameAsFastRenderer(subsurface, subsurfaceGpu, firstCamera(subsurface.scene), 64, 48);

  const LightField glossy = randomLightField(withSurfaceDetail(loadScene(kMcGuire + "CornellBox-Glossy.obj"), false), 32);
  ASSERT_EQ(gpuUnsupportedFeature(glossy), "");
  ASSERT_GT(std::count_if(glossy.charts.begin(), glossy.charts.end(), [&](const Chart& c) {
              return c.diffuseValue && glossy.scene.materials[c.material].albedoTexture >= 0;
            }),
            0);
  GpuRenderer glossyGpu(glossy);
  expectSameAsFastRenderer(glossy, glossyGpu, firstCamera(glossy.scene), 64, 48);
  expectSameAsFastRenderer(glossy, glossyGpu, insideCamera(glossy.scene), 64, 48, false, four);
}

// Alpha masks: the built-in box's blocks cut out by a random coverage texture (bilinear, cutoff
// 0.5), so the floor and walls are seen through them; the albedo-textured walls behind.
/// `scene` with the meshes named in `meshes` given a masked copy of their first material: a
/// random coverage texture (bilinear, 0 or 1 per texel, cutoff 0.5) cuts holes in them.
Scene withAlphaMasks(Scene scene, const std::vector<std::string>& meshes) {
  Texture mask = test_support::randomTexture(6, 5, true, 9);
  mask.decode = ImageDecode::Coverage;
  for (Rgb& texel : mask.image.pixels) texel = Rgb(texel.r < 0.5f ? 0.0f : 1.0f);
  scene.textures.push_back(mask);
  for (const std::string& name : meshes) {
    const auto mesh = std::find_if(scene.meshes.begin(), scene.meshes.end(), [&](const Mesh& m) { return m.name == name; });
    EXPECT_NE(mesh, scene.meshes.end()) << name;
    if (mesh == scene.meshes.end()) continue;
    Material masked = scene.materials[mesh->materials.front()];
    masked.name += " masked";
    masked.alphaTexture = int(scene.textures.size()) - 1;
    scene.materials.push_back(masked);
    std::fill(mesh->materials.begin(), mesh->materials.end(), uint32_t(scene.materials.size() - 1));
  }
  return scene;
}

TEST_F(GpuRendererTest, MatchesFastRendererWithAlphaMasks) {
  Scene scene = withAlphaMasks(withSurfaceDetail(makeCornellBox(), true), {"blocks"});
  const LightField lf = randomLightField(std::move(scene), 33);
  ASSERT_EQ(gpuUnsupportedFeature(lf), "");
  GpuRenderer gpu(lf);
  RenderSettings three;
  three.samplesPerPixel = 3;
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 80, 60);
  expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 64, 48, false, three);
  // A material cut away whole (alpha factor below its cutoff, no texture): the blocks vanish.
  LightField gone = lf;
  gone.scene.materials.back().alphaTexture = -1;
  gone.scene.materials.back().alphaFactor = 0.25f;
  GpuRenderer goneGpu(gone);
  expectSameAsFastRenderer(gone, goneGpu, firstCamera(gone.scene), 64, 48);
  // Vertex alphas (glTF COLOR_0's alpha) multiply the coverage: random ones on the blocks.
  Scene faded = withAlphaMasks(withSurfaceDetail(makeCornellBox(), true), {"blocks"});
  Pcg32 rng(61, 2);
  for (Mesh& mesh : faded.meshes)
    if (mesh.name == "blocks")
      for (size_t v = 0; v < mesh.positions.size(); ++v) mesh.alphas.push_back(rng.uniform());
  faded.finalize();
  const LightField fadedLf = randomLightField(std::move(faded), 34);
  ASSERT_TRUE(fadedLf.scene.materials.back().vertexAlpha);
  GpuRenderer fadedGpu(fadedLf);
  expectSameAsFastRenderer(fadedLf, fadedGpu, firstCamera(fadedLf.scene), 64, 48);
}

// An emission texture on a diffuse emitter (the glTF emissive seed, made Lambertian).
TEST_F(GpuRendererTest, MatchesFastRendererWithEmissionTexture) {
  Scene scene = loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/fuzz/gltf/seed-emissive-texture.gltf");
  scene.materials[0].bsdf = LambertBsdf{Rgb(0.5f)};
  const LightField lf = randomLightField(scene, 7);
  ASSERT_GE(lf.scene.materials[0].emissionTexture, 0);
  GpuRenderer gpu(lf);
  CameraDesc desc = lf.scene.automaticCamera();
  desc.fovYDegrees = 25.0f;  // the quad fills the view
  expectSameAsFastRenderer(lf, gpu, desc, 64, 48);
}

/// `lf` lit by a sun as well, with random sun masks (every bit pattern: wholly lit, wholly
/// shadowed and mixed tixels) and its punctual highlights taken as part of its glossy maps.
LightField withRandomSunMasks(LightField lf, uint64_t seed) {
  lf.scene.lights.push_back(DirectionalLight{glm::normalize(Vec3(0.3f, -1.0f, 0.4f)), Rgb(3.0f, 2.5f, 2.0f)});
  lf.scene.finalize();
  lf.settings.punctualHighlights = false;
  lf.sunMaskLightCount = uint32_t(sunMaskLights(lf.scene).size());
  uint64_t tixels = 0;
  for (const Chart& c : lf.charts) tixels = std::max(tixels, c.firstTixel + c.tixelCount());
  Pcg32 rng(seed, 5);
  lf.sunMasks.resize(tixels * lf.sunMaskLightCount);
  for (SunMask& m : lf.sunMasks) {
    const uint32_t kind = rng.next() % 3;
    m = kind == 0 ? SunMask(0) : kind == 1 ? SunMask(0xffff) : SunMask(rng.next() & 0xffff);
  }
  return lf;
}

TEST_F(GpuRendererTest, MatchesFastRendererWithSunMasks) {
  for (const std::string& file : {std::string("CornellBox-Original.obj"), std::string("CornellBox-Glossy.obj")}) {
    SCOPED_TRACE(file);
    const LightField lf = withRandomSunMasks(randomLightField(loadScene(kMcGuire + file), 11), 12);
    ASSERT_EQ(lf.sunMaskLightCount, 1u);
    GpuRenderer gpu(lf);
    expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 48);
    expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 64, 48);
  }
}

/// `scene` with planar uvs and a bumpy normal map (random tilts up to ±0.4 in x and y,
/// scaled by 0.8) on every material that does not emit, and albedo textures as
/// withSurfaceDetail's on the Lambertian ones.
Scene withNormalMaps(Scene scene) {
  scene = withSurfaceDetail(std::move(scene), true);
  Texture bumps = test_support::randomTexture(9, 7, false, 5);
  bumps.decode = ImageDecode::Data;
  for (Rgb& texel : bumps.image.pixels) texel = Rgb(0.1f + 0.8f * texel.r, 0.1f + 0.8f * texel.g, 1.0f);
  scene.textures.push_back(bumps);
  for (Material& m : scene.materials)
    if (!m.isEmissive()) {
      m.normalTexture = int(scene.textures.size()) - 1;
      m.normalScale = 0.8f;
    }
  return scene;
}

// Normal maps: diffuse charts with tilted irradiances (directionalIrradiance) and sun masks lit
// on the mapped normal, glossy maps read in the direction the normal map bends the view to,
// and the glossy charts' diffuse part about the mapped normal.
TEST_F(GpuRendererTest, MatchesFastRendererWithNormalMaps) {
  for (const std::string& file : {std::string("CornellBox-Original.obj"), std::string("CornellBox-Glossy.obj")}) {
    SCOPED_TRACE(file);
    const LightField lf = withRandomSunMasks(randomLightField(withNormalMaps(loadScene(kMcGuire + file)), 41), 42);
    ASSERT_EQ(gpuUnsupportedFeature(lf), "");
    ASSERT_GT(std::count_if(lf.charts.begin(), lf.charts.end(), [](const Chart& c) { return c.directionalIrradiance; }), 0);
    GpuRenderer gpu(lf);
    RenderSettings four;
    four.samplesPerPixel = 4;
    expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 48);
    expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 64, 48, false, four);
  }
}

/// `scene` with every material that does not emit made GGX-like with a diffuse base: GgxBsdf
/// (rough, then less rough with a metal-like f0) and GltfPbrBsdf without layers, in turn.
Scene withGgxDiffuseBases(Scene scene) {
  int next = 0;
  for (Material& m : scene.materials) {
    if (m.isEmissive()) continue;
    const Rgb rho = diffuseAlbedo(m.bsdf);
    m.tixelDensity = 0.15f;  // coarse tixels: their maps stay a few MiB
    switch (next++ % 3) {
      case 0: m.bsdf = GgxBsdf{rho, Rgb(0.04f), 0.6f}; break;
      case 1: m.bsdf = GgxBsdf{0.5f * rho, Rgb(0.5f, 0.4f, 0.3f), 0.4f}; break;
      default: m.bsdf = GltfPbrBsdf{.diffuse = rho, .alpha = 0.5f}; break;
    }
  }
  return scene;
}

// GGX materials with a diffuse base: the diffuse part ρ/π · k(μo) · Ẽ with k from the lobe's
// albedo table, plain and normal-mapped, at one and four samples per pixel.
TEST_F(GpuRendererTest, MatchesFastRendererWithGgxDiffuseBases) {
  for (const bool bumpy : {false, true}) {
    SCOPED_TRACE(bumpy ? "normal-mapped" : "plain");
    Scene scene = withGgxDiffuseBases(loadScene(kMcGuire + "CornellBox-Original.obj"));
    const LightField lf = randomLightField(bumpy ? withNormalMaps(std::move(scene)) : std::move(scene), 43);
    ASSERT_EQ(gpuUnsupportedFeature(lf), "");
    ASSERT_GT(std::count_if(lf.charts.begin(), lf.charts.end(), [](const Chart& c) { return c.diffuseValue; }), 0);
    ASSERT_LT(lf.values.size(), 1u << 20);
    GpuRenderer gpu(lf);
    RenderSettings four;
    four.samplesPerPixel = 4;
    expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 48);
    expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 64, 48, false, four);
  }
}

// The shader's lookup (the function the shading pass calls) against exitantRadiance on random
// points and directions over every chart: both sides of each record, points off the grid
// (clamped), grazing and below-horizon directions.
TEST_F(GpuRendererTest, ShaderLookupMatchesCppLookup) {
  for (const std::string& file : {std::string("CornellBox-Glossy.obj"), std::string("CornellBox-Original.obj")}) {
    const LightField lf = withRandomSunMasks(randomLightField(loadScene(kMcGuire + file), 4), 13);
    GpuRenderer gpu(lf);
    Pcg32 rng(11, 3);
    std::vector<GpuRenderer::LookupQuery> queries;
    while (queries.size() < 4000) {
      // A front record (as triangleChart gives them; the chart normal decides the side).
      const uint32_t chart = rng.next() % uint32_t(lf.charts.size());
      const Chart& c = lf.charts[chart];
      if (c.isBack) continue;
      const float u = (1.4f * rng.uniform() - 0.2f) * float(c.resU) * c.tixelSize;
      const float v = (1.4f * rng.uniform() - 0.2f) * float(c.resV) * c.tixelSize;
      GpuRenderer::LookupQuery q;
      q.chart = chart;
      q.position = c.origin + u * c.axisU + v * c.axisV;
      q.towardsViewer = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
      // Behind a one-sided curved record a view ray sees nothing (viewedChart), which this
      // overload of exitantRadiance, having no triangle, does not model.
      if (c.curved && c.sides == 1 && glm::dot(q.towardsViewer, c.normal) < 0.0f) continue;
      queries.push_back(q);
    }
    const std::vector<Rgb> gpuValues = gpu.lookup(queries);
    ASSERT_EQ(gpuValues.size(), queries.size());
    int differing = 0;
    double worst = 0.0;
    for (size_t i = 0; i < queries.size(); ++i) {
      const Rgb expected = exitantRadiance(lf, queries[i].chart, queries[i].position, queries[i].towardsViewer, Vec2(0.0f));
      for (int ch = 0; ch < 3; ++ch) {
        // Float rounding (a fused multiply-add here or there) on values up to ≈ 4; a wrong tap,
        // weight or side is off by ≥ 1e-2.
        const double diff = std::abs(double(gpuValues[i][ch]) - double(expected[ch]));
        worst = std::max(worst, diff);
        if (!(diff <= 1e-4)) ++differing;
      }
    }
    EXPECT_EQ(differing, 0) << file << ": worst difference " << worst;
  }
}

/// How far apart two display words are: the largest difference of their 8-bit channels.
int wordChannelDistance(uint32_t a, uint32_t b) {
  int worst = 0;
  for (int shift : {0, 8, 16, 24}) worst = std::max(worst, std::abs(int((a >> shift) & 255u) - int((b >> shift) & 255u)));
  return worst;
}

/// How many of `count` display words the GPU may make differently from DisplayEncoder, by one
/// level: a word changes only where a display value lies within float rounding of a step of the
/// sRGB table (every 1/16383 of [0, 1]) and the GPU rounds otherwise — GLSL's division may be 2.5
/// ulp off — which a few ulp hit about once in 10⁶ channels (llvmpipe: none). One word in 1000,
/// at least one, leaves room for that and still fails a wrong formula: a constant changed by
/// 1e-4 in the GLSL changes 160 to 1426 words of 20 000.
int allowedRoundingWords(size_t count) { return int(count / 1000) + 1; }

/// 20 004 exposed colours to hold the display pass's GLSL to the C++ with: dark and bright
/// (10⁻⁸ … 10⁸), saturated, negative, zero, and four non-finite ones at the end.
std::vector<Rgb> randomExposedColours() {
  Pcg32 rng(5, 9);
  std::vector<Rgb> exposed;
  for (int i = 0; i < 20000; ++i) {
    auto logUniform = [&] { return std::exp2(-26.0f + 52.0f * rng.uniform()); };
    switch (i % 5) {
      case 0: exposed.push_back(Rgb(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0f); break;
      case 1: exposed.push_back(Rgb(logUniform(), logUniform(), logUniform())); break;
      case 2: exposed.push_back(Rgb(rng.uniform(), 0.0f, rng.uniform()) * 4.0f); break;  // saturated
      case 3: exposed.push_back(Rgb(rng.uniform() - 0.5f, rng.uniform() - 0.3f, rng.uniform())); break;
      default: exposed.push_back(Rgb(0.0f)); break;
    }
  }
  const float inf = std::numeric_limits<float>::infinity(), nan = std::nanf("");
  for (const Rgb& c : {Rgb(nan, 0.5f, 0.5f), Rgb(0.5f, inf, 0.5f), Rgb(0.5f, 0.5f, -inf), Rgb(nan)}) exposed.push_back(c);
  return exposed;
}

// The display pass's GLSL (gpu_display.h) against DisplayEncoder::word on random exposed
// colours (randomExposedColours), for each operator: the non-finite ones magenta, exactly, the
// rest within allowedRoundingWords.
TEST_F(GpuRendererTest, DisplayWordsMatchTheCpuEncoder) {
  const LightField lf = randomLightField(makeCornellBox(), 1);
  GpuRenderer gpu(lf);
  const DisplayEncoder encoder;
  const std::vector<Rgb> exposed = randomExposedColours();
  std::vector<ToneMapCurve> curves(5);
  curves[0].luminanceScale = 0.37f;  // Reinhard with a key, no white point (eq. 3)
  curves[1].luminanceScale = 1.9f;   // with a white point (eq. 4)
  curves[1].whiteScaled = 2.5f;
  curves[2].op = ToneMapOperator::Reinhard;  // no key: the luminance as it is
  curves[3].op = ToneMapOperator::Linear;
  curves[3].luminanceScale = 0.8f;
  curves[4].op = ToneMapOperator::Clamp;
  for (const ToneMapCurve& curve : curves) {
    const std::vector<uint32_t> words = gpu.displayWords(curve, exposed);
    ASSERT_EQ(words.size(), exposed.size());
    int differing = 0, worst = 0;
    for (size_t i = 0; i < exposed.size(); ++i) {
      const uint32_t expected = encoder.word(curve, exposed[i]);
      if (!isFinite(exposed[i])) {
        EXPECT_EQ(words[i], DisplayEncoder::kNonFiniteWord) << i;
        continue;
      }
      differing += words[i] != expected;
      worst = std::max(worst, wordChannelDistance(words[i], expected));
    }
    EXPECT_LE(worst, 1) << toneMapOperatorName(curve.op);
    EXPECT_LE(differing, allowedRoundingWords(exposed.size())) << toneMapOperatorName(curve.op);
    std::printf("%s: %d of %zu words differ (by one level)\n", toneMapOperatorName(curve.op), differing, exposed.size());
  }
}

// The log sum's GLSL term (gpu_display.h) against tonemap.h's logLuminanceTerm on random exposed
// colours (randomExposedColours; the non-finite ones NaN: left out of the sum), within GLSL's
// precision of log (2⁻²¹ absolute near 1, 3 ulp elsewhere) and the float rounding of δ + Y.
TEST_F(GpuRendererTest, LogLuminanceTermsMatchTheCpu) {
  const LightField lf = randomLightField(makeCornellBox(), 1);
  GpuRenderer gpu(lf);
  const std::vector<Rgb> exposed = randomExposedColours();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> terms = gpu.logLuminanceTerms(exposed);
  ASSERT_EQ(terms.size(), exposed.size());
  double worst = 0.0;
  for (size_t i = 0; i < exposed.size(); ++i) {
    if (!isFinite(exposed[i])) {
      EXPECT_TRUE(std::isnan(terms[i])) << i;
      continue;
    }
    const double expected = logLuminanceTerm(exposed[i]);
    const float magnitude = float(std::abs(expected));
    const double ulp = double(std::nextafter(magnitude, inf) - magnitude);
    const double allowed = std::exp2(-21.0) + 3.0 * ulp + 2.0 * std::exp2(-24.0);
    EXPECT_LE(std::abs(double(terms[i]) - expected), allowed) << i << ": " << exposed[i].r << ", " << exposed[i].g << ", "
                                                             << exposed[i].b;
    worst = std::max(worst, std::abs(double(terms[i]) - expected));
  }
  std::printf("log luminance terms: worst difference %.3g\n", worst);
}

// The viewer's path: draw(), then encodeDisplay() — the frame's words made on the GPU — against
// readRadiance() and DisplayEncoder::encode on the CPU, at odd sizes (a subsample row and column
// at the edge; one or two runs of the log sum per row) and a padded pitch, for each operator and
// its statistics (the key from the log-average summed on the GPU, to float rounding; the
// automatic key from the percentiles of the subsample read back, exactly; white points).
TEST_F(GpuRendererTest, EncodeDisplayMatchesTheCpuEncoder) {
  const LightField lf = randomLightField(loadScene(kMcGuire + "CornellBox-Glossy.obj"), 3);
  GpuRenderer gpu(lf);
  DisplayEncoder onGpu, onCpu;
  std::vector<uint32_t> pixels;
  EXPECT_THROW(gpu.encodeDisplay(onGpu, 1.0f, ToneMapSettings{}, pixels.data(), 4), Error);  // nothing drawn yet
  ToneMapSettings autoKey;
  autoKey.autoKey = true;
  autoKey.white = 3.0f;
  ToneMapSettings linear;
  linear.op = ToneMapOperator::Linear;
  linear.white = 0.5f;
  ToneMapSettings clamp;
  clamp.op = ToneMapOperator::Clamp;
  for (auto [width, height] : {std::pair{67, 45}, std::pair{40, 30}, std::pair{301, 170}}) {
    const Camera camera(insideCamera(lf.scene), width, height);
    gpu.draw(camera, RenderSettings{});
    Image radiance;
    gpu.readRadiance(radiance);
    ASSERT_EQ(radiance.width, width);
    const int pitchWords = width + 3;  // three words of padding per row, left alone
    constexpr uint32_t kPadding = 0x12345678u;
    // The display pass's GPU memory: its words (4 bytes per pixel), the radiance subsample (16
    // per 16 pixels) and, the first time, the sRGB table (4 bytes per entry).
    const uint64_t before = gpu.gpuBytes();
    const bool first = width == 67;
    const uint64_t subsample = uint64_t(DisplayEncoder::statisticsSize(width)) * uint64_t(DisplayEncoder::statisticsSize(height));
    for (const ToneMapSettings& settings : {ToneMapSettings{}, autoKey, linear, clamp}) {
      for (float exposure : {1.0f, 0.3f}) {
        pixels.assign(size_t(pitchWords) * size_t(height), kPadding);
        std::vector<uint32_t> expected = pixels;
        gpu.encodeDisplay(onGpu, exposure, settings, pixels.data(), pitchWords * 4);
        onCpu.encode(radiance, exposure, settings, expected.data(), pitchWords * 4);
        if (toneMapStatistics(settings) == ToneMapStatistics::LogAverage) {
          // Eq. 1's terms in float: each within ~6e-6 of the double (LogLuminanceTermsMatchTheCpu:
          // 3 ulp of |ln| ≤ 16, plus δ + Y rounded), so the mean log too; the runs' Kahan sums
          // add a rounding or two of a sum of 64 terms, under 1e-7 on the mean. exp() turns that
          // into a relative error under ~7e-6 on the scale: 2e-5 is three times it (measured:
          // at most 1.8e-7 on these frames).
          const float scale = onCpu.curve().luminanceScale;
          EXPECT_NEAR(onGpu.curve().luminanceScale, scale, 2e-5f * scale) << width;
          std::printf("%dx%d: log-average key's scale relative difference %.3g\n", width, height,
                      double(onGpu.curve().luminanceScale / scale - 1.0f));
        } else {
          EXPECT_EQ(onGpu.curve().luminanceScale, onCpu.curve().luminanceScale);
          EXPECT_EQ(onGpu.curve().whiteScaled, onCpu.curve().whiteScaled);
        }
        int differing = 0, worst = 0;
        for (int y = 0; y < height; ++y)
          for (int x = 0; x < pitchWords; ++x) {
            const size_t i = size_t(y) * size_t(pitchWords) + size_t(x);
            if (x >= width) {
              EXPECT_EQ(pixels[i], kPadding) << x << ", " << y;
              continue;
            }
            differing += pixels[i] != expected[i];
            worst = std::max(worst, wordChannelDistance(pixels[i], expected[i]));
          }
        EXPECT_LE(worst, 1) << toneMapOperatorName(settings.op);
        EXPECT_LE(differing, allowedRoundingWords(size_t(width * height))) << toneMapOperatorName(settings.op);
      }
    }
    EXPECT_GT(gpu.lastGpuPasses().total(), 0.0);
    EXPECT_EQ(gpu.gpuBytes() - before,
              4 * uint64_t(width * height) + 16 * subsample + (first ? 4 * DisplayEncoder::kSrgbTableSize : 0));
  }
}

/// Channel `shift` (0: blue … 24: alpha) of an 0xAARRGGBB word, in [0, 255].
int wordChannel(uint32_t word, int shift) { return int((word >> shift) & 255u); }

/// What a window shows of `frame` (fw × fh words) stretched over w × h pixels by GL's bilinear
/// filter (texel centres at half-integers, clamped at the edges), each channel rounded.
std::vector<uint32_t> bilinearStretch(const std::vector<uint32_t>& frame, int fw, int fh, int w, int h) {
  std::vector<uint32_t> out(size_t(w) * size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double u = (x + 0.5) / w * fw - 0.5, v = (y + 0.5) / h * fh - 0.5;
      const int x0 = int(std::floor(u)), y0 = int(std::floor(v));
      const double ax = u - x0, ay = v - y0;
      auto texel = [&](int tx, int ty) {
        return frame[size_t(std::clamp(ty, 0, fh - 1)) * size_t(fw) + size_t(std::clamp(tx, 0, fw - 1))];
      };
      uint32_t word = 0xFF000000u;
      for (int shift : {0, 8, 16}) {
        const double c = (1 - ay) * ((1 - ax) * wordChannel(texel(x0, y0), shift) + ax * wordChannel(texel(x0 + 1, y0), shift)) +
                         ay * ((1 - ax) * wordChannel(texel(x0, y0 + 1), shift) + ax * wordChannel(texel(x0 + 1, y0 + 1), shift));
        word |= uint32_t(std::lround(c)) << shift;
      }
      out[size_t(y) * size_t(w) + size_t(x)] = word;
    }
  return out;
}

// The viewer's present pass (what a window with the renderer's context shows): the frame's
// words as the display pass made them, texel for pixel; the HUD blended over the top-left
// corner by its alpha as SDL_BLENDMODE_BLEND blends; a frame smaller than the window
// stretched bilinearly; a frame from the CPU (its pitch honoured) shown as it is.
TEST_F(GpuRendererTest, PresentShowsTheFrameWordsAndTheHud) {
  const LightField lf = randomLightField(loadScene(kMcGuire + "CornellBox-Glossy.obj"), 3);
  GpuRenderer gpu(lf);
  constexpr int kWidth = 40, kHeight = 30;
  const Camera camera(insideCamera(lf.scene), kWidth, kHeight);
  gpu.draw(camera, RenderSettings{});
  EXPECT_THROW(gpu.presentOffscreen({}, {}, kWidth, kHeight), Error);  // drawn, not encoded yet
  DisplayEncoder encoder;
  std::vector<uint32_t> words(size_t(kWidth) * size_t(kHeight));
  gpu.encodeDisplay(encoder, 1.0f, ToneMapSettings{}, words.data(), 4 * kWidth);
  const uint64_t before = gpu.gpuBytes();
  EXPECT_EQ(gpu.presentOffscreen({}, {}, kWidth, kHeight), words);
  EXPECT_EQ(gpu.gpuBytes(), before);  // (the words read where the display pass wrote them)
  gpu.encodeDisplay(encoder, 0.25f, ToneMapSettings{}, nullptr, 0);  // left on the GPU
  std::vector<uint32_t> darker(words.size());
  gpu.encodeDisplay(encoder, 0.25f, ToneMapSettings{}, darker.data(), 4 * kWidth);
  EXPECT_EQ(gpu.presentOffscreen({}, {}, kWidth, kHeight), darker);
  EXPECT_NE(darker, words);

  // The HUD: 13 × 7 words of every alpha, blended over the frame's corner.
  Pcg32 rng(7, 1);
  constexpr int kHudWidth = 13, kHudHeight = 7;
  std::vector<uint32_t> hud(size_t(kHudWidth) * size_t(kHudHeight));
  for (uint32_t& word : hud) word = rng.next();
  hud[0] = 0x00FFFFFFu;  // transparent
  hud[1] = 0xFF102030u;  // opaque
  hud[2] = 0x80000000u;  // the HUD's backdrop: black at half opacity
  const std::vector<uint32_t> shown = gpu.presentOffscreen({}, {hud.data(), kHudWidth, kHudHeight, 4 * kHudWidth}, kWidth, kHeight);
  ASSERT_EQ(shown.size(), darker.size());
  int worst = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const size_t i = size_t(y) * kWidth + size_t(x);
      if (x >= kHudWidth || y >= kHudHeight) {
        ASSERT_EQ(shown[i], darker[i]) << x << ", " << y;
        continue;
      }
      const uint32_t o = hud[size_t(y) * kHudWidth + size_t(x)];
      const double a = wordChannel(o, 24) / 255.0;
      EXPECT_EQ(wordChannel(shown[i], 24), 255);
      for (int shift : {0, 8, 16}) {
        const long expected = std::lround(wordChannel(o, shift) * a + wordChannel(darker[i], shift) * (1.0 - a));
        worst = std::max(worst, int(std::abs(wordChannel(shown[i], shift) - expected)));
      }
    }
  EXPECT_LE(worst, 1);  // (8-bit blending: one level of rounding)
  EXPECT_EQ(shown[0], darker[0]);
  EXPECT_EQ(shown[1], 0xFF102030u);

  // A CPU frame with a padded pitch, at the window's size: as it is; smaller: stretched.
  constexpr int kPitchWords = kWidth + 5;
  std::vector<uint32_t> padded(size_t(kPitchWords) * kHeight, 0xFFFF00FFu);
  for (int y = 0; y < kHeight; ++y) std::copy_n(&words[size_t(y) * kWidth], kWidth, &padded[size_t(y) * kPitchWords]);
  EXPECT_EQ(gpu.presentOffscreen({padded.data(), kWidth, kHeight, 4 * kPitchWords}, {}, kWidth, kHeight), words);
  // Stretched: the CPU's frame, and the display pass's (copied into the frame texture on the GPU).
  for (bool cpuFrame : {true, false})
    for (auto [w, h] : {std::pair{80, 60}, std::pair{67, 45}}) {
      const std::vector<uint32_t>& source = cpuFrame ? words : darker;
      const std::vector<uint32_t> stretched =
          gpu.presentOffscreen(cpuFrame ? DisplayPixels{words.data(), kWidth, kHeight, 4 * kWidth} : DisplayPixels{}, {}, w, h);
      const std::vector<uint32_t> expected = bilinearStretch(source, kWidth, kHeight, w, h);
      int far = 0;
      for (size_t i = 0; i < expected.size(); ++i) far = std::max(far, wordChannelDistance(stretched[i], expected[i]));
      // (GPUs weigh the four texels in fixed point, 8 bits on most: a level or two off the exact
      // weights where neighbours differ by most of the range.)
      EXPECT_LE(far, 2) << w << "x" << h << (cpuFrame ? " from the CPU" : " from the GPU");
    }
  EXPECT_EQ(gpu.gpuBytes() - before, 4u * kWidth * kHeight + 4u * kHudWidth * kHudHeight);  // frame and HUD textures
  EXPECT_THROW(gpu.presentOffscreen({words.data(), kWidth, kHeight, 4 * kWidth - 4}, {}, kWidth, kHeight), Error);
  EXPECT_THROW(gpu.presentOffscreen({}, {}, 0, kHeight), Error);
  // A new size re-makes the frame's targets: nothing encoded at that size yet.
  gpu.draw(Camera(insideCamera(lf.scene), 20, 15), RenderSettings{});
  EXPECT_THROW(gpu.presentOffscreen({}, {}, 20, 15), Error);
}

// A renderer in the caller's context (the viewer's window's) needs one to be current: without
// one it is a clear error, not a crash in the GL dispatch.
TEST_F(GpuRendererTest, CurrentContextIsRequired) {
  const LightField lf = randomLightField(makeCornellBox(), 3);
  try {
    GpuRenderer gpu(lf, GpuContext::Current);
    FAIL() << "made a renderer without a current context";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no OpenGL context is current"), std::string::npos) << e.what();
  }
}

// The viewer's refinement on the GPU: frames of several samples accumulated there, their
// average (sum × 1 / count) read back and shown, against the same average made on the CPU from
// each frame read back — the same floats, and the same words as DisplayEncoder makes of them.
TEST_F(GpuRendererTest, AccumulatedFramesAverageAsOnTheCpu) {
  const LightField lf = randomLightField(loadScene(kMcGuire + "CornellBox-Glossy.obj"), 5);
  GpuRenderer gpu(lf);
  const Camera camera(insideCamera(lf.scene), 40, 30);
  Image frame, sum, average;
  RenderSettings settings;
  settings.samplesPerPixel = 2;
  EXPECT_THROW(gpu.readAverage(average), Error);  // nothing accumulated yet
  for (int batch = 0; batch < 3; ++batch) {
    settings.seed = 17 + uint64_t(batch);
    gpu.draw(camera, settings);
    gpu.accumulate(batch == 0);
    gpu.readRadiance(frame);
    if (batch == 0) sum = Image(frame.width, frame.height);
    for (size_t i = 0; i < sum.pixels.size(); ++i) sum.pixels[i] += frame.pixels[i];
    EXPECT_EQ(gpu.accumulatedFrames(), batch + 1);
  }
  const float weight = 1.0f / 3.0f;
  Image expected(sum.width, sum.height);
  for (size_t i = 0; i < sum.pixels.size(); ++i) expected.pixels[i] = sum.pixels[i] * weight;
  gpu.readAverage(average);
  ASSERT_EQ(average.width, 40);
  size_t equal = 0;
  for (size_t i = 0; i < average.pixels.size(); ++i) equal += average.pixels[i] == expected.pixels[i];
  EXPECT_EQ(equal, average.pixels.size());
  DisplayEncoder onGpu, onCpu;
  std::vector<uint32_t> words(40 * 30), expectedWords(40 * 30);
  gpu.encodeDisplay(onGpu, 0.7f, ToneMapSettings{}, words.data(), 40 * 4, true);
  onCpu.encode(expected, 0.7f, ToneMapSettings{}, expectedWords.data(), 40 * 4);
  int worst = 0, differing = 0;
  for (size_t i = 0; i < words.size(); ++i) {
    worst = std::max(worst, wordChannelDistance(words[i], expectedWords[i]));
    differing += words[i] != expectedWords[i];
  }
  EXPECT_LE(worst, 1);
  EXPECT_LE(differing, allowedRoundingWords(words.size()));
  // A restart keeps the last frame alone; new targets (another size) drop the sum.
  gpu.accumulate(true);
  EXPECT_EQ(gpu.accumulatedFrames(), 1);
  gpu.readAverage(average);
  gpu.readRadiance(frame);
  EXPECT_EQ(compareImages(average, frame).maxAbsError, 0.0);
  const uint64_t before = gpu.gpuBytes();
  gpu.draw(Camera(insideCamera(lf.scene), 20, 10), settings);  // new targets: the accumulation is gone
  EXPECT_EQ(gpu.accumulatedFrames(), 0);
  EXPECT_LT(gpu.gpuBytes(), before);
}

void addLights(Scene& scene);  // below

// Mirror-like lobes (specular charts of a Blinn-Phong or GGX model too narrow for a map):
// followed as the fast renderer follows them — kFirstHitLobeSamples stratified lobe samples at
// the camera ray's first hit, each with a light sample (MirrorLikeLights, MIS against the lobe),
// one at later hits — with the same numbers (specularLobeU, nextEventU: hashes of the ray's
// bits), at one sample per pixel and several, one reflection deep.
//
// Not yet pixel for pixel: a few pixels at the edges of the lamp's reflection differ (23 of
// 768 in the worst view here, mean luminance within 0.5 %), so this asserts the mean within
// 1 % and at most 5 % of the pixels off by more than 1e-3 relative, not the relMSE ≤ 1e-4 of
// the other scenes (docs/design.md "Mirror-like lobes in the GPU renderer").
TEST_F(GpuRendererTest, MatchesFastRendererOnMirrorLikeCornellBox) {
  const LightField lf = randomLightField(test_support::mirrorLikeCornellBox(), 5);
  ASSERT_EQ(gpuUnsupportedFeature(lf), "");
  uint32_t mirrorLike = 0;
  for (const Chart& c : lf.charts) mirrorLike += isMirrorLikeRecord(c, lf.scene.materials[c.material].bsdf);
  ASSERT_GT(mirrorLike, 0u);
  GpuRenderer gpu(lf);
  const Accel accel(lf.scene);
  const FastRenderer fast(lf, accel);
  auto expectClose = [&](const Camera& camera, const RenderSettings& settings) {
    const Image expected = fast.render(camera, settings);
    Image image;
    gpu.render(camera, settings, image);
    ASSERT_EQ(image.pixels.size(), expected.pixels.size());
    const ImageComparison c = compareImages(image, expected);
    size_t differing = 0;
    for (size_t i = 0; i < image.pixels.size(); ++i)
      differing += glm::length(image.pixels[i] - expected.pixels[i]) > 1e-3f * (1.0f + glm::length(expected.pixels[i]));
    EXPECT_EQ(c.nonFinitePixels, 0u);
    EXPECT_NEAR(c.meanLuminanceRatio, 1.0, 1e-2);
    EXPECT_LE(double(differing), 0.05 * double(image.pixels.size()));
    std::printf("%dx%d: relMSE %.3g, mean luminance ratio %.6f, %zu pixels differ by more than 1e-3\n", camera.width(),
                camera.height(), c.relMseAverage, c.meanLuminanceRatio, differing);
  };
  RenderSettings one;
  one.mirrorDepth = 1;
  expectClose(Camera(firstCamera(lf.scene), 32, 24), one);
  expectClose(Camera(insideCamera(lf.scene), 32, 24, true), one);
  one.samplesPerPixel = 2;
  one.seed = 3;
  expectClose(Camera(firstCamera(lf.scene), 24, 18), one);
}

TEST_F(GpuRendererTest, RefusesWhatItDoesNotDrawYet) {
  // An environment map lighting a mirror-like lobe: the GLSL light sampler does not sample maps.
  Scene sky = test_support::mirrorLikeCornellBox();
  sky.environment.map = std::make_shared<const EnvironmentMap>(test_support::skyWithSun(30.0f));
  const LightField mapLit = randomLightField(std::move(sky), 5);
  EXPECT_EQ(gpuUnsupportedFeature(mapLit), "environment maps lighting mirror-like lobes");
  try {
    GpuRenderer gpu(mapLit);
    ADD_FAILURE() << "the map-lit mirror-like box was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("environment maps lighting mirror-like lobes"), std::string::npos) << e.what();
  }
  // A clear coat over a metallic-roughness texture: each point's α would need its own k(μ)
  // normalisation (here for the highlights of delta lights).
  Scene layered = test_support::rampBox(-1);
  for (Material& m : layered.materials)
    if (m.metallicRoughness.texture >= 0) {
      m.layers.layered = true;
      m.layers.factors = GltfPbrInputs{.baseColor = Rgb(0.8f), .metallic = 0.0f, .roughness = 0.6f, .clearcoat = 0.5f,
                                       .clearcoatRoughness = 0.5f};
      m.bsdf = gltfPbrFromInputs(m.layers.factors);
    }
  addLights(layered);
  EXPECT_EQ(gpuUnsupportedFeature(randomLightField(std::move(layered), 8)),
            "glTF materials with a clear coat or sheen and a metallic-roughness texture");
  EXPECT_EQ(gpuUnsupportedFeature(randomLightField(makeCornellBox(), 6)), "");
}

// A thin lens (depth of field): the CPU renderers' lens points (pixelSample's second ZSobol
// dimension; the lens centre at one sample per pixel), every camera ray cast through the BVH —
// the built-in box (millimetres) at f/2.8 focused on the back wall's centre and at f/1 on a near
// point, at 1, 4 and the default 16 samples per pixel, and through the mirror box's chains.
TEST_F(GpuRendererTest, ThinLensMatchesFastRenderer) {
  const LightField box = randomLightField(makeCornellBox(), 6);
  GpuRenderer gpu(box);
  CameraDesc lens = firstCamera(box.scene);
  lens.fNumber = 2.8f;
  RenderSettings one, four, sixteen;
  one.samplesPerPixel = 1;
  four.samplesPerPixel = 4;
  four.seed = 99;
  const float mm = 0.001f;  // the box's unit in metres: sizes the aperture
  expectSameAsFastRenderer(box, gpu, Camera(lens, 64, 48, false, mm), one);
  expectSameAsFastRenderer(box, gpu, Camera(lens, 64, 48, false, mm), four);
  expectSameAsFastRenderer(box, gpu, Camera(lens, 32, 24, true, mm), sixteen);
  CameraDesc near = insideCamera(box.scene);
  near.fNumber = 1.0f;
  near.focusDistance = 150.0f;
  expectSameAsFastRenderer(box, gpu, Camera(near, 48, 40, false, mm), four);
  // The blur is drawn: at 4 samples the lens moves the picture away from the pinhole's.
  CameraDesc pinhole = near;
  pinhole.fNumber = 0.0f;
  Image blurred, sharp;
  gpu.render(Camera(near, 48, 40, false, mm), four, blurred);
  gpu.render(Camera(pinhole, 48, 40, false, mm), four, sharp);
  EXPECT_GT(compareImages(blurred, sharp).relMseAverage, 1e-3);

  const LightField mirror = randomLightField(loadScene(kMcGuire + "CornellBox-Mirror.obj"), 14);
  GpuRenderer mirrorGpu(mirror);
  CameraDesc mirrorLens = firstCamera(mirror.scene);
  mirrorLens.fNumber = 0.5f;
  expectSameAsFastRenderer(mirror, mirrorGpu, Camera(mirrorLens, 48, 48, false, 1.0f), four);
}

// The BVH traversal the shading pass traces mirrors and glass with (gpu_bvh.h), run on the GPU,
// against the same traversal on the CPU and against Embree: the same closest triangle and t
// to float rounding, and bvhOccluded agreeing with the closest hit.
TEST_F(GpuRendererTest, BvhTraversalMatchesCpuAndEmbree) {
  const LightField lf = randomLightField(loadScene(kMcGuire + "CornellBox-Sphere.obj"), 21);
  GpuRenderer gpu(lf);
  const Scene& scene = lf.scene;
  const Accel accel(scene);
  std::vector<Vec3> positions;
  std::vector<UVec3> triangles;
  std::vector<std::pair<uint32_t, uint32_t>> meshTriangle;
  flattenSceneTriangles(scene, positions, triangles, &meshTriangle);
  const GpuBvh bvh = buildGpuBvh(positions, triangles);
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  Pcg32 rng(11, 3);
  std::vector<Ray> rays(3000);
  for (size_t i = 0; i < rays.size(); ++i) {
    rays[i].origin = lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * (hi - lo);
    rays[i].direction = sampleUniformSphere(Vec2(rng.uniform(), rng.uniform()));
    if (i % 3 == 0) rays[i].tMax = 0.3f * glm::length(hi - lo) * rng.uniform();  // shadow-ray segments
  }
  std::vector<uint8_t> occluded;
  const std::vector<BvhHit> hits = gpu.intersect(rays, &occluded);
  ASSERT_EQ(hits.size(), rays.size());
  size_t sameAsCpu = 0, sameAsEmbree = 0, hitCount = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    const BvhHit cpu = intersectGpuBvh(bvh, rays[i]);
    RayHit embree;
    accel.intersect(rays[i], embree);
    EXPECT_EQ(hits[i].triangle != 0xffffffffu, embree.hit()) << "ray " << i;
    EXPECT_EQ(occluded[i] != 0, embree.hit()) << "ray " << i;
    if (!embree.hit() || hits[i].triangle == 0xffffffffu) continue;
    ++hitCount;
    EXPECT_NEAR(hits[i].t, embree.t, 1e-5f * std::max(1.0f, embree.t)) << "ray " << i;
    EXPECT_NEAR(hits[i].t, cpu.t, 1e-5f * std::max(1.0f, cpu.t)) << "ray " << i;
    sameAsCpu += hits[i].triangle == cpu.triangle;
    sameAsEmbree += meshTriangle[hits[i].triangle] == std::make_pair(embree.mesh, embree.triangle);
  }
  EXPECT_GT(hitCount, rays.size() / 2);
  // A different triangle only where a ray passes within rounding of a shared edge.
  EXPECT_GE(sameAsCpu, hitCount - 3);
  EXPECT_GE(sameAsEmbree, hitCount - 3);
}

/// The built-in Cornell box with a glass ball (solid, η 1.5, a little absorption) in front of
/// the tall block and a thin glass sheet, for the specular chains on the GPU.
Scene glassBallBox() {
  Scene scene = makeCornellBox();
  Material glass;
  glass.name = "glass";
  glass.bsdf = DielectricBsdf{1.5f, Rgb(1.0f), 0.0f, false, Rgb(0.002f, 0.001f, 0.0f)};
  scene.materials.push_back(glass);
  Material sheet;
  sheet.name = "sheet";
  sheet.bsdf = DielectricBsdf{1.5f, Rgb(0.9f, 0.8f, 0.9f), 0.0f, true, Rgb(0.0f)};
  scene.materials.push_back(sheet);
  Mesh ball;
  ball.name = "ball";
  test_support::addSphere(ball, Vec3(200.0f, 110.0f, 150.0f), 100.0f, 16, 32, uint32_t(scene.materials.size() - 2));
  scene.meshes.push_back(std::move(ball));
  Mesh pane;
  pane.name = "pane";
  pane.positions = {Vec3(330.0f, 20.0f, 80.0f), Vec3(480.0f, 20.0f, 80.0f), Vec3(480.0f, 250.0f, 120.0f), Vec3(330.0f, 250.0f, 120.0f)};
  pane.triangles = {UVec3(0, 1, 2), UVec3(0, 2, 3)};
  pane.materials = {uint32_t(scene.materials.size() - 1), uint32_t(scene.materials.size() - 1)};
  scene.meshes.push_back(std::move(pane));
  scene.finalize();
  return scene;
}

// Mirrors: the tall block of McGuire's mirror box reflects the room, up to the mirror depth.
TEST_F(GpuRendererTest, MatchesFastRendererOnMirrorCornellBox) {
  const LightField lf = randomLightField(loadScene(kMcGuire + "CornellBox-Mirror.obj"), 22);
  ASSERT_EQ(gpuUnsupportedFeature(lf), "");
  GpuRenderer gpu(lf);
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 64);
  expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 80, 60, true);
  RenderSettings shallow;
  shallow.mirrorDepth = 1;
  expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 48, 36, false, shallow);
  RenderSettings multi;
  multi.samplesPerPixel = 3;
  multi.seed = 5;
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 48, 48, false, multi);
}

// Glass: a solid ball (refraction in and out, total internal reflection, Beer–Lambert) and a
// thin sheet, each branch drawn as followSpecular draws it (the hash of the arriving ray).
TEST_F(GpuRendererTest, MatchesFastRendererOnGlassBall) {
  const LightField lf = randomLightField(glassBallBox(), 23);
  ASSERT_EQ(gpuUnsupportedFeature(lf), "");
  GpuRenderer gpu(lf);
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 64, false, {}, 0.01);
  expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 64, 48, false, {}, 0.01);
  // One interface only: every branch is drawn from the camera ray's own bits, the same on
  // both renderers (a pixel or two differ where the refracted ray passes within rounding of
  // an edge).
  RenderSettings one;
  one.mirrorDepth = 1;
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 48, 48, false, one, 0.002);
  // Four samples a pixel are four chances for a branch drawn apart: 25 of the 2 304 pixels
  // (1.1 %) with the stratified film points (pixelSample), mean ratio 1.0006, relMSE 0.0013.
  RenderSettings multi;
  multi.samplesPerPixel = 4;
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 48, 48, false, multi, 0.015);
}

// Rough glass: a glossy chart on both sides (lightfield.h "Rough glass"), the ball's inside its
// back records; looked up as the fast renderer looks it up.
TEST_F(GpuRendererTest, MatchesFastRendererOnRoughGlassBall) {
  Scene scene = glassBallBox();
  for (Material& m : scene.materials)
    if (auto* glass = std::get_if<DielectricBsdf>(&m.bsdf); glass != nullptr) {
      if (glass->thin)
        m.bsdf = LambertBsdf{Rgb(0.5f)};  // no specular chain: the lookups alone, pixel for pixel
      else
        glass->alpha = 0.09f;
    }
  const LightField lf = randomLightField(std::move(scene), 24);
  ASSERT_TRUE(std::any_of(lf.charts.begin(), lf.charts.end(),
                          [&](const Chart& c) { return isRoughGlassChart(c, lf.scene.materials[c.material].bsdf); }));
  ASSERT_EQ(gpuUnsupportedFeature(lf), "");
  GpuRenderer gpu(lf);
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 64);
  expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 64, 48);
}

/// A point, a spot and a directional light added to `scene` (delta lights: punctual highlights).
void addLights(Scene& scene) {
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  const Vec3 extent = hi - lo;
  scene.lights.push_back(PointLight{lo + Vec3(0.3f, 0.8f, 0.6f) * extent, Rgb(0.4f, 0.3f, 0.2f) * glm::dot(extent, extent)});
  SpotLight spot;
  spot.position = lo + Vec3(0.7f, 0.9f, 0.4f) * extent;
  spot.direction = Vec3(-0.2f, -1.0f, 0.1f);
  spot.intensity = Rgb(0.2f, 0.3f, 0.5f) * glm::dot(extent, extent);
  spot.innerAngle = 0.3f;
  spot.outerAngle = 0.6f;
  spot.prepare();
  scene.lights.push_back(spot);
  DirectionalLight sun;
  sun.direction = Vec3(0.3f, -1.0f, -0.6f);
  sun.irradiance = Rgb(2.0f);
  scene.lights.push_back(sun);
}

// Punctual highlights (lookup.h PunctualHighlights): point, spot and directional lights'
// direct glossy reflection evaluated per pixel with a shadow ray through the GPU BVH, on
// McGuire's glossy box (Blinn-Phong, the diffuse part in Ẽ) and on GGX metal walls around a
// glass ball and a thin glass sheet (the highlights seen through the glass, the sheet's
// shadow its transmittance).
TEST_F(GpuRendererTest, PunctualHighlightsMatchFastRenderer) {
  Scene glossy = loadScene(kMcGuire + "CornellBox-Glossy.obj");
  addLights(glossy);
  const LightField glossyLf = randomLightField(std::move(glossy), 25);
  ASSERT_TRUE(glossyLf.settings.punctualHighlights);
  ASSERT_EQ(gpuUnsupportedFeature(glossyLf), "");
  GpuRenderer glossyGpu(glossyLf);
  // (A pixel may differ where a shadow ray passes within rounding of an occluder's edge: its
  // origin is rebuilt from barycentrics that the GPU traversal and Embree give a few ulp apart.)
  expectSameAsFastRenderer(glossyLf, glossyGpu, firstCamera(glossyLf.scene), 64, 64, false, {}, 0.002);
  expectSameAsFastRenderer(glossyLf, glossyGpu, insideCamera(glossyLf.scene), 64, 48, false, {}, 0.002);
  // The highlights are there: without them (a light field baked without) the picture differs.
  LightField without = randomLightField(loadScene(kMcGuire + "CornellBox-Glossy.obj"), 25);
  without.scene.lights = glossyLf.scene.lights;
  without.settings.punctualHighlights = false;
  GpuRenderer withoutGpu(without);
  Image with, plain;
  const Camera camera(firstCamera(glossyLf.scene), 32, 32);
  glossyGpu.render(camera, RenderSettings{}, with);
  withoutGpu.render(camera, RenderSettings{}, plain);
  EXPECT_GT(compareImages(with, plain).meanLuminanceRatio, 1.002);

  Scene metal = glassBallBox();
  for (Material& m : metal.materials)
    if (!m.isEmissive() && std::holds_alternative<LambertBsdf>(m.bsdf)) m.bsdf = GgxBsdf{Rgb(0.0f), Rgb(0.9f, 0.7f, 0.5f), 0.09f};
  addLights(metal);
  // Coarse tixels: the narrow lobe's maps at the default preset's 40 tixels across take 849 MiB,
  // past llvmpipe's largest storage block (128 MiB).
  BakeSettings coarse;
  coarse.tixelsAcrossScene = 12.0f;
  const LightField metalLf = randomLightField(std::move(metal), 26, coarse);
  ASSERT_EQ(gpuUnsupportedFeature(metalLf), "");
  GpuRenderer metalGpu(metalLf);
  expectSameAsFastRenderer(metalLf, metalGpu, firstCamera(metalLf.scene), 64, 64, false, {}, 0.01);
  expectSameAsFastRenderer(metalLf, metalGpu, insideCamera(metalLf.scene), 64, 48, false, {}, 0.01);
}

/// The metallic-roughness box (support/metallic_roughness_box.h: its white surfaces a glTF
/// material whose metalness and roughness follow a ramp texture along x) of ramp `texelOf` and
/// base colour `base`, the white surfaces also albedo-textured (uv v along y + z; coarse
/// tixels) and every other mesh vertex-coloured.
Scene metallicRoughnessBox(Rgb (*texelOf)(int), Rgb base) {
  Scene scene = test_support::rampBox(-1, texelOf, base);
  Pcg32 rng(62, 5);
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    Mesh& mesh = scene.meshes[m];
    for (size_t v = 0; v < mesh.positions.size(); ++v)
      mesh.uvs[v].y = (mesh.positions[v].y + mesh.positions[v].z) / test_support::kBoxWidth;
    if (m % 2 == 0)
      for (size_t v = 0; v < mesh.positions.size(); ++v) mesh.colors.push_back(Rgb(rng.uniform(), rng.uniform(), rng.uniform()));
  }
  scene.textures.push_back(test_support::randomTexture(16, 12, true, 5));
  for (Material& m : scene.materials)
    if (m.metallicRoughness.texture >= 0) {
      m.albedoTexture = int(scene.textures.size()) - 1;
      m.tixelDensity = 0.15f;  // coarse tixels: their maps stay a few MiB
    }
  scene.finalize();
  return scene;
}

// Metallic-roughness textures: the glossy charts' diffuse part with each pixel's own model
// (ρ and k(μo) of the texel's metalness and roughness, lookup.h glossyDiffuseReflectanceAt),
// over an albedo texture and vertex colours; a ramp through fractional metalness (glTF's
// layered mix) and one from a dielectric to a metal (GGX at its ends); then the punctual
// highlights of the points' own lobes (the texel's α and f0, the albedo at full resolution).
TEST_F(GpuRendererTest, MatchesFastRendererWithMetallicRoughnessTextures) {
  const std::pair<Rgb (*)(int), Rgb> ramps[] = {{test_support::rampTexel, Rgb(0.8f)},
                                                {test_support::metalRampTexel, Rgb(1.0f, 0.78f, 0.34f)}};
  for (const auto& [texelOf, base] : ramps) {
    SCOPED_TRACE(texelOf == test_support::rampTexel ? "ramp" : "metal ramp");
    const LightField lf = randomLightField(metallicRoughnessBox(texelOf, base), 63);
    ASSERT_EQ(gpuUnsupportedFeature(lf), "");
    ASSERT_GT(std::count_if(lf.charts.begin(), lf.charts.end(), [&](const Chart& c) {
                return c.diffuseValue && lf.scene.materials[c.material].metallicRoughness.texture >= 0;
              }),
              0);
    ASSERT_LT(lf.values.size(), 1u << 22);
    GpuRenderer gpu(lf);
    RenderSettings four;
    four.samplesPerPixel = 4;
    expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 48);
    expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 64, 48, false, four);

    Scene lit = metallicRoughnessBox(texelOf, base);
    addLights(lit);
    const LightField litLf = randomLightField(std::move(lit), 63);
    ASSERT_TRUE(litLf.settings.punctualHighlights);
    ASSERT_EQ(gpuUnsupportedFeature(litLf), "");
    GpuRenderer litGpu(litLf);
    // (Shadow rays within rounding of an edge may differ: PunctualHighlightsMatchFastRenderer.)
    expectSameAsFastRenderer(litLf, litGpu, firstCamera(litLf.scene), 64, 48, false, {}, 0.002);
    expectSameAsFastRenderer(litLf, litGpu, insideCamera(litLf.scene), 64, 48, false, {}, 0.002);
  }
  // The glTF room of bench/scenes/gltf-materials.gltf: a floor whose metallic-roughness ramp is
  // read through the second uv set, under a transformed, mirrored-repeat checker; walls of a
  // glTF material (GGX of roughness 1 over a diffuse base) coloured by COLOR_0.
  const LightField room =
      randomLightField(loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/../../bench/scenes/gltf-materials.gltf"), 65);
  ASSERT_EQ(gpuUnsupportedFeature(room), "");
  GpuRenderer roomGpu(room);
  RenderSettings four;
  four.samplesPerPixel = 4;
  expectSameAsFastRenderer(room, roomGpu, firstCamera(room.scene), 64, 48);
  expectSameAsFastRenderer(room, roomGpu, firstCamera(room.scene), 48, 36, false, four);
}

/// `scene` with every material that does not emit made a glTF model with layers over a
/// diffuse base of its albedo: a clear coat, a sheen, and both, in turn.
Scene withLayeredDiffuseBases(Scene scene) {
  int next = 0;
  for (Material& m : scene.materials) {
    if (m.isEmissive()) continue;
    GltfPbrInputs in{.baseColor = diffuseAlbedo(m.bsdf), .metallic = 0.0f, .roughness = 0.7f};
    m.tixelDensity = 0.15f;  // coarse tixels: their maps stay a few MiB
    const int kind = next++ % 3;
    if (kind != 1) in.clearcoat = 0.7f, in.clearcoatRoughness = 0.35f;
    if (kind != 0) in.sheenColor = Rgb(0.7f, 0.5f, 0.3f), in.sheenRoughness = 0.5f;
    m.bsdf = gltfPbrFromInputs(in);
  }
  return scene;
}

// glTF's clear coat and sheen over a diffuse base: the diffuse part's k(μ) under them (the
// coat's albedo from the GGX table, the sheen's from its own, ggx_lobe.h) — the glTF room of
// bench/scenes/gltf-layers.gltf (KHR_materials_clearcoat and KHR_materials_sheen) at 1 and 4
// samples per pixel; then CornellBox-Original's materials so, lit by delta lights: the
// highlights of the coat, the sheen and the base lobe, their diffuse part left to Ẽ.
TEST_F(GpuRendererTest, MatchesFastRendererWithClearcoatAndSheen) {
  auto layeredDiffuse = [](const LightField& lf) {
    return std::count_if(lf.charts.begin(), lf.charts.end(), [&](const Chart& c) {
      const std::optional<GgxLobeParameters> lobe = ggxLobeParameters(lf.scene.materials[c.material].bsdf);
      return c.diffuseValue && lobe && lobe->layered();
    });
  };
  Scene layers = loadScene(std::string(PLENOPTIC_TEST_DATA_DIR) + "/../../bench/scenes/gltf-layers.gltf");
  for (Material& m : layers.materials) m.tixelDensity = 0.2f;  // coarse tixels: their maps stay a few MiB
  const LightField room = randomLightField(std::move(layers), 66);
  ASSERT_EQ(gpuUnsupportedFeature(room), "");
  ASSERT_GT(layeredDiffuse(room), 0);
  ASSERT_LT(room.values.size(), 1u << 22);
  GpuRenderer roomGpu(room);
  RenderSettings four;
  four.samplesPerPixel = 4;
  expectSameAsFastRenderer(room, roomGpu, firstCamera(room.scene), 64, 48);
  expectSameAsFastRenderer(room, roomGpu, insideCamera(room.scene), 48, 36, false, four);

  Scene scene = withLayeredDiffuseBases(loadScene(kMcGuire + "CornellBox-Original.obj"));
  addLights(scene);
  const LightField lf = randomLightField(std::move(scene), 67);
  ASSERT_TRUE(gpuHighlightsActive(lf));
  ASSERT_EQ(gpuUnsupportedFeature(lf), "");
  ASSERT_GT(layeredDiffuse(lf), 0);
  ASSERT_LT(lf.values.size(), 1u << 22);
  GpuRenderer gpu(lf);
  // (Shadow rays within rounding of an edge may differ: PunctualHighlightsMatchFastRenderer.)
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 48, false, {}, 0.002);
  expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 64, 48, false, four, 0.002);
}

// Punctual highlights on GGX-like models with a diffuse base (GGX, glTF PBR): the lobe of each
// material, its diffuse part left to the map's Ẽ.
TEST_F(GpuRendererTest, PunctualHighlightsOnGltfMaterialsMatchFastRenderer) {
  Scene scene = withGgxDiffuseBases(loadScene(kMcGuire + "CornellBox-Original.obj"));
  addLights(scene);
  const LightField lf = randomLightField(std::move(scene), 64);
  ASSERT_EQ(gpuUnsupportedFeature(lf), "");
  GpuRenderer gpu(lf);
  expectSameAsFastRenderer(lf, gpu, firstCamera(lf.scene), 64, 48, false, {}, 0.002);
  expectSameAsFastRenderer(lf, gpu, insideCamera(lf.scene), 64, 48, false, {}, 0.002);
}

/// `scene` with an albedo texture (texture 0) and random vertex colours on its mirrors and
/// glass, which leave their models as they are (materialModelAt): the chains read neither.
Scene withColouredSpecular(Scene scene) {
  Pcg32 rng(5, 17);
  auto specular = [](const Material& m) { return isDelta(m.bsdf) || std::holds_alternative<DielectricBsdf>(m.bsdf); };
  for (Material& m : scene.materials)
    if (specular(m)) m.albedoTexture = 0;
  for (Mesh& mesh : scene.meshes)
    if (specular(scene.materials[mesh.materials.front()])) {
      mesh.colors.clear();
      for (size_t v = 0; v < mesh.positions.size(); ++v) mesh.colors.push_back(Rgb(rng.uniform(), rng.uniform(), rng.uniform()));
    }
  scene.finalize();
  return scene;
}

// The traced rays read the surface detail at their hits as the CPU renderer's do: the mirror
// box with albedo textures (their mip level from the chain's ray cone), vertex colours, normal
// maps (on the mirror too: it reflects about the mapped normal) and alpha masks (cut by the
// reflected rays as by the camera's), the mirror emitting through an emission texture; the
// glossy box so, lit by delta lights whose highlights' shadow rays pass through the masks'
// holes; the glass ball, cut by a mask, and the sheet beside textured walls. The mirrors and glass
// carry albedo textures and vertex colours, which change nothing of them. (No mask here lets a
// ray reach a face lying on another, as a box's bottom on the floor: which of two coplanar
// triangles rasterisation and the ray caster see is not the same, docs/limitations.md.)
TEST_F(GpuRendererTest, TracedRaysReadSurfaceDetailAtTheirHits) {
  Scene mirror = withAlphaMasks(withNormalMaps(loadScene(kMcGuire + "CornellBox-Mirror.obj")), {"leftWall", "backWall"});
  for (Material& m : mirror.materials)
    if (std::holds_alternative<MirrorBsdf>(m.bsdf)) {
      m.emission = Rgb(0.2f, 0.3f, 0.1f);
      m.emissionTexture = 3;
    }
  const LightField mirrorLf = randomLightField(withColouredSpecular(std::move(mirror)), 51);
  ASSERT_EQ(gpuUnsupportedFeature(mirrorLf), "");
  GpuRenderer mirrorGpu(mirrorLf);
  RenderSettings three;
  three.samplesPerPixel = 3;
  expectSameAsFastRenderer(mirrorLf, mirrorGpu, firstCamera(mirrorLf.scene), 64, 64);
  expectSameAsFastRenderer(mirrorLf, mirrorGpu, insideCamera(mirrorLf.scene), 64, 48, true, three);

  Scene glossy = withAlphaMasks(withNormalMaps(loadScene(kMcGuire + "CornellBox-Glossy.obj")), {"sphere", "leftWall"});
  addLights(glossy);
  const LightField glossyLf = randomLightField(std::move(glossy), 52);
  ASSERT_TRUE(gpuHighlightsActive(glossyLf));
  ASSERT_EQ(gpuUnsupportedFeature(glossyLf), "");
  GpuRenderer glossyGpu(glossyLf);
  // (A pixel may differ where a shadow ray passes within rounding of an occluder's edge.)
  expectSameAsFastRenderer(glossyLf, glossyGpu, firstCamera(glossyLf.scene), 48, 48, false, {}, 0.002);
  expectSameAsFastRenderer(glossyLf, glossyGpu, insideCamera(glossyLf.scene), 48, 36, false, {}, 0.002);

  const LightField glassLf =
      randomLightField(withColouredSpecular(withAlphaMasks(withSurfaceDetail(glassBallBox(), true), {"ball"})), 53);
  ASSERT_EQ(gpuUnsupportedFeature(glassLf), "");
  GpuRenderer glassGpu(glassLf);
  expectSameAsFastRenderer(glassLf, glassGpu, firstCamera(glassLf.scene), 64, 64, false, {}, 0.01);

}

TEST_F(GpuRendererTest, GpuMemoryIsTheLightFieldAndOneFrame) {
  const LightField lf = randomLightField(loadScene(kMcGuire + "CornellBox-Glossy.obj"), 7);
  GpuRenderer gpu(lf);
  Image image;
  gpu.render(Camera(firstCamera(lf.scene), 64, 48), RenderSettings{}, image);
  // Values as 16-byte RGBA, 128 bytes per chart record, the geometry, 292 bytes per material
  // and the GGX and sheen albedo tables after a 32-byte header (no textures, uvs or masks here),
  // the BVH of the primary rays beside edges (32 bytes per node, 48 per triangle) and 44 bytes
  // per pixel (radiance, hits, the queue of rays to cast, id and depth) and the queue's
  // 16-byte header.
  uint64_t geometry = 0;
  for (const Mesh& m : lf.scene.meshes) geometry += m.positions.size() * 32 + m.triangles.size() * 28;
  const GgxAlbedoTables& ggx = ggxAlbedoTables();
  const SheenAlbedoTables& sheen = sheenAlbedoTables();
  const uint64_t tables = 4 * (ggx.mu.size() + ggx.e0.size() + ggx.e5.size() + ggx.mean0.size() + ggx.mean5.size() +
                               sheen.mu.size() + sheen.e.size() + sheen.scale.size());
  std::vector<Vec3> positions;
  std::vector<UVec3> triangles;
  flattenSceneTriangles(lf.scene, positions, triangles);
  const GpuBvh bvh = buildGpuBvh(positions, triangles);
  const uint64_t expected = lf.values.size() * 16 + lf.charts.size() * 128 + geometry + 32 +
                            lf.scene.materials.size() * 292 + tables + bvh.nodes.size() * 32 +
                            bvh.triangles.size() * 48 + 64 * 48 * 44 + 16;
  EXPECT_LE(gpu.gpuBytes(), expected + 8 * 16);  // 16-byte stand-ins for empty buffers
  EXPECT_GE(gpu.gpuBytes(), expected);
  EXPECT_NE(gpu.deviceName().find("OpenGL 4.5"), std::string::npos) << gpu.deviceName();
}

// Sponza (/work/shared/scenes/sponza, where present: it is not part of the repository) at
// 160×120, both cameras: textures at their levels of detail, alpha-masked plants and chains,
// normal maps, curved charts and the sun's masks, on a random light field with the draft
// preset's charts (bench/gpu_vs_cpu.sh compares a real draft bake). Sponza has coplanar,
// overlapping faces, where the GPU's traversal and Embree may pick different triangles at one
// distance (and so, on a random light field, very different values: a dozen pixels), so this
// asserts the mean, that at most 0.5 % of pixels differ by more than 1 %, and relMSE over the
// rest.
TEST_F(GpuRendererTest, MatchesFastRendererOnSponza) {
  const std::string file = "/work/shared/scenes/sponza/sponza.json";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is absent (bench/gpu_vs_cpu.sh runs this comparison)";
  const LightField lf = randomLightField(loadScene(file), 44, bakePreset("draft"));
  ASSERT_EQ(gpuUnsupportedFeature(lf), "");
  GpuRenderer gpu(lf);
  const Accel accel(lf.scene);
  const FastRenderer fast(lf, accel);
  for (const CameraDesc& desc : lf.scene.cameras) {
    SCOPED_TRACE(desc.name);
    const Camera camera(desc, 160, 120);
    const Image expected = fast.render(camera, RenderSettings{});
    Image image;
    gpu.render(camera, RenderSettings{}, image);
    Image agreeing = image, agreeingExpected = expected;
    size_t differing = 0;
    for (size_t i = 0; i < image.pixels.size(); ++i) {
      const Rgb a = image.pixels[i], b = expected.pixels[i];
      if (glm::length(a - b) > 0.01f * glm::length(b) + 1e-4f) {
        ++differing;
        agreeing.pixels[i] = agreeingExpected.pixels[i] = Rgb(0.0f);
      }
    }
    const ImageComparison all = compareImages(image, expected), rest = compareImages(agreeing, agreeingExpected);
    std::printf("Sponza %s 160x120: relMSE %.3g (%.3g without the %zu differing pixels), mean luminance ratio %.6f\n",
                desc.name.c_str(), all.relMseAverage, rest.relMseAverage, differing, all.meanLuminanceRatio);
    EXPECT_LE(differing, image.pixels.size() / 200);
    EXPECT_LE(rest.relMseAverage, 1e-4);
    EXPECT_NEAR(all.meanLuminanceRatio, 1.0, 1e-3);
    // The viewer's display pass on this frame (textures, the sky map's range, automatic key):
    // the words DisplayEncoder makes of the radiance render() read back.
    ToneMapSettings autoKey;
    autoKey.autoKey = true;
    for (const ToneMapSettings& settings : {ToneMapSettings{}, autoKey}) {
      DisplayEncoder onGpu, onCpu;
      std::vector<uint32_t> words(image.pixels.size()), expectedWords(image.pixels.size());
      gpu.encodeDisplay(onGpu, 0.5f, settings, words.data(), image.width * 4);
      onCpu.encode(image, 0.5f, settings, expectedWords.data(), image.width * 4);
      int differingWords = 0, worst = 0;
      for (size_t i = 0; i < words.size(); ++i) {
        differingWords += words[i] != expectedWords[i];
        worst = std::max(worst, wordChannelDistance(words[i], expectedWords[i]));
      }
      EXPECT_LE(worst, 1);
      EXPECT_LE(differingWords, allowedRoundingWords(words.size()));
      std::printf("Sponza %s display words (%s key): %d of %zu differ\n", desc.name.c_str(),
                  settings.autoKey ? "automatic" : "fixed", differingWords, words.size());
    }
  }
}

/// Sets an environment variable for the scope of one test.
class ScopedEnvironment {
 public:
  ScopedEnvironment(const char* name, const char* value) : name_(name) { setenv(name, value, 1); }
  ~ScopedEnvironment() { unsetenv(name_); }

 private:
  const char* name_;
};

// PLENOPTIC_GPU_VISIBILITY=rays: no rasterised ids, every camera ray cast through the BVH —
// the CPU renderer's picture still, at one sample per pixel and several, with alpha masks cut
// by the traversal; anything but raster or rays is refused by name.
TEST_F(GpuRendererTest, CastingEveryCameraRayDrawsTheSamePicture) {
  const ScopedEnvironment rays("PLENOPTIC_GPU_VISIBILITY", "rays");
  const LightField glossy = randomLightField(loadScene(kMcGuire + "CornellBox-Glossy.obj"), 21);
  GpuRenderer gpu(glossy);
  expectSameAsFastRenderer(glossy, gpu, insideCamera(glossy.scene), 64, 48);
  EXPECT_EQ(gpu.lastBvhRayShare(), std::optional<double>(1.0));
  RenderSettings settings;
  settings.samplesPerPixel = 4;
  expectSameAsFastRenderer(glossy, gpu, firstCamera(glossy.scene), 48, 40, false, settings);
  const LightField masked = randomLightField(withAlphaMasks(withSurfaceDetail(makeCornellBox(), true), {"blocks"}), 22);
  GpuRenderer maskedGpu(masked);
  expectSameAsFastRenderer(masked, maskedGpu, firstCamera(masked.scene), 64, 48);
  const ScopedEnvironment bogus("PLENOPTIC_GPU_VISIBILITY", "compute");
  try {
    GpuRenderer refused(glossy);
    ADD_FAILURE() << "PLENOPTIC_GPU_VISIBILITY=compute was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("PLENOPTIC_GPU_VISIBILITY=compute is not a visibility mode (use raster or rays)"),
              std::string::npos)
        << e.what();
  }
}

// An image whose resolve pass's ray queue (4 bytes per pixel) exceeds the driver's largest
// storage block is refused with the sizes before any target is made, not drawn wrong; the
// renderer goes on drawing smaller images.
TEST_F(GpuRendererTest, RefusesAnImageWhoseRayQueueExceedsTheLargestStorageBlock) {
  const LightField lf = randomLightField(makeCornellBox(), 41);
  GpuRenderer gpu(lf);
  const uint64_t most = gpu.maxImagePixels();
  ASSERT_GT(most, uint64_t(1920) * 1080);
  const int side = int(std::ceil(std::sqrt(double(most) + 1.0)));
  if (side > 16384) GTEST_SKIP() << "this driver's largest storage block holds the queue of any image size";
  const CameraDesc desc = firstCamera(lf.scene);
  Image image;
  try {
    gpu.render(Camera(desc, side, side), RenderSettings{}, image);
    ADD_FAILURE() << side << "x" << side << " was drawn";
  } catch (const Error& e) {
    const std::string message = e.what();
    const std::string size = std::to_string(side) + "x" + std::to_string(side);
    EXPECT_NE(message.find("a " + size + " image's queue of rays to cast takes"), std::string::npos)
        << message;
    EXPECT_NE(message.find("GL_MAX_SHADER_STORAGE_BLOCK_SIZE"), std::string::npos) << message;
    EXPECT_NE(message.find("--renderer cpu"), std::string::npos) << message;
  }
  EXPECT_EQ(image.width, 0);  // nothing drawn
  gpu.render(Camera(desc, 32, 24), RenderSettings{}, image);
  EXPECT_EQ(image.width, 32);
}

// A light field that does not fit the GPU memory (here: PLENOPTIC_GPU_MEMORY set below it) is
// refused before anything is uploaded, with the sizes and --renderer cpu suggested; a
// malformed limit is an error naming it.
TEST_F(GpuRendererTest, RefusesALightFieldThatDoesNotFitItsMemory) {
  const LightField lf = randomLightField(makeCornellBox(), 40);
  {
    const ScopedEnvironment limit("PLENOPTIC_GPU_MEMORY", "64K");
    try {
      GpuRenderer gpu(lf);
      ADD_FAILURE() << "a light field larger than 64 KiB was accepted";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("needs "), std::string::npos) << message;
      EXPECT_NE(message.find("values "), std::string::npos) << message;  // the largest part, by name
      EXPECT_NE(message.find("but 64 KiB is available (PLENOPTIC_GPU_MEMORY=64K)"), std::string::npos) << message;
      EXPECT_NE(message.find("--renderer cpu"), std::string::npos) << message;
    }
  }
  {
    const ScopedEnvironment limit("PLENOPTIC_GPU_MEMORY", "lots");
    try {
      GpuRenderer gpu(lf);
      ADD_FAILURE() << "a malformed limit was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("PLENOPTIC_GPU_MEMORY=lots: expected a number of bytes"), std::string::npos)
          << e.what();
    }
  }
  const ScopedEnvironment limit("PLENOPTIC_GPU_MEMORY", "1G");
  GpuRenderer gpu(lf);
  EXPECT_LT(gpu.gpuBytes(), uint64_t(1) << 30);
}

// `plenoptic render --renderer gpu` end to end: the picture of `--renderer cpu` (a thin lens too), its stats,
// and the refusals (what it does not draw, no OpenGL 4.5 context, --reference with it).
class GpuRenderCliTest : public cli_test::CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    writeLightField(path("box.plf"), randomLightField(loadScene(kMcGuire + "CornellBox-Glossy.obj"), 8));
  }
};

// PLENOPTIC_GPU_SHADER_DUMP=DIR writes each shader as compiled, for a driver bug report.
TEST_F(GpuRenderCliTest, ShaderDumpWritesEachStage) {
  const std::filesystem::path dir = path("shaders");
  std::filesystem::create_directories(dir);
  std::string err;
  ::setenv("PLENOPTIC_GPU_SHADER_DUMP", dir.c_str(), 1);  // the child process inherits it
  const int status = run("render " + path("box.plf") + " -o " + path("dump.exr") + " --width 16 --height 12 --renderer gpu",
                         nullptr, &err);
  ::unsetenv("PLENOPTIC_GPU_SHADER_DUMP");
  ASSERT_EQ(status, 0) << err;
  for (const char* name : {"visibility.vert", "visibility.frag", "resolve.comp", "shading.comp"}) {
    SCOPED_TRACE(name);
    const std::string text = cli_test::readFileText((dir / name).string());
    EXPECT_EQ(text.rfind("#version 450 core\n", 0), 0u);
    EXPECT_NE(text.find("void main()"), std::string::npos);
  }
}

TEST_F(GpuRenderCliTest, RendersTheCpuPicture) {
  std::string err;
  const std::string size = " --width 64 --height 48";
  ASSERT_EQ(run("render " + path("box.plf") + " -o " + path("gpu.exr") + size + " --renderer gpu --stats " + path("gpu.json"),
                nullptr, &err),
            0)
      << err;
  ASSERT_EQ(run("render " + path("box.plf") + " -o " + path("cpu.exr") + size + " --renderer cpu", nullptr, &err), 0) << err;
  const ImageComparison c = compareImages(readImage(path("gpu.exr")), readImage(path("cpu.exr")));
  EXPECT_LE(c.relMseAverage, 1e-4);
  EXPECT_NEAR(c.meanLuminanceRatio, 1.0, 1e-3);
  const auto json = nlohmann::json::parse(cli_test::readFileText(path("gpu.json")));
  EXPECT_EQ(json["renderer"], "gpu");
  EXPECT_NE(std::string(json["device"]).find("OpenGL 4.5"), std::string::npos) << json["device"];
  EXPECT_GT(double(json["primary_ms_median"]), 0.0);  // the rasterisation pass alone
  // The GPU's own time of each frame (timestamp queries) lies inside the frame's wall time.
  EXPECT_GT(double(json["gpu_ms_median"]), 0.0);
  EXPECT_LE(double(json["gpu_ms_min"]), double(json["gpu_ms_median"]));
  EXPECT_LE(double(json["gpu_ms_median"]), double(json["ms_per_frame_median"]));
  // Pass by pass: each pass of a one-sample frame ran and was timed.
  EXPECT_GT(double(json["gpu_visibility_ms_median"]), 0.0);
  EXPECT_GT(double(json["gpu_resolve_ms_median"]), 0.0);
  EXPECT_GT(double(json["gpu_shading_ms_median"]), 0.0);
  // The camera rays cast through the BVH: near the box's corners, where three surfaces or
  // more meet. An edge between two (walls, a block's silhouette) is answered by testing its
  // two triangles, a fan around a vertex by testing its triangles; casting every edge
  // pixel's ray would be 43 % of them here.
  EXPECT_GT(double(json["gpu_bvh_ray_share_median"]), 0.0);
  EXPECT_LT(double(json["gpu_bvh_ray_share_median"]), 0.2);
  // A thin lens casts every one (its rays start off the eye the ids were rasterised from).
  ASSERT_EQ(run("render " + path("box.plf") + " -o " + path("gpu-lens1.exr") + size +
                    " --aperture 0.5 --spp 1 --renderer gpu --stats " + path("gpu-lens1.json"),
                nullptr, &err),
            0)
      << err;
  EXPECT_EQ(double(nlohmann::json::parse(cli_test::readFileText(path("gpu-lens1.json")))["gpu_bvh_ray_share_median"]), 1.0);
  // A thin lens likewise (depth of field: its lens points are the CPU renderer's).
  const std::string lens = size + " --aperture 0.5 --spp 4";
  ASSERT_EQ(run("render " + path("box.plf") + " -o " + path("gpu-lens.exr") + lens + " --renderer gpu", nullptr, &err), 0) << err;
  ASSERT_EQ(run("render " + path("box.plf") + " -o " + path("cpu-lens.exr") + lens + " --renderer cpu", nullptr, &err), 0) << err;
  const ImageComparison l = compareImages(readImage(path("gpu-lens.exr")), readImage(path("cpu-lens.exr")));
  EXPECT_LE(l.relMseAverage, 1e-4);
  EXPECT_NEAR(l.meanLuminanceRatio, 1.0, 1e-3);
}

// A walk-through (--path) frame by frame, on the built-in box.
TEST_F(GpuRenderCliTest, CameraPathFramesAreTheCpuFrames) {
  writeLightField(path("cornell.plf"), randomLightField(makeCornellBox(), 10));
  std::ofstream(path("path.json")) << R"({"fps": 30, "keyframes": [
      {"time": 0, "eye": [278, 273, -800], "target": [278, 273, 0], "fov": 39},
      {"time": 0.1, "eye": [150, 300, -400], "target": [300, 200, 300]}]})";
  // One sample per pixel, and several (multi-sample along a path).
  for (const std::string spp : {"1", "3"}) {
    for (const std::string renderer : {"gpu", "cpu"}) {
      std::string err;
      ASSERT_EQ(run("render " + path("cornell.plf") + " --path " + path("path.json") + " -o " +
                        path(renderer + spp + "/%02d.exr") + " --width 48 --height 36 --spp " + spp + " --renderer " + renderer,
                    nullptr, &err),
                0)
          << err;
    }
    for (const std::string frame : {"00", "01", "02", "03"}) {
      SCOPED_TRACE(spp + " spp, frame " + frame);
      const ImageComparison c = compareImages(readImage(path("gpu" + spp + "/" + frame + ".exr")),
                                              readImage(path("cpu" + spp + "/" + frame + ".exr")));
      EXPECT_LE(c.relMseAverage, 1e-4);
      EXPECT_NEAR(c.meanLuminanceRatio, 1.0, 1e-3);
    }
  }
}

TEST_F(GpuRenderCliTest, RefusesWhatItDoesNotDrawAndWritesNothing) {
  Scene sky = test_support::mirrorLikeCornellBox();
  sky.environment.map = std::make_shared<const EnvironmentMap>(test_support::skyWithSun(30.0f));
  writeLightField(path("mirror.plf"), randomLightField(std::move(sky), 9));
  std::string err;
  EXPECT_NE(run("render " + path("mirror.plf") + " -o " + path("m.exr") + " --renderer gpu", nullptr, &err), 0);
  EXPECT_NE(err.find("environment maps lighting mirror-like lobes"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(path("m.exr")));
  EXPECT_NE(run("render " + path("box.plf") + " -o " + path("r.exr") + " --renderer gpu --reference", nullptr, &err), 0);
  EXPECT_NE(err.find("--reference and --renderer gpu"), std::string::npos) << err;
  EXPECT_NE(run("render " + path("box.plf") + " -o " + path("r.exr") + " --renderer vulkan", nullptr, &err), 0);
  // A light field larger than the GPU memory.
  EXPECT_NE(cli_test::runPlenoptic("render " + path("box.plf") + " -o " + path("r.exr") + " --renderer gpu --quiet", dir_,
                                   nullptr, &err, "PLENOPTIC_GPU_MEMORY=100K"),
            0);
  EXPECT_NE(err.find("--renderer cpu"), std::string::npos) << err;
  EXPECT_NE(err.find("100 KiB is available"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(path("r.exr")));
}

// A driver that offers less than OpenGL 4.5 (Mesa told to report 3.3), and no EGL at all: a
// clear error naming the EGL error, a non-zero exit, no image.
TEST_F(GpuRenderCliTest, NoOpenGl45ContextIsAClearError) {
  std::string err;
  EXPECT_NE(cli_test::runPlenoptic("render " + path("box.plf") + " -o " + path("n.exr") + " --renderer gpu --quiet", dir_,
                                   nullptr, &err, "MESA_GL_VERSION_OVERRIDE=3.3"),
            0);
  EXPECT_NE(err.find("no OpenGL 4.5 core context"), std::string::npos) << err;
  EXPECT_NE(err.find("EGL_BAD_MATCH"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(path("n.exr")));
  // No EGL implementation at all (the vendor-neutral libEGL finds no vendor): no platform
  // extension, no display — the same clear error, no abort.
  EXPECT_EQ(cli_test::runPlenoptic("render " + path("box.plf") + " -o " + path("n.exr") + " --renderer gpu --quiet", dir_,
                                   nullptr, &err, "__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json"),
            1);
  EXPECT_NE(err.find("no OpenGL 4.5 core context"), std::string::npos) << err;
  EXPECT_NE(err.find("EGL_MESA_platform_surfaceless not offered"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(path("n.exr")));
}

}  // namespace
}  // namespace pl
