#pragma once
// Test support (header-only; include as "support/relight_scenes.h"): the small scenes and bake
// settings with which relighting and the warm-started re-bake are compared to fresh bakes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bake/bake.h"
#include "light/lights.h"
#include "scene/scene.h"
#include "support/quad_mesh.h"

namespace pl::test_support {

/// The draft preset made small (tixelsAcross tixels across the room scale, 64 gather
/// directions) and converged tightly (tolerance 1e-4), so that fields compare at 5× it.
inline BakeSettings relightTestSettings(float tixelsAcross = 10.0f) {
  BakeSettings s = bakePreset("draft");
  s.tixelsAcrossScene = tixelsAcross;
  s.gatherDirections = 64;
  s.areaLightSamples = 8;
  s.tolerance = 1e-4f;
  s.maxIterations = 400;
  return s;
}

/// The index of the material named `name` (a test failure and 0 when there is none).
inline uint32_t materialIndex(const Scene& scene, const std::string& name) {
  for (uint32_t m = 0; m < scene.materials.size(); ++m)
    if (scene.materials[m].name == name) return m;
  ADD_FAILURE() << "no material " << name;
  return 0;
}

/// The built-in Cornell box with a point light beside its area light.
inline Scene cornellWithPointLight() {
  Scene scene = makeCornellBox();
  scene.lights.push_back(createLight("point", {{"position", Vec3(278.0f, 400.0f, 200.0f)}, {"intensity", Vec3(2e4f)}},
                                     "test light"));
  scene.finalize();
  return scene;
}

/// An open scene under a grey sky: a floor, a wall standing on it and a sun.
inline Scene sunScene(const Vec3& sunDirection) {
  Scene scene;
  scene.sourcePath = "sun test";
  Material ground;
  ground.name = "ground";
  ground.bsdf = LambertBsdf{Rgb(0.6f)};
  scene.materials.push_back(ground);
  Mesh mesh;
  addQuad(mesh, Vec3(0, 0, 0), Vec3(0, 0, 10), Vec3(10, 0, 10), Vec3(10, 0, 0), 0);
  addQuad(mesh, Vec3(3, 0, 5), Vec3(7, 0, 5), Vec3(7, 3, 5), Vec3(3, 3, 5), 0);
  scene.meshes.push_back(std::move(mesh));
  scene.environment.constant = Rgb(0.2f, 0.3f, 0.5f);
  scene.lights.push_back(createLight("directional", {{"direction", sunDirection}, {"irradiance", Vec3(3.0f)}}, "sun"));
  scene.finalize();
  return scene;
}

/// The direction of travel of sunlight from elevation and azimuth (degrees).
inline Vec3 sunAt(float elevationDegrees, float azimuthDegrees) {
  const float e = elevationDegrees * kPi / 180.0f, a = azimuthDegrees * kPi / 180.0f;
  return -Vec3(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
}

}  // namespace pl::test_support
