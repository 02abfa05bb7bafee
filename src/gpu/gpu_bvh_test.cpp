// The GPU BVH (gpu_bvh.h) on the CPU: its structure, and its traversal against brute force
// (the same triangle test over every triangle) and against Embree on a scene.
#include "gpu/gpu_bvh.h"

#include <gtest/gtest.h>

#include <cmath>

#include "accel/accel.h"
#include "core/rng.h"
#include "scene/scene.h"

namespace pl {
namespace {

Vec3 randomPoint(Pcg32& rng, float scale) { return scale * Vec3(rng.uniform(), rng.uniform(), rng.uniform()); }

/// A soup of n small random triangles in the unit cube.
void randomSoup(uint32_t n, Pcg32& rng, std::vector<Vec3>& positions, std::vector<UVec3>& triangles) {
  for (uint32_t i = 0; i < n; ++i) {
    const Vec3 centre = randomPoint(rng, 1.0f);
    for (int k = 0; k < 3; ++k) positions.push_back(centre + randomPoint(rng, 0.1f) - Vec3(0.05f));
    triangles.push_back(UVec3(3 * i, 3 * i + 1, 3 * i + 2));
  }
}

/// The closest hit over every triangle with the traversal's own triangle test (a one-leaf BVH).
BvhHit bruteForce(const std::vector<Vec3>& positions, const std::vector<UVec3>& triangles, const Ray& ray) {
  GpuBvh flat;
  flat.nodes.push_back(BvhNode{{-1e30f, -1e30f, -1e30f}, 0, {1e30f, 1e30f, 1e30f}, uint32_t(triangles.size())});
  std::vector<uint32_t> order(triangles.size());
  for (uint32_t t = 0; t < triangles.size(); ++t) order[t] = t;
  flat.triangles = leafOrderTriangles(order, positions, triangles);
  return intersectGpuBvh(flat, ray);
}

/// Every node's box holds its children's or its triangles; every triangle is in one leaf; the
/// depth stays within the traversal's stack.
void expectWellFormed(const GpuBvh& bvh, const std::vector<Vec3>& positions, const std::vector<UVec3>& triangles) {
  std::vector<int> seen(triangles.size(), 0);
  struct Item {
    uint32_t node;
    int depth;
  };
  std::vector<Item> stack{{0, 0}};
  int maxDepth = 0;
  auto inside = [](const BvhNode& outer, const Vec3& p) {
    for (int k = 0; k < 3; ++k)
      if (p[k] < outer.lower[k] || p[k] > outer.upper[k]) return false;
    return true;
  };
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    maxDepth = std::max(maxDepth, item.depth);
    const BvhNode& node = bvh.nodes[item.node];
    if (node.count == 0) {
      ASSERT_LT(node.first + 1, bvh.nodes.size());
      for (uint32_t c = node.first; c < node.first + 2; ++c) {
        const BvhNode& child = bvh.nodes[c];
        if (child.lower[0] > child.upper[0]) continue;  // empty
        EXPECT_TRUE(inside(node, Vec3(child.lower[0], child.lower[1], child.lower[2])));
        EXPECT_TRUE(inside(node, Vec3(child.upper[0], child.upper[1], child.upper[2])));
        stack.push_back({c, item.depth + 1});
      }
      continue;
    }
    for (uint32_t i = node.first; i < node.first + node.count; ++i) {
      // The leaf-order record: its triangle's first vertex and edges.
      const BvhTriangle& record = bvh.triangles[i];
      const uint32_t t = record.triangle;
      ASSERT_LT(t, triangles.size());
      ++seen[t];
      const Vec3 p0 = positions[triangles[t][0]], e1 = positions[triangles[t][1]] - p0, e2 = positions[triangles[t][2]] - p0;
      if (isFinite(p0) && isFinite(e1) && isFinite(e2))  // (NaN compares unequal to itself)
        for (int k = 0; k < 3; ++k) {
          EXPECT_EQ(record.p0[k], p0[k]);
          EXPECT_EQ(record.e1[k], e1[k]);
          EXPECT_EQ(record.e2[k], e2[k]);
        }
      const Vec3 p[3] = {positions[triangles[t][0]], positions[triangles[t][1]], positions[triangles[t][2]]};
      if (!isFinite(p[0]) || !isFinite(p[1]) || !isFinite(p[2])) continue;  // in no box
      for (const Vec3& v : p) EXPECT_TRUE(inside(node, v));
    }
  }
  for (size_t t = 0; t < seen.size(); ++t) EXPECT_EQ(seen[t], 1) << "triangle " << t;
  EXPECT_LT(maxDepth, 60);
}

TEST(GpuBvh, RandomSoupMatchesBruteForce) {
  Pcg32 rng(7, 1);
  std::vector<Vec3> positions;
  std::vector<UVec3> triangles;
  randomSoup(2000, rng, positions, triangles);
  const GpuBvh bvh = buildGpuBvh(positions, triangles);
  expectWellFormed(bvh, positions, triangles);
  EXPECT_GT(bvh.nodes.size(), 2000u / kBvhLeafTriangles);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    Ray ray;
    ray.origin = randomPoint(rng, 3.0f) - Vec3(1.0f);
    ray.direction = glm::normalize(randomPoint(rng, 2.0f) - Vec3(1.0f));
    if (i % 4 == 0) ray.tMax = 0.5f;   // a bounded segment
    if (i % 7 == 0) ray.tMin = 0.2f;
    const BvhHit expected = bruteForce(positions, triangles, ray), hit = intersectGpuBvh(bvh, ray);
    ASSERT_EQ(hit.t, expected.t) << "ray " << i;
    if (hit.triangle != expected.triangle) continue;  // a tie at equal t (shared edge): either
    EXPECT_EQ(hit.barycentrics, expected.barycentrics);
    hits += expected.triangle != 0xffffffffu;
  }
  EXPECT_GT(hits, 50);
}

TEST(GpuBvh, AxisAlignedRaysAndDegenerateInput) {
  // Axis-aligned directions (zero components) through a grid of quads, and a degenerate
  // (zero-area) and a non-finite triangle, which are never hit.
  std::vector<Vec3> positions;
  std::vector<UVec3> triangles;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const uint32_t v = uint32_t(positions.size());
      const float z = float(i + j) * 0.1f;
      positions.insert(positions.end(), {Vec3(i, j, z), Vec3(i + 1, j, z), Vec3(i + 1, j + 1, z), Vec3(i, j + 1, z)});
      triangles.insert(triangles.end(), {UVec3(v, v + 1, v + 2), UVec3(v, v + 2, v + 3)});
    }
  const uint32_t v = uint32_t(positions.size());
  positions.insert(positions.end(), {Vec3(5.5f, 5.5f, 10.0f), Vec3(5.5f, 5.5f, 10.0f), Vec3(5.5f, 5.5f, 10.0f),
                                     Vec3(std::nanf(""), 0.0f, 0.0f)});
  triangles.insert(triangles.end(), {UVec3(v, v + 1, v + 2), UVec3(v + 3, v, v + 1)});
  const GpuBvh bvh = buildGpuBvh(positions, triangles);
  expectWellFormed(bvh, positions, triangles);
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const Ray down{Vec3(i + 0.25f, j + 0.5f, 20.0f), Vec3(0.0f, 0.0f, -1.0f)};
      const BvhHit hit = intersectGpuBvh(bvh, down);
      ASSERT_NE(hit.triangle, 0xffffffffu);
      EXPECT_EQ(hit.triangle / 2, uint32_t(i * 10 + j));
      EXPECT_NEAR(hit.t, 20.0f - float(i + j) * 0.1f, 1e-5f);
    }
  const Ray sideways{Vec3(-1.0f, 0.5f, 0.0f), Vec3(1.0f, 0.0f, 0.0f)};  // in the plane of the first quad's row
  EXPECT_EQ(intersectGpuBvh(bvh, sideways).t, bruteForce(positions, triangles, sideways).t);
  // An empty scene: one empty leaf, nothing hit.
  const GpuBvh empty = buildGpuBvh({}, {});
  ASSERT_EQ(empty.nodes.size(), 1u);
  EXPECT_EQ(intersectGpuBvh(empty, sideways).triangle, 0xffffffffu);
}

TEST(GpuBvh, CornellBoxMatchesEmbree) {
  const Scene scene = makeCornellBox();
  const Accel accel(scene);
  std::vector<Vec3> positions;
  std::vector<UVec3> triangles;
  std::vector<std::pair<uint32_t, uint32_t>> meshTriangle;
  flattenSceneTriangles(scene, positions, triangles, &meshTriangle);
  const GpuBvh bvh = buildGpuBvh(positions, triangles);
  expectWellFormed(bvh, positions, triangles);
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  Pcg32 rng(3, 1);
  int same = 0, hits = 0, rays = 4000;
  for (int i = 0; i < rays; ++i) {
    Ray ray;
    ray.origin = lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * (hi - lo);
    ray.direction = glm::normalize(randomPoint(rng, 2.0f) - Vec3(1.0f));
    RayHit expected;
    accel.intersect(ray, expected);
    const BvhHit hit = intersectGpuBvh(bvh, ray);
    ASSERT_EQ(hit.triangle != 0xffffffffu, expected.hit()) << "ray " << i;
    if (!expected.hit()) continue;
    EXPECT_NEAR(hit.t, expected.t, 1e-4f * std::max(1.0f, expected.t)) << "ray " << i;
    same += meshTriangle[hit.triangle] == std::make_pair(expected.mesh, expected.triangle);
    ++hits;
  }
  // A different triangle only at a shared edge or a tie between coplanar triangles.
  EXPECT_GT(hits, rays / 2);
  EXPECT_GE(same, hits - 4);
}

}  // namespace
}  // namespace pl
