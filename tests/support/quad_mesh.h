#pragma once
// Test support (header-only; include as "support/quad_mesh.h"): quads for scenes built in code.
#include "core/math.h"
#include "scene/scene.h"

namespace pl::test_support {

/// Appends the quad a-b-c-d as the triangles (a, b, c) and (a, c, d), both of `material`; the
/// winding a → b → c is its front side (counter-clockwise seen from the front).
inline void addQuad(Mesh& mesh, Vec3 a, Vec3 b, Vec3 c, Vec3 d, uint32_t material) {
  const auto base = static_cast<uint32_t>(mesh.positions.size());
  for (const Vec3& p : {a, b, c, d}) mesh.positions.push_back(p);
  mesh.triangles.push_back(UVec3(base, base + 1, base + 2));
  mesh.triangles.push_back(UVec3(base, base + 2, base + 3));
  mesh.materials.push_back(material);
  mesh.materials.push_back(material);
}

}  // namespace pl::test_support
