#pragma once
// Test support (header-only; include as "support/box_mesh.h"): an axis-aligned box for scenes
// built in code (solid glass and subsurface objects of the path tracer's tests).
#include <utility>

#include "core/math.h"
#include "scene/scene.h"

namespace pl::test_support {

/// The box [lo, hi] as 12 triangles (four vertices per face) wound outwards, so its front side
/// is its outside.
inline void addBox(Mesh& mesh, const Vec3& lo, const Vec3& hi, uint32_t material) {
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      Vec3 c[4];
      const int cu[4] = {0, 1, 1, 0}, cv[4] = {0, 0, 1, 1};
      for (int k = 0; k < 4; ++k) {
        c[k][axis] = side ? hi[axis] : lo[axis];
        c[k][u] = cu[k] ? hi[u] : lo[u];
        c[k][v] = cv[k] ? hi[v] : lo[v];
      }
      Vec3 outward(0.0f);
      outward[axis] = side ? 1.0f : -1.0f;
      if (glm::dot(glm::cross(c[1] - c[0], c[2] - c[0]), outward) < 0.0f) std::swap(c[1], c[3]);
      const auto base = static_cast<uint32_t>(mesh.positions.size());
      mesh.positions.insert(mesh.positions.end(), {c[0], c[1], c[2], c[3]});
      mesh.triangles.push_back(UVec3(base, base + 1, base + 2));
      mesh.triangles.push_back(UVec3(base, base + 2, base + 3));
      mesh.materials.insert(mesh.materials.end(), {material, material});
    }
}

}  // namespace pl::test_support
