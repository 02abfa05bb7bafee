#pragma once
// Test support (header-only; include as "support/sphere_mesh.h"): a closed triangulated sphere
// for scenes built in code (glass furnaces of the path tracer and the light field).
#include <utility>

#include "core/math.h"
#include "scene/scene.h"

namespace pl::test_support {

/// A closed latitude-longitude sphere (flat triangles, no vertex normals) wound outwards, so
/// its front side is its outside.
inline void addSphere(Mesh& mesh, const Vec3& centre, float radius, int rings, int segments, uint32_t material) {
  auto point = [&](int i, int j) {
    const float theta = kPi * float(i) / float(rings), phi = kTwoPi * float(j % segments) / float(segments);
    return centre + radius * Vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
  };
  auto triangle = [&](Vec3 a, Vec3 b, Vec3 c) {
    if (glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0f - centre) < 0.0f) std::swap(b, c);
    const auto base = static_cast<uint32_t>(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), {a, b, c});
    mesh.triangles.push_back(UVec3(base, base + 1, base + 2));
    mesh.materials.push_back(material);
  };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      if (i > 0) triangle(point(i, j), point(i, j + 1), point(i + 1, j));
      if (i + 1 < rings) triangle(point(i, j + 1), point(i + 1, j + 1), point(i + 1, j));
    }
}

}  // namespace pl::test_support
