// The GPU renderer's BVH (gpu_bvh.h): the binned-SAH build, its CPU traversal and the GLSL one.
#include "gpu/gpu_bvh.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "scene/scene.h"

namespace pl {
namespace {

struct Box {
  Vec3 lower{std::numeric_limits<float>::max()}, upper{-std::numeric_limits<float>::max()};
  void grow(const Vec3& p) {
    lower = glm::min(lower, p);
    upper = glm::max(upper, p);
  }
  void grow(const Box& b) {
    lower = glm::min(lower, b.lower);
    upper = glm::max(upper, b.upper);
  }
  bool empty() const { return !(lower.x <= upper.x); }
  /// Half the surface area (the SAH's ratios need no factor 2); 0 when empty.
  float halfArea() const {
    if (empty()) return 0.0f;
    const Vec3 e = upper - lower;
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
};

constexpr int kBins = 16;
/// Deeper nodes become leaves, however many triangles they hold: the traversal's stack of 64
/// then never overflows (it holds at most one node per level besides the current one).
constexpr int kMaxBvhDepth = 48;

struct Builder {
  const std::vector<Vec3>& positions;
  const std::vector<UVec3>& triangles;
  std::vector<Box> bounds;     ///< per triangle (finite vertices only)
  std::vector<Vec3> centroid;  ///< per triangle
  std::vector<uint32_t> order;  ///< triangle indices, leaf by leaf once built
  GpuBvh bvh;

  /// Makes node `index` over order[first, first + count), recursing into its children.
  void build(uint32_t index, uint32_t first, uint32_t count, int depth) {
    Box box, centroids;
    for (uint32_t i = first; i < first + count; ++i) {
      box.grow(bounds[order[i]]);
      centroids.grow(centroid[order[i]]);
    }
    BvhNode& node = bvh.nodes[index];
    for (int k = 0; k < 3; ++k) {
      node.lower[k] = box.empty() ? 0.0f : box.lower[k];
      node.upper[k] = box.empty() ? -1.0f : box.upper[k];  // an empty box no slab test enters
    }
    node.first = first;
    node.count = count;
    if (count <= kBvhLeafTriangles || centroids.empty() || depth >= kMaxBvhDepth) return;
    const Vec3 extent = centroids.upper - centroids.lower;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    if (!(extent[axis] > 0.0f)) return;  // all centroids at one point: no split separates them
    // Bin the centroids along the axis; the SAH cost of each of the kBins − 1 planes.
    const float scale = float(kBins) / extent[axis];
    auto binOf = [&](uint32_t t) {
      return std::clamp(int((centroid[t][axis] - centroids.lower[axis]) * scale), 0, kBins - 1);
    };
    std::array<Box, kBins> binBox;
    std::array<uint32_t, kBins> binCount{};
    for (uint32_t i = first; i < first + count; ++i) {
      const int b = binOf(order[i]);
      binBox[b].grow(bounds[order[i]]);
      ++binCount[b];
    }
    std::array<float, kBins> leftCost{};
    Box left;
    uint32_t leftCount = 0;
    for (int b = 0; b < kBins - 1; ++b) {
      left.grow(binBox[b]);
      leftCount += binCount[b];
      leftCost[b] = left.halfArea() * float(leftCount);
    }
    Box right;
    uint32_t rightCount = 0;
    float bestCost = std::numeric_limits<float>::infinity();
    int bestPlane = -1;
    for (int b = kBins - 1; b > 0; --b) {
      right.grow(binBox[b]);
      rightCount += binCount[b];
      const float cost = leftCost[b - 1] + right.halfArea() * float(rightCount);
      if (rightCount < count && rightCount > 0 && cost < bestCost) {
        bestCost = cost;
        bestPlane = b;  // bins [0, b) left, [b, kBins) right
      }
    }
    // Cost relative to the node's area: 1 (traversal) + children's expected intersections,
    // against the leaf's `count` intersections.
    const float area = box.halfArea();
    if (bestPlane < 0 || (area > 0.0f && 1.0f + bestCost / area >= float(count) && count <= 2 * kBvhLeafTriangles)) return;
    const auto middle = std::partition(order.begin() + first, order.begin() + first + count,
                                       [&](uint32_t t) { return binOf(t) < bestPlane; });
    const uint32_t leftSize = uint32_t(middle - (order.begin() + first));
    const uint32_t children = uint32_t(bvh.nodes.size());
    bvh.nodes.resize(bvh.nodes.size() + 2);
    bvh.nodes[index].first = children;  // (`node` may dangle after the resize)
    bvh.nodes[index].count = 0;
    build(children, first, leftSize, depth + 1);
    build(children + 1, first + leftSize, count - leftSize, depth + 1);
  }
};

/// The slab test of kBvhGlsl: the entry distance of the ray into node's box within
/// (tMin, tMax), or +∞ when it misses.
float enterNode(const BvhNode& node, const Vec3& origin, const Vec3& inverseDirection, float tMin, float tMax) {
  float enter = tMin, leave = tMax;
  for (int k = 0; k < 3; ++k) {
    const float a = (node.lower[k] - origin[k]) * inverseDirection[k], b = (node.upper[k] - origin[k]) * inverseDirection[k];
    enter = std::max(enter, std::min(a, b));
    leave = std::min(leave, std::max(a, b));
  }
  return enter <= leave ? enter : kInfinity;
}

}  // namespace

void flattenSceneTriangles(const Scene& scene, std::vector<Vec3>& positions, std::vector<UVec3>& triangles,
                           std::vector<std::pair<uint32_t, uint32_t>>* meshTriangle) {
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    const uint32_t first = uint32_t(positions.size());
    positions.insert(positions.end(), mesh.positions.begin(), mesh.positions.end());
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      triangles.push_back(mesh.triangles[t] + UVec3(first));
      if (meshTriangle != nullptr) meshTriangle->emplace_back(m, t);
    }
  }
}

GpuBvh buildGpuBvh(const std::vector<Vec3>& positions, const std::vector<UVec3>& triangles) {
  Builder builder{positions, triangles, {}, {}, {}, {}};
  const uint32_t n = uint32_t(triangles.size());
  builder.bounds.resize(n);
  builder.centroid.resize(n);
  for (uint32_t t = 0; t < n; ++t) {
    Box& b = builder.bounds[t];
    bool finite = true;
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = positions[triangles[t][k]];
      finite = finite && isFinite(p);
      b.grow(p);
    }
    if (!finite) b = Box{};  // never hit; kept out of the boxes
    builder.centroid[t] = b.empty() ? Vec3(0.0f) : 0.5f * (b.lower + b.upper);
    builder.order.push_back(t);
  }
  builder.bvh.nodes.reserve(size_t(2) * n / kBvhLeafTriangles + 1);
  builder.bvh.nodes.resize(1);
  builder.build(0, 0, n, 0);
  builder.bvh.triangles = leafOrderTriangles(builder.order, positions, triangles);
  return std::move(builder.bvh);
}

std::vector<BvhTriangle> leafOrderTriangles(const std::vector<uint32_t>& order, const std::vector<Vec3>& positions,
                                            const std::vector<UVec3>& triangles) {
  std::vector<BvhTriangle> records(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    const UVec3& v = triangles[order[i]];
    const Vec3 p0 = positions[v[0]], e1 = positions[v[1]] - p0, e2 = positions[v[2]] - p0;
    BvhTriangle& record = records[i];
    for (int k = 0; k < 3; ++k) {
      record.p0[k] = p0[k];
      record.e1[k] = e1[k];
      record.e2[k] = e2[k];
    }
    record.e1[3] = record.e2[3] = 0.0f;
    record.triangle = order[i];
  }
  return records;
}

BvhHit intersectGpuBvh(const GpuBvh& bvh, const Ray& ray) {
  // kBvhGlsl's bvhIntersect, statement for statement.
  BvhHit hit;
  hit.t = ray.tMax;
  Vec3 inverse;
  for (int k = 0; k < 3; ++k)
    inverse[k] = 1.0f / (std::abs(ray.direction[k]) > 1e-20f ? ray.direction[k] : (ray.direction[k] >= 0.0f ? 1e-20f : -1e-20f));
  // Each node with its entry distance: popped, it is skipped when a hit since lies nearer.
  uint32_t stack[64];
  float stackEnter[64];
  int top = 0;
  const float rootEnter = enterNode(bvh.nodes[0], ray.origin, inverse, ray.tMin, hit.t);
  if (rootEnter < kInfinity) {
    stack[0] = 0;
    stackEnter[0] = rootEnter;
    top = 1;
  }
  while (top > 0) {
    --top;
    if (!(stackEnter[top] <= hit.t)) continue;
    const BvhNode& node = bvh.nodes[stack[top]];
    if (node.count == 0) {
      const float a = enterNode(bvh.nodes[node.first], ray.origin, inverse, ray.tMin, hit.t);
      const float b = enterNode(bvh.nodes[node.first + 1], ray.origin, inverse, ray.tMin, hit.t);
      // The nearer child on top; a missed child not pushed.
      const uint32_t nearer = a <= b ? node.first : node.first + 1, farther = a <= b ? node.first + 1 : node.first;
      if (std::max(a, b) < kInfinity && top < 64) {
        stack[top] = farther;
        stackEnter[top++] = std::max(a, b);
      }
      if (std::min(a, b) < kInfinity && top < 64) {
        stack[top] = nearer;
        stackEnter[top++] = std::min(a, b);
      }
      continue;
    }
    for (uint32_t i = node.first; i < node.first + node.count; ++i) {
      const BvhTriangle& record = bvh.triangles[i];
      const Vec3 p0(record.p0[0], record.p0[1], record.p0[2]), e1(record.e1[0], record.e1[1], record.e1[2]),
          e2(record.e2[0], record.e2[1], record.e2[2]);
      const Vec3 q = glm::cross(ray.direction, e2);
      const float det = glm::dot(e1, q);
      if (det == 0.0f) continue;
      const Vec3 s = ray.origin - p0;
      const float u = glm::dot(s, q) / det;
      const Vec3 r = glm::cross(s, e1);
      const float v = glm::dot(ray.direction, r) / det;
      const float distance = glm::dot(e2, r) / det;
      if (u >= 0.0f && v >= 0.0f && u + v <= 1.0f && distance > ray.tMin && distance < hit.t) {
        hit.t = distance;
        hit.triangle = record.triangle;
        hit.barycentrics = Vec2(u, v);
      }
    }
  }
  if (hit.triangle == 0xffffffffu) hit.t = kInfinity;
  return hit;
}

std::string bvhGlslConstants() {
  return fmt::format("#define BVH_NODES_BINDING {}\n#define BVH_TRIANGLES_BINDING {}\n", kBvhNodesBinding, kBvhTrianglesBinding);
}

const char* const kBvhGlsl = R"glsl(
struct BvhNode { vec4 lower; vec4 upper; };  // lower.w: first (uint bits), upper.w: count
layout(std430, binding = BVH_NODES_BINDING) readonly buffer BvhNodes { BvhNode bvhNodes[]; };
// BvhTriangle: p0 (w: the triangle's index, as uint bits), e1, e2.
struct BvhTriangleRecord { vec4 p0; vec4 e1; vec4 e2; };
layout(std430, binding = BVH_TRIANGLES_BINDING) readonly buffer BvhTriangles { BvhTriangleRecord bvhTriangles[]; };
const float kNoEntry = 1.0 / 0.0;
// The slab test: entry distance into node's box within (tMin, tMax), +inf on a miss.
float bvhEnter(uint node, vec3 origin, vec3 inverseDirection, float tMin, float tMax) {
  vec3 a = (bvhNodes[node].lower.xyz - origin) * inverseDirection;
  vec3 b = (bvhNodes[node].upper.xyz - origin) * inverseDirection;
  vec3 near = min(a, b), far = max(a, b);
  float enter = max(tMin, max(near.x, max(near.y, near.z)));
  float leave = min(tMax, min(far.x, min(far.y, far.z)));
  return enter <= leave ? enter : kNoEntry;
}
vec3 bvhInverse(vec3 d) {
  // A zero component: ±1e20 instead of ±inf (0·inf in the slab test would be NaN).
  vec3 tiny = mix(vec3(-1e-20), vec3(1e-20), greaterThanEqual(d, vec3(0.0)));
  return 1.0 / mix(tiny, d, greaterThan(abs(d), vec3(1e-20)));
}
// Möller–Trumbore, edges inclusive, on the triangle with first vertex p0 and edges e1, e2:
// the distance along the ray, +inf on a miss; (u, v) as Embree's.
float mollerTrumbore(vec3 p0, vec3 e1, vec3 e2, vec3 origin, vec3 direction, float tMin, float tMax, out vec2 uv) {
  vec3 q = cross(direction, e2);
  float det = dot(e1, q);
  uv = vec2(0.0);
  if (det == 0.0) return kNoEntry;
  vec3 s = origin - p0;
  float u = dot(s, q) / det;
  vec3 r = cross(s, e1);
  float v = dot(direction, r) / det;
  float t = dot(e2, r) / det;
  uv = vec2(u, v);
  return u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > tMin && t < tMax ? t : kNoEntry;
}
// The same on triangle `triangle` of the triangle array.
float bvhTriangle(uint triangle, vec3 origin, vec3 direction, float tMin, float tMax, out vec2 uv) {
  uvec4 tri = triangles[triangle];
  vec3 p0 = positions[tri.x].xyz;
  return mollerTrumbore(p0, positions[tri.y].xyz - p0, positions[tri.z].xyz - p0, origin, direction, tMin, tMax, uv);
}
// The same on the leaf-order triangle i (BvhTriangles), its index in `triangle`.
float bvhLeafTriangle(uint i, vec3 origin, vec3 direction, float tMin, float tMax, out vec2 uv, out uint triangle) {
  BvhTriangleRecord r = bvhTriangles[i];
  triangle = floatBitsToUint(r.p0.w);
  return mollerTrumbore(r.p0.xyz, r.e1.xyz, r.e2.xyz, origin, direction, tMin, tMax, uv);
}
// The ray caster's alpha-mask hit filter (accel_embree.cpp alphaMaskFilter): a candidate hit
// on an alpha-masked triangle where its coverage is below the cutoff (coverageAt) is no hit and
// traversal goes on past it. With BVH_ALPHA_MASKS the program has the surface detail
// (gpu_surface_detail.h masked, maskedMaterial) and the uniform anyMasked before this chunk.
bool bvhCutAway(uint triangle, vec2 uv) {
#ifdef BVH_ALPHA_MASKS
  return anyMasked && maskedMaterial(triangle) && masked(triangle, triangles[triangle].xyz, uv);
#else
  return false;
#endif
}
// The closest hit in (tMin, tMax): true and its distance, triangle and barycentrics.
bool bvhIntersect(vec3 origin, vec3 direction, float tMin, float tMax, out float t, out uint triangle, out vec2 uv) {
  vec3 inverse = bvhInverse(direction);
  // Each node with its entry distance: popped, it is skipped when a hit since lies nearer.
  uint stack[64];
  float stackEnter[64];
  int top = 0;
  t = tMax;
  triangle = 0xffffffffu;
  uv = vec2(0.0);
  float rootEnter = bvhEnter(0u, origin, inverse, tMin, t);
  if (rootEnter < kNoEntry) {
    stack[0] = 0u;
    stackEnter[0] = rootEnter;
    top = 1;
  }
  while (top > 0) {
    --top;
    if (!(stackEnter[top] <= t)) continue;
    uint node = stack[top];
    uint first = floatBitsToUint(bvhNodes[node].lower.w), count = floatBitsToUint(bvhNodes[node].upper.w);
    if (count == 0u) {
      float a = bvhEnter(first, origin, inverse, tMin, t), b = bvhEnter(first + 1u, origin, inverse, tMin, t);
      uint nearer = a <= b ? first : first + 1u, farther = a <= b ? first + 1u : first;
      if (max(a, b) < kNoEntry && top < 64) {
        stack[top] = farther;
        stackEnter[top++] = max(a, b);
      }
      if (min(a, b) < kNoEntry && top < 64) {
        stack[top] = nearer;
        stackEnter[top++] = min(a, b);
      }
      continue;
    }
    for (uint i = first; i < first + count; ++i) {
      vec2 hitUv;
      uint candidate;
      float hit = bvhLeafTriangle(i, origin, direction, tMin, t, hitUv, candidate);
      if (hit < t && !bvhCutAway(candidate, hitUv)) {
        t = hit;
        triangle = candidate;
        uv = hitUv;
      }
    }
  }
  if (triangle == 0xffffffffu) t = kNoEntry;
  return triangle != 0xffffffffu;
}
// Whether anything blocks the ray in (tMin, tMax).
bool bvhOccluded(vec3 origin, vec3 direction, float tMin, float tMax) {
  vec3 inverse = bvhInverse(direction);
  uint stack[64];
  int top = 0;
  stack[top++] = 0u;
  while (top > 0) {
    uint node = stack[--top];
    if (!(bvhEnter(node, origin, inverse, tMin, tMax) < kNoEntry)) continue;
    uint first = floatBitsToUint(bvhNodes[node].lower.w), count = floatBitsToUint(bvhNodes[node].upper.w);
    if (count == 0u) {
      if (top < 63) {
        stack[top++] = first + 1u;
        stack[top++] = first;
      }
      continue;
    }
    for (uint i = first; i < first + count; ++i) {
      vec2 uv;
      uint candidate;
      if (bvhLeafTriangle(i, origin, direction, tMin, tMax, uv, candidate) < kNoEntry && !bvhCutAway(candidate, uv)) return true;
    }
  }
  return false;
}
)glsl";

}  // namespace pl
