#pragma once
// The GPU renderer's ray-casting structure: a bounding-volume hierarchy built on the CPU over
// the renderer's triangle array (every mesh's triangles in scene order, global vertex
// indices: GpuRenderer's upload), uploaded as two shader storage buffers (the nodes; the
// triangles in leaf order, each as its first vertex and two edges) and traversed by
// the GLSL functions of kBvhGlsl — the rays of mirror and glass chains and the shadow rays of
// punctual highlights, which rasterisation cannot answer.
//
// Build: binned SAH (16 bins on the centroids along the longest centroid axis; a node
// becomes a leaf at ≤ kBvhLeafTriangles triangles, or when no split is cheaper than the leaf,
// traversal cost 1 against intersection cost 1 per triangle, up to 8 triangles; and at depth
// 48 whatever it holds, so that the traversal's stack cannot overflow). Nodes are in depth-first order,
// the two children of an inner node adjacent.
//
// Traversal (GLSL, kBvhGlsl): a stack of 64 node indices, the nearer child first (by the slab
// test's entry distance), closest hit (bvhIntersect) or any hit (bvhOccluded) in (tMin, tMax).
// The closest-hit stack keeps each node's entry distance beside it: a node popped is skipped
// when a hit found since lies nearer than its entry — the slab test again against the nearer
// hit, without reading the node's box again. A leaf's triangles are read in leaf order, one
// 48-byte record each (no index into the triangle and vertex arrays on the way).
// The triangle test is Möller–Trumbore with inclusive edges (u ≥ 0, v ≥ 0, u + v ≤ 1), so a
// ray through a shared edge hits one of the two triangles (both, the nearer kept), and
// barycentrics (u, v) as Embree reports them. It is not Embree's arithmetic: t and (u, v)
// agree with Embree's to float rounding (a few ulp), not bit for bit. In a program compiled
// with BVH_ALPHA_MASKS (the shading passes of a scene with alpha masks) both cut alpha masks as the ray caster's hit filter
// does: a candidate hit where the coverage is below the cutoff is passed over (bvhCutAway).
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/math.h"

namespace pl {

struct Scene;

inline constexpr uint32_t kBvhLeafTriangles = 4;

/// One node as the shaders read it (std430: two 16-byte rows). Inner node: count == 0 and
/// its children at `first` and `first + 1`. Leaf: triangles order[first … first + count).
struct BvhNode {
  float lower[3];
  uint32_t first;
  float upper[3];
  uint32_t count;
};
static_assert(sizeof(BvhNode) == 32);

/// One triangle as the traversal reads it (std430: three 16-byte rows): its first vertex p0,
/// its edges e1 = p1 − p0 and e2 = p2 − p0 (as Möller–Trumbore computes them: the same float
/// subtractions), and its index in the triangle array.
struct BvhTriangle {
  float p0[3];
  uint32_t triangle;
  float e1[4], e2[4];
};
static_assert(sizeof(BvhTriangle) == 48);

struct GpuBvh {
  std::vector<BvhNode> nodes;          ///< nodes[0] is the root (an empty leaf when there are no triangles)
  std::vector<BvhTriangle> triangles;  ///< the triangles in leaf order (a leaf holds triangles[first, first + count))
};

/// Every mesh's vertices and triangles of `scene` in one array each, in scene order, the
/// triangles' indices into `positions`: the triangle array the GPU renderer draws and builds
/// the BVH over. `meshTriangle`, when given, gets each triangle's (mesh, triangle in the mesh).
void flattenSceneTriangles(const Scene& scene, std::vector<Vec3>& positions, std::vector<UVec3>& triangles,
                           std::vector<std::pair<uint32_t, uint32_t>>* meshTriangle = nullptr);

/// Builds the hierarchy over triangles (p[v[0]], p[v[1]], p[v[2]]) for every v in
/// `triangles`, triangle i of the result being triangles[i]. Degenerate and non-finite
/// triangles are kept (they never report a hit).
GpuBvh buildGpuBvh(const std::vector<Vec3>& positions, const std::vector<UVec3>& triangles);
/// The records of triangles order[0], order[1], … (buildGpuBvh's leaf order) of `triangles`.
std::vector<BvhTriangle> leafOrderTriangles(const std::vector<uint32_t>& order, const std::vector<Vec3>& positions,
                                            const std::vector<UVec3>& triangles);

/// The closest hit of `ray` in (ray.tMin, ray.tMax) by the traversal kBvhGlsl runs, on the
/// CPU (the build's unit test); triangle = kNone (0xffffffff) for a miss.
struct BvhHit {
  float t = kInfinity;
  uint32_t triangle = 0xffffffffu;
  Vec2 barycentrics{0.0f};
};
BvhHit intersectGpuBvh(const GpuBvh& bvh, const Ray& ray);

/// The storage-buffer bindings of the nodes and the leaf-order triangles (above the renderer's own).
inline constexpr uint32_t kBvhNodesBinding = 16, kBvhTrianglesBinding = 17;
/// GLSL #defines of BVH_NODES_BINDING and BVH_TRIANGLES_BINDING (prefixed to kBvhGlsl's programs).
std::string bvhGlslConstants();

/// GLSL: bvhIntersect(origin, direction, tMin, tMax, out t, out triangle, out barycentrics)
/// and bvhOccluded(origin, direction, tMin, tMax), over the storage blocks BvhNodes
/// (binding BVH_NODES_BINDING) and BvhTriangles (BVH_TRIANGLES_BINDING). Needs the shading pass's
/// `positions` (vec4 per vertex) and `triangles` (uvec4: vertex indices, chart) blocks declared
/// before it. Triangle indices are into `triangles`.
extern const char* const kBvhGlsl;

}  // namespace pl
