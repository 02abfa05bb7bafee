#pragma once
// Test support (header-only; include as "support/glossy_spheres.h"): McGuire's CornellBox-Sphere
// (tests/data, public domain) with both spheres made glossy through a JSON scene, the same as
// bench/scenes/CornellBox-Sphere-glossy.json: the left one GGX (a coloured metal, roughness
// 0.4 → α 0.16), the right one Blinn-Phong (a grey-blue plastic, exponent 60). For the curved
// glossy charts (bake/parameterisation.h "Curved charts"): the spheres are smooth meshes
// (vertex normals) of 1 088 faces each.
#include <filesystem>
#include <fstream>
#include <string>

#include "scene/scene.h"

namespace pl::test_support {

/// Writes the scene into `dir` (an existing directory) and loads it.
inline Scene loadGlossySpheres(const std::filesystem::path& dir) {
  const std::filesystem::path json = dir / "glossy_spheres.json";
  std::ofstream(json) << R"({"meshes": [{"file": ")" << PLENOPTIC_TEST_DATA_DIR
                      << R"(/cornell-mcguire/CornellBox-Sphere.obj"}], "materials": {)"
                      << R"("leftSphere": {"type": "ggx", "diffuse": 0.05, "f0": [0.9, 0.75, 0.5], "roughness": 0.4},)"
                      << R"("rightSphere": {"type": "blinn-phong", "diffuse": [0.3, 0.35, 0.45], "specular": 0.3, "exponent": 60}}})";
  return loadScene(json.string());
}

}  // namespace pl::test_support
