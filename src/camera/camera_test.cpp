// Camera and exposure against closed forms: sunny 16, exposure scaling per stop, the cos⁴
// law on an analytic uniform-radiance plane, and the thin-lens blur circle.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "camera/camera.h"
#include "camera/exposure.h"
#include "core/error.h"
#include "core/rng.h"

namespace pl {
namespace {

TEST(Exposure, SunnySixteenGivesEv100OfFifteen) {
  // f/16, 1/125 s, ISO 100: EV100 = log2(16² · 125) = log2(32000) = 14.966. The rule's "15"
  // is log2(16² · 128): the nominal 1/125 s stands for 1/128 s, so |EV100 − 15| = log2(128/125).
  const double ev = ev100({16.0f, 1.0f / 125.0f, 100.0f});
  EXPECT_NEAR(ev, std::log2(32000.0), 1e-6);  // float inputs: 1/125 is rounded to ~6e-8 rel
  EXPECT_NEAR(ev, 15.0, std::log2(128.0 / 125.0) + 1e-6);
  // Saturation exposure: 1/(1.2 · 2^EV100) → L_max = 1.2 · 32000 = 38400 cd/m².
  EXPECT_NEAR(1.0 / exposureScale({.photographic = PhotographicExposure{16.0f, 1.0f / 125.0f, 100.0f}}), 38400.0,
              38400.0 * 1e-6);
}

TEST(Exposure, ScalesPerStop) {
  const PhotographicExposure base{8.0f, 1.0f / 60.0f, 200.0f};
  const float h = exposureScale({.photographic = base});
  PhotographicExposure longer = base;
  longer.shutterSeconds *= 2.0f;
  PhotographicExposure faster = base;
  faster.iso *= 2.0f;
  PhotographicExposure stopDown = base;
  stopDown.fNumber *= std::sqrt(2.0f);
  // Ratios are exact up to float rounding of the inputs and the result (1e-6 relative).
  EXPECT_NEAR(exposureScale({.photographic = longer}) / h, 2.0, 2e-6);
  EXPECT_NEAR(exposureScale({.photographic = faster}) / h, 2.0, 2e-6);
  EXPECT_NEAR(exposureScale({.photographic = stopDown}) / h, 0.5, 2e-6);
  // Compensation: 2^EV, alone or on top of the photographic exposure; nothing set → 1.
  EXPECT_EQ(exposureScale({}), 1.0f);
  EXPECT_EQ(exposureScale({.compensationEv = 3.0f}), 8.0f);
  EXPECT_EQ(exposureScale({.compensationEv = -1.0f}), 0.5f);
  EXPECT_NEAR(exposureScale({.compensationEv = 1.0f, .photographic = base}) / h, 2.0, 2e-6);
  EXPECT_THROW(ev100({0.0f, 1.0f, 100.0f}), Error);
  EXPECT_THROW(ev100({2.0f, -1.0f, 100.0f}), Error);
  EXPECT_THROW(ev100({2.0f, 1.0f, std::nanf("")}), Error);
}

CameraDesc lookingDownMinusZ(float fovY) {
  CameraDesc desc;
  desc.name = "test";
  desc.eye = Vec3(0.0f);
  desc.target = Vec3(0.0f, 0.0f, -1.0f);
  desc.up = Vec3(0.0f, 1.0f, 0.0f);
  desc.fovYDegrees = fovY;
  return desc;
}

/// Renders one pixel of an analytic scene: an infinite plane z = −distance facing the camera
/// with uniform radiance L (a Lambertian emitter looks the same from every direction).
/// Averages weight·L over stratified film × lens samples, as a path tracer's box filter does.
float renderUniformPlanePixel(const Camera& camera, int px, int py, float radiance, float distance) {
  const int strata = 6;
  Pcg32 rng{uint64_t(px), uint64_t(py)};
  double sum = 0.0;
  for (int i = 0; i < strata; ++i)
    for (int j = 0; j < strata; ++j) {
      const Vec2 film(float(px) + (float(i) + rng.uniform()) / strata, float(py) + (float(j) + rng.uniform()) / strata);
      const Camera::Sample s = camera.generateRay(film, {rng.uniform(), rng.uniform()});
      const float t = (-distance - s.ray.origin.z) / s.ray.direction.z;
      sum += t > 0.0f ? double(s.weight * radiance) : 0.0;
    }
  return float(sum / (strata * strata));
}

TEST(Camera, UniformPlaneFollowsCosFourthLawWithVignetting) {
  const int width = 81, height = 41;
  const float radiance = 2.5f, fovY = 70.0f;  // horizontal half-angle ≈ 54°: cos⁴ down to ≈ 0.12
  const float tanHalf = std::tan(glm::radians(fovY) / 2.0f), aspect = float(width) / float(height);
  for (float fNumber : {0.0f, 2.0f}) {  // pinhole and thin lens
    CameraDesc desc = lookingDownMinusZ(fovY);
    desc.fNumber = fNumber;
    desc.focusDistance = 3.0f;
    const Camera on(desc, width, height, true), off(desc, width, height, false);
    ASSERT_EQ(on.isThinLens(), fNumber > 0.0f);
    // cos θ of a pixel centre, from the fov geometry alone (camera.h's film mapping).
    auto cosTheta = [&](int px, int py) {
      const float sx = (2.0f * (float(px) + 0.5f) / float(width) - 1.0f) * tanHalf * aspect;
      const float sy = (1.0f - 2.0f * (float(py) + 0.5f) / float(height)) * tanHalf;
      return 1.0f / std::sqrt(1.0f + sx * sx + sy * sy);
    };
    const int cx = width / 2, cy = height / 2;  // the centre pixel, θ = 0 (odd sizes)
    ASSERT_EQ(cosTheta(cx, cy), 1.0f);
    const float centre = renderUniformPlanePixel(on, cx, cy, radiance, 5.0f);
    for (int py : {0, height / 2, height - 1})
      for (int px = 0; px < width; px += 8) {
        const float expected = std::pow(cosTheta(px, py), 4.0f);
        const float ratio = renderUniformPlanePixel(on, px, py, radiance, 5.0f) / centre;
        // 1 %: a pixel averages cos⁴ over its footprint (≈ 1/40 of the field), which differs
        // from cos⁴ at its centre by a second-order term ≲ 1e-3 relative; the rest is float rounding.
        EXPECT_NEAR(ratio, expected, 0.01f * expected) << px << "," << py << " N=" << fNumber;
        // Vignetting off: every pixel records the radiance itself (exactly: weight 1, all rays hit).
        EXPECT_FLOAT_EQ(renderUniformPlanePixel(off, px, py, radiance, 5.0f), radiance);
      }
  }
}

/// The film point from which the ray through lens sample `lens` passes through `world`:
/// for a fixed lens point the ray's hit on the plane at `world`'s depth is an affine function
/// of the film position (camera.h), so three rays from generateRay determine it.
Vec2 filmPointThrough(const Camera& camera, Vec2 lens, const Vec3& world) {
  auto hit = [&](Vec2 film) {
    const Camera::Sample s = camera.generateRay(film, lens);
    const double t = (double(world.z) - s.ray.origin.z) / s.ray.direction.z;
    return glm::dvec2(s.ray.origin.x + t * s.ray.direction.x, s.ray.origin.y + t * s.ray.direction.y);
  };
  const Vec2 f0(float(camera.width()) / 2.0f, float(camera.height()) / 2.0f);
  const float step = 50.0f;
  const glm::dvec2 h0 = hit(f0);
  const glm::dvec2 dx = (hit(f0 + Vec2(step, 0.0f)) - h0) / double(step);
  const glm::dvec2 dy = (hit(f0 + Vec2(0.0f, step)) - h0) / double(step);
  const glm::dvec2 r = glm::dvec2(world.x, world.y) - h0;
  const double det = dx.x * dy.y - dx.y * dy.x;
  return f0 + Vec2(float((r.x * dy.y - r.y * dy.x) / det), float((dx.x * r.y - dx.y * r.x) / det));
}

TEST(Camera, ThinLensFocusesAtTheFocusDistanceAndBlursByTheThinLensLaw) {
  const float focalMm = 50.0f, fNumber = 2.0f, focus = 4.0f;  // metres; scene unit = 1 m
  const int size = 400;
  CameraDesc desc = lookingDownMinusZ(fovForFocalLengthMm(focalMm));
  desc.focalLengthMm = focalMm;
  desc.fNumber = fNumber;
  desc.focusDistance = focus;
  const Camera camera(desc, size, size, false, 1.0f);
  ASSERT_NEAR(camera.apertureRadius(), 0.050f / (2.0f * fNumber), 1e-7f);
  // Lens samples on the aperture's rim (concentric map: u = (1, ½) → (+1, 0), etc.) and inside.
  const std::vector<Vec2> lensSamples = {{0.9999f, 0.5f}, {0.0f, 0.5f}, {0.5f, 0.9999f}, {0.5f, 0.0f}, {0.3f, 0.8f}};

  // In focus: every lens sample sees the point from the same film position (its projection).
  const Vec3 sharp(0.7f, -0.4f, -focus);
  Vec2 projected;
  ASSERT_TRUE(camera.project(sharp, projected));
  for (const Vec2& u : lensSamples) {
    // 2e-3 px: float rounding of positions ~4 m with 24-bit significands, magnified to the film.
    EXPECT_NEAR(glm::distance(filmPointThrough(camera, u, sharp), projected), 0.0f, 2e-3f);
  }

  // Out of focus: the rim samples at ±x trace the blur circle's diameter.
  for (float depth : {1.5f, 2.0f, 8.0f, 30.0f}) {
    const Vec3 point(0.3f, 0.2f, -depth);
    const float measured = glm::distance(filmPointThrough(camera, lensSamples[0], point),
                                         filmPointThrough(camera, lensSamples[1], point));
    // Thin-lens law on the physical sensor (millimetres): aperture A = f/N, lens-to-sensor
    // distance v = f·d_f/(d_f − f), sensor height spanning the fov at this focus h = 2·v·tan(fovY/2),
    // blur circle c = A·|d − d_f|/d · f/(d_f − f); in pixels c/h · size.
    const double f = focalMm, dMm = depth * 1000.0, dfMm = focus * 1000.0;
    const double aperture = f / fNumber, v = f * dfMm / (dfMm - f);
    const double sensor = 2.0 * v * std::tan(glm::radians(double(desc.fovYDegrees)) / 2.0);
    const double c = aperture * std::abs(dMm - dfMm) / dMm * f / (dfMm - f);
    const double expected = c / sensor * size;
    // 1e-3 relative: float rounding in generateRay (the circle is 5–25 px wide).
    EXPECT_NEAR(measured, expected, 1e-3 * expected + 2e-3) << "depth " << depth;
    // The blur circle is centred on the chief-ray projection.
    Vec2 centre;
    ASSERT_TRUE(camera.project(point, centre));
    const Vec2 mid = 0.5f * (filmPointThrough(camera, lensSamples[0], point) + filmPointThrough(camera, lensSamples[1], point));
    EXPECT_NEAR(glm::distance(mid, centre), 0.0f, 2e-3f);
  }
}

TEST(Camera, SceneUnitScalesTheLens) {
  CameraDesc desc = lookingDownMinusZ(40.0f);
  desc.fNumber = 4.0f;
  desc.focusDistance = 2000.0f;  // millimetres
  const Camera mm(desc, 64, 64, false, 0.001f);
  desc.focusDistance = 2.0f;  // metres
  const Camera m(desc, 64, 64, false, 1.0f);
  // Same physical lens: the radius in scene units differs by exactly the unit ratio.
  EXPECT_NEAR(mm.apertureRadius(), 1000.0f * m.apertureRadius(), 1e-3f * mm.apertureRadius());
  EXPECT_NEAR(m.focalLengthMm(), 12.0f / std::tan(glm::radians(20.0f)), 1e-3f);
}

TEST(Camera, PinholeRaysProjectBackToTheirFilmPoint) {
  CameraDesc desc = lookingDownMinusZ(50.0f);
  desc.eye = Vec3(1.0f, 2.0f, 3.0f);
  desc.target = Vec3(-2.0f, 0.5f, -4.0f);
  desc.up = Vec3(0.1f, 1.0f, 0.0f);
  const Camera camera(desc, 320, 200);
  Pcg32 rng(3, 4);
  for (int i = 0; i < 200; ++i) {
    const Vec2 film(rng.uniform() * 320.0f, rng.uniform() * 200.0f);
    const Camera::Sample s = camera.generateRay(film, {0.5f, 0.5f});
    EXPECT_NEAR(glm::length(s.ray.direction), 1.0f, 1e-6f);
    EXPECT_EQ(s.weight, 1.0f);
    Vec2 back;
    ASSERT_TRUE(camera.project(s.ray.origin + 7.0f * s.ray.direction, back));
    EXPECT_NEAR(glm::distance(back, film), 0.0f, 1e-3f);  // float rounding at ~300 px
  }
  // The image centre looks at the target; y = 0 is the top of the image.
  Vec2 centre, above;
  ASSERT_TRUE(camera.project(desc.target, centre));
  EXPECT_NEAR(centre.x, 160.0f, 1e-3f);
  EXPECT_NEAR(centre.y, 100.0f, 1e-3f);
  ASSERT_TRUE(camera.project(desc.target + Vec3(0.0f, 0.5f, 0.0f), above));
  EXPECT_LT(above.y, centre.y);
  Vec2 ignored;
  EXPECT_FALSE(camera.project(desc.eye - (desc.target - desc.eye), ignored));
}

TEST(Camera, ImpossibleSettingsAreRefused) {
  CameraDesc desc = lookingDownMinusZ(40.0f);
  desc.target = desc.eye;
  EXPECT_THROW(Camera(desc, 10, 10), Error);
  desc = lookingDownMinusZ(40.0f);
  desc.up = Vec3(0.0f, 0.0f, 2.0f);
  EXPECT_THROW(Camera(desc, 10, 10), Error);
  desc = lookingDownMinusZ(180.0f);
  EXPECT_THROW(Camera(desc, 10, 10), Error);
  desc = lookingDownMinusZ(40.0f);
  desc.fNumber = 2.0f;
  desc.focusDistance = 0.01f;  // closer than a 33 mm focal length
  EXPECT_THROW(Camera(desc, 10, 10), Error);
  EXPECT_THROW(Camera(lookingDownMinusZ(40.0f), 0, 10), Error);
}

}  // namespace
}  // namespace pl
