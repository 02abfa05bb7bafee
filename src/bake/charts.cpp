// buildCharts (parameterisation.h): the charts of a scene, their frames and grids, in stages —
// weld, adjacency, growth (with the smooth-edge rules of curved charts), open surfaces,
// frames and grids, back sides, tixel layout. The per-tixel work (gather points, coverage,
// albedo, sun masks) is fillTixels, in parameterisation.cpp.
#include "bake/parameterisation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include "core/parallel.h"
#include "light/emitters.h"
#include "lightfield/lookup.h"

namespace pl {
namespace {

struct TriangleInfo {
  uint32_t mesh = 0, triangle = 0, material = 0;
  std::array<uint32_t, 3> welded{};
  Vec3 normal{0.0f};  ///< unit winding normal (zero for a degenerate triangle)
  double area = 0.0;
};

using TriangleList = std::vector<std::pair<uint32_t, uint32_t>>;  ///< (mesh, triangle) pairs

/// Weld: every triangle of the scene, in mesh order, with welded vertex ids — vertices closer
/// than weldEps (positions quantised to weldEps from `lo`) are one vertex for adjacency, so
/// the split normals and uvs of OBJ files still connect.
std::vector<TriangleInfo> weldTriangles(const Scene& scene, const Vec3& lo, float weldEps) {
  std::vector<TriangleInfo> tris;
  tris.reserve(scene.triangleCount());
  std::unordered_map<uint64_t, uint32_t> weld;
  auto weldId = [&](const Vec3& pos) {
    const auto q = [&](float x, float origin) {
      return uint64_t(std::llround(double(x - origin) / double(weldEps))) & 0x1fffff;
    };
    const uint64_t key = q(pos.x, lo.x) | (q(pos.y, lo.y) << 21) | (q(pos.z, lo.z) << 42);
    return weld.try_emplace(key, uint32_t(weld.size())).first->second;
  };
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      TriangleInfo info;
      info.mesh = m;
      info.triangle = t;
      info.material = mesh.materials[t];
      const Vec3 p0 = mesh.positions[mesh.triangles[t][0]], p1 = mesh.positions[mesh.triangles[t][1]],
                 p2 = mesh.positions[mesh.triangles[t][2]];
      const DVec3 cr = glm::cross(DVec3(p1 - p0), DVec3(p2 - p0));
      const double len = glm::length(cr);
      info.area = 0.5 * len;
      info.normal = len > 0.0 ? Vec3(cr / len) : Vec3(0.0f);
      info.welded = {weldId(p0), weldId(p1), weldId(p2)};
      tris.push_back(info);
    }
  }
  return tris;
}

/// Adjacency: every triangle edge as (edge key, triangle), sorted, so that the triangles
/// sharing an edge are one run of equal keys.
struct EdgeAdjacency {
  std::vector<std::pair<uint64_t, uint32_t>> edges;
  std::unordered_map<uint64_t, std::pair<uint32_t, uint32_t>> runs;  ///< key → [begin, end) in edges

  /// The key of the edge between welded ids a and b (either order).
  static uint64_t key(uint32_t a, uint32_t b) { return (uint64_t(std::min(a, b)) << 32) | std::max(a, b); }
  /// Calls f(begin, end) for every run of equal keys [begin, end) of `edges`, in key order.
  template <typename F>
  void forEachRun(F&& f) const {
    for (size_t k = 0; k < edges.size();) {
      size_t e = k;
      while (e < edges.size() && edges[e].first == edges[k].first) ++e;
      f(k, e);
      k = e;
    }
  }
};

EdgeAdjacency edgeAdjacency(const std::vector<TriangleInfo>& tris) {
  EdgeAdjacency adjacency;
  std::vector<std::pair<uint64_t, uint32_t>>& edges = adjacency.edges;
  edges.reserve(tris.size() * 3);
  for (uint32_t g = 0; g < tris.size(); ++g)
    for (int e = 0; e < 3; ++e)
      edges.emplace_back(EdgeAdjacency::key(tris[g].welded[e], tris[g].welded[(e + 1) % 3]), g);
  std::sort(edges.begin(), edges.end());
  adjacency.runs.reserve(edges.size());
  adjacency.forEachRun([&](size_t k, size_t e) { adjacency.runs[edges[k].first] = {uint32_t(k), uint32_t(e)}; });
  return adjacency;
}

/// Per material: whether its charts may grow curved (mayGrowCurvedCharts).
std::vector<uint8_t> curvedMaterials(const Scene& scene, const BakeSettings& settings) {
  std::vector<uint8_t> curved(scene.materials.size(), 0);
  for (size_t m = 0; m < scene.materials.size(); ++m) curved[m] = mayGrowCurvedCharts(scene.materials[m], settings);
  return curved;
}

/// The smooth-edge rules of curved charts (parameterisation.h "Curved charts"): whether the
/// edge (welded ids a, b) between triangles g and h may join a curved chart. At both ends the
/// two triangles' vertex normals agree (a smooth edge); between two triangles of meshes
/// without vertex normals (flat shading), when their faces meet at no more than
/// kFlatShadedChartEdgeDegrees.
class SmoothEdgeRule {
 public:
  SmoothEdgeRule(const Scene& scene, const std::vector<TriangleInfo>& tris) : scene_(scene), tris_(tris) {}

  bool operator()(uint32_t g, uint32_t h, uint32_t a, uint32_t b) const {
    const Mesh& mg = scene_.meshes[tris_[g].mesh];
    const Mesh& mh = scene_.meshes[tris_[h].mesh];
    if (mg.normals.empty() || mh.normals.empty())
      return mg.normals.empty() && mh.normals.empty() && glm::dot(tris_[g].normal, tris_[h].normal) >= cosFlatShaded_;
    for (const uint32_t w : {a, b}) {
      int kg = 0, kh = 0;
      while (kg < 3 && tris_[g].welded[kg] != w) ++kg;
      while (kh < 3 && tris_[h].welded[kh] != w) ++kh;
      if (kg == 3 || kh == 3) return false;
      const Vec3 ng = mg.normals[mg.triangles[tris_[g].triangle][kg]];
      const Vec3 nh = mh.normals[mh.triangles[tris_[h].triangle][kh]];
      // Zero normals (no normal given) never match; unit ones within the tolerance do.
      if (!(glm::dot(ng, nh) >= cosSmooth_)) return false;
    }
    return true;
  }

 private:
  const Scene& scene_;
  const std::vector<TriangleInfo>& tris_;
  const float cosSmooth_ = std::cos(kSmoothEdgeToleranceDegrees * kPi / 180.0f);
  const float cosFlatShaded_ = std::cos(kFlatShadedChartEdgeDegrees * kPi / 180.0f);
};

/// Growth: from each triangle not yet in a chart (in order), a depth-first flood over shared
/// edges to the triangles of the same material that are coplanar with the seed (normal within
/// cosTol, vertices within planeTol of its plane) or, for a material that may curve, join
/// across a smooth edge within kCurvedChartConeDegrees of the seed's normal. A degenerate
/// seed stays alone. Appends each chart's triangles to `chartTriangles`; returns per chart
/// whether it grew across a smooth, non-coplanar edge.
std::vector<uint8_t> growCharts(const Scene& scene, const std::vector<TriangleInfo>& tris,
                                const EdgeAdjacency& adjacency, const std::vector<uint8_t>& curvedMaterial,
                                const SmoothEdgeRule& smoothEdge, float planeTol, float cosTol,
                                std::vector<TriangleList>& chartTriangles) {
  const float cosCone = std::cos(kCurvedChartConeDegrees * kPi / 180.0f);
  std::vector<uint32_t> chartOf(tris.size(), UINT32_MAX);
  std::vector<uint8_t> chartCurved;
  std::vector<uint32_t> stack;
  for (uint32_t seed = 0; seed < tris.size(); ++seed) {
    if (chartOf[seed] != UINT32_MAX) continue;
    const uint32_t chart = uint32_t(chartTriangles.size());
    chartTriangles.emplace_back();
    chartCurved.push_back(0);
    const TriangleInfo& s = tris[seed];
    const Vec3 n0 = s.normal;
    const float d0 = glm::dot(n0, scene.meshes[s.mesh].positions[scene.meshes[s.mesh].triangles[s.triangle][0]]);
    const bool mayCurve = curvedMaterial[s.material] != 0;
    chartOf[seed] = chart;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const uint32_t g = stack.back();
      stack.pop_back();
      chartTriangles[chart].emplace_back(tris[g].mesh, tris[g].triangle);
      if (s.area == 0.0) continue;  // a degenerate seed stays alone
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = tris[g].welded[e], b = tris[g].welded[(e + 1) % 3];
        const auto [begin, end] = adjacency.runs.at(EdgeAdjacency::key(a, b));
        for (uint32_t k = begin; k < end; ++k) {
          const uint32_t h = adjacency.edges[k].second;
          if (chartOf[h] != UINT32_MAX) continue;
          const TriangleInfo& t = tris[h];
          if (t.material != s.material || t.area == 0.0) continue;
          const Mesh& mesh = scene.meshes[t.mesh];
          bool coplanar = glm::dot(t.normal, n0) >= cosTol;
          for (int v = 0; v < 3; ++v)
            coplanar = coplanar && std::abs(glm::dot(n0, mesh.positions[mesh.triangles[t.triangle][v]]) - d0) <= planeTol;
          if (!coplanar) {
            if (!mayCurve || glm::dot(t.normal, n0) < cosCone || !smoothEdge(g, h, a, b)) continue;
            chartCurved[chart] = 1;
          }
          chartOf[h] = chart;
          stack.push_back(h);
        }
      }
    }
  }
  return chartCurved;
}

/// Open surfaces (lightfield.h "Sides"): the triangles of a connected surface (welded edges,
/// any material) are a closed, consistently wound surface when every edge is shared by exactly
/// two triangles that run along it in opposite directions. Anything else — a boundary edge (a
/// sheet, a banner, a wall modelled as one quad), a non-manifold edge, or a neighbour wound the
/// other way — makes the whole connected surface open. Returns per triangle whether its
/// surface is open.
std::vector<uint8_t> openSurfaceTriangles(const std::vector<TriangleInfo>& tris, const EdgeAdjacency& adjacency) {
  const std::vector<std::pair<uint64_t, uint32_t>>& edges = adjacency.edges;
  std::vector<uint32_t> component(tris.size());
  for (uint32_t g = 0; g < tris.size(); ++g) component[g] = g;
  auto root = [&](uint32_t g) {
    while (component[g] != g) g = component[g] = component[component[g]];
    return g;
  };
  adjacency.forEachRun([&](size_t k, size_t e) {
    for (size_t q = k + 1; q < e; ++q) {
      const uint32_t a = root(edges[k].second), b = root(edges[q].second);
      if (a != b) component[std::max(a, b)] = std::min(a, b);
    }
  });
  // Direction of triangle g along the edge with key `key`: true when it runs from the smaller
  // welded id to the larger.
  auto runsUp = [&](uint32_t g, uint64_t key) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = tris[g].welded[e], b = tris[g].welded[(e + 1) % 3];
      if (EdgeAdjacency::key(a, b) == key) return a < b;
    }
    return false;
  };
  std::vector<uint8_t> openComponent(tris.size(), 0);
  adjacency.forEachRun([&](size_t k, size_t e) {
    const bool closedEdge = e - k == 2 && runsUp(edges[k].second, edges[k].first) != runsUp(edges[k + 1].second, edges[k].first);
    if (!closedEdge)
      for (size_t q = k; q < e; ++q) openComponent[root(edges[q].second)] = 1;
  });
  std::vector<uint8_t> open(tris.size());
  for (uint32_t g = 0; g < tris.size(); ++g) open[g] = openComponent[root(g)];
  return open;
}

/// Frame and grid of the chart of triangles `list`: material and kind, the area-weighted
/// normal, whether it is curved (grewCurved, or a lone facet of a smooth mesh whose vertex
/// normals leave the plane), axisU along the projected edge that gives the smallest bounding
/// rectangle, and the tixel grid over that rectangle. `area` receives the chart's area.
Chart frameChart(const Scene& scene, const TriangleList& list, bool grewCurved, const std::vector<uint8_t>& curvedMaterial,
                 float cosTol, float baseSize, const BakeSettings& settings, double& area) {
  Chart c;
  DVec3 normalSum(0.0);
  DVec3 centroid(0.0);
  area = 0.0;
  for (const auto& [m, t] : list) {
    const Mesh& mesh = scene.meshes[m];
    const UVec3 tri = mesh.triangles[t];
    const DVec3 p0 = mesh.positions[tri[0]], p1 = mesh.positions[tri[1]], p2 = mesh.positions[tri[2]];
    const DVec3 cr = glm::cross(p1 - p0, p2 - p0);
    normalSum += cr;
    area += 0.5 * glm::length(cr);
    centroid += (p0 + p1 + p2) / 3.0;
  }
  centroid /= double(list.size());
  const uint32_t firstMaterial = scene.meshes[list[0].first].materials[list[0].second];
  c.material = firstMaterial;
  const Bsdf& bsdf = scene.materials[firstMaterial].bsdf;
  c.kind = chartKindOf(bsdf, settings);
  c.dirRes = chartDirectionalResolution(scene, c, settings);
  // A glossy model with a diffuse part keeps that part's irradiance per tixel (lightfield.h).
  c.diffuseValue = c.kind == ChartKind::Glossy && !isBlack(diffuseAlbedo(bsdf));
  // A normal-mapped diffuse material, or glossy one with a diffuse part, keeps irradiances
  // about tilted normals (lightfield.h "Normal-mapped diffuse charts").
  // (Not a subsurface chart: its light leaves at the boundary diffusely, whatever the normal.)
  c.directionalIrradiance = (c.kind == ChartKind::Diffuse || c.diffuseValue) &&
                            scene.materials[c.material].normalTexture >= 0 && !isSubsurfaceChart(scene, c);
  const double nLen = glm::length(normalSum);
  const Vec3 n = nLen > 0.0 ? Vec3(normalSum / nLen) : Vec3(0.0f, 0.0f, 1.0f);
  c.normal = n;
  // A curved chart: the projection along n foreshortens a face tilted θ by cos θ, so its
  // tixels shrink by the smallest cos θ (parameterisation.h "Curved charts").
  float minCosine = 1.0f;
  c.curved = grewCurved;
  // A chart of a smooth mesh that did not grow past one plane (a lone facet between two
  // curved charts) is curved too when its vertex normals leave the plane's normal: it
  // then gathers around them like its neighbours instead of shading flat.
  for (size_t k = 0; !c.curved && curvedMaterial[c.material] && k < list.size(); ++k) {
    const Mesh& mesh = scene.meshes[list[k].first];
    if (mesh.normals.empty()) break;
    for (int v = 0; v < 3; ++v) {
      const Vec3 vn = mesh.normals[mesh.triangles[list[k].second][v]];
      c.curved = c.curved || (vn != Vec3(0.0f) && glm::dot(vn, n) < cosTol);
    }
  }
  if (c.curved)
    for (const auto& [m, t] : list) {
      const Vec3 fn = triangleNormal(scene.meshes[m], t);
      if (fn != Vec3(0.0f)) minCosine = std::min(minCosine, glm::dot(fn, n));
    }

  // axisU: among the (longest 256) triangle edges projected into the plane, the one giving
  // the smallest bounding rectangle; ties keep the first.
  std::vector<std::pair<float, Vec3>> candidates;
  std::vector<Vec3> points;
  for (const auto& [m, t] : list) {
    const Mesh& mesh = scene.meshes[m];
    const UVec3 tri = mesh.triangles[t];
    for (int e = 0; e < 3; ++e) {
      points.push_back(mesh.positions[tri[e]]);
      Vec3 d = mesh.positions[tri[(e + 1) % 3]] - mesh.positions[tri[e]];
      d -= glm::dot(d, n) * n;
      const float len = glm::length(d);
      if (len > 0.0f) candidates.emplace_back(len, d / len);
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  if (candidates.size() > 256) candidates.resize(256);
  if (candidates.empty()) candidates.emplace_back(1.0f, Frame::fromNormal(n).s);
  const Vec3 ref(centroid);
  float bestArea = kInfinity;
  Vec3 bestU = candidates[0].second;
  Vec2 bestLo(0.0f), bestHi(0.0f);
  for (const auto& cand : candidates) {
    const Vec3 u = cand.second, v = glm::cross(n, u);
    Vec2 plo(kInfinity), phi(-kInfinity);
    for (const Vec3& q : points) {
      const Vec2 uv(glm::dot(q - ref, u), glm::dot(q - ref, v));
      plo = glm::min(plo, uv);
      phi = glm::max(phi, uv);
    }
    const float a = (phi.x - plo.x) * (phi.y - plo.y);
    if (a < bestArea * (1.0f - 1e-5f)) {
      bestArea = a;
      bestU = u;
      bestLo = plo;
      bestHi = phi;
    }
  }
  c.axisU = bestU;
  c.axisV = glm::cross(n, bestU);
  const float width = bestHi.x - bestLo.x, height = bestHi.y - bestLo.y;
  float size = chartTixelSize(scene, c.material, c.kind, baseSize) * minCosine;
  // Only a chart wider than maxTixelsPerChartSide tixels (16 384 in every preset: kilometres
  // of floor at centimetre tixels) is coarsened; none is coarsened for being small.
  const uint32_t cap = std::max<uint32_t>(1, settings.maxTixelsPerChartSide);
  if (std::max(width, height) > size * float(cap)) size = std::max(width, height) / float(cap);
  c.tixelSize = size;
  // The small slack keeps an edge that is an exact multiple of the size from gaining a tixel.
  c.resU = std::clamp(uint32_t(std::ceil(width / size - 1e-4f)), 1u, cap);
  c.resV = std::clamp(uint32_t(std::ceil(height / size - 1e-4f)), 1u, cap);
  const float padU = 0.5f * (float(c.resU) * size - width), padV = 0.5f * (float(c.resV) * size - height);
  c.origin = ref + (bestLo.x - padU) * c.axisU + (bestLo.y - padV) * c.axisV;
  return c;
}

/// Frames and grids: the room scale and base tixel size, then every chart's frameChart (in parallel).
void frameCharts(const Scene& scene, const Accel& accel, const BakeSettings& settings,
                 const std::vector<uint8_t>& curvedMaterial, const std::vector<uint8_t>& chartCurved, float cosTol,
                 Parameterisation& p) {
  p.sceneScale = settings.tixelsPerUnit > 0.0f ? 0.0f : sceneScale(scene, accel);
  p.baseTixelSize = baseTixelSize(settings, p.sceneScale);
  const size_t chartCount = p.chartTriangles.size();
  p.charts.resize(chartCount);
  p.chartArea.assign(chartCount, 0.0);
  parallelFor(chartCount, [&](uint64_t ci) {
    p.charts[ci] = frameChart(scene, p.chartTriangles[ci], chartCurved[ci] != 0, curvedMaterial, cosTol,
                              p.baseTixelSize, settings, p.chartArea[ci]);
  });
}

/// Back sides (lightfield.h "Sides"): a two-sided chart's back record right after its front
/// one. Specular charts store nothing and stay one-sided (followSpecular turns a mirror's
/// frame). Rough glass is always two-sided, closed or not: its back record holds the light on
/// the other side of the interface (the inside of a solid), which the front transmits. Other
/// charts are two-sided on an open surface (openTriangle, per triangle in weld order) when
/// something can light or see their back.
void addBackSides(const Scene& scene, const std::vector<uint8_t>& openTriangle, const Vec3& lo, const Vec3& hi,
                  float diagonal, Parameterisation& p) {
  const size_t chartCount = p.charts.size();
  std::vector<Chart> charts;
  std::vector<TriangleList> chartTriangles;
  std::vector<double> chartArea;
  charts.reserve(chartCount);
  std::vector<uint32_t> meshBase(scene.meshes.size() + 1, 0);  // weld-order index of each mesh's triangle 0
  for (size_t m = 0; m < scene.meshes.size(); ++m) meshBase[m + 1] = meshBase[m] + uint32_t(scene.meshes[m].triangles.size());
  // A back side that nothing can light or see is not stored: when the environment is black,
  // no punctual light shines on the back and the whole scene (its bounding box) lies on or in
  // front of the chart's plane, the back's radiance is exactly 0 — what a one-sided chart
  // shows from behind. (The walls of an open box, a floor, a ground plane under a black sky.)
  const float behindTolerance = 1e-4f * diagonal;
  // Something behind the plane with unit normal n through point x.
  auto somethingBehindPlane = [&](const Vec3& n, const Vec3& x) {
    const float d0 = glm::dot(n, x);
    for (int k = 0; k < 8; ++k) {
      const Vec3 corner((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
      if (glm::dot(n, corner) - d0 < -behindTolerance) return true;
    }
    for (const Light& light : scene.lights)
      if (shinesBehindPlane(light, n, d0)) return true;
    return false;
  };
  // A curved chart does not lie in one plane: behind any of its triangles' planes.
  auto somethingBehind = [&](const Chart& c, uint32_t ci) {
    if (!scene.environment.isBlack()) return true;
    if (!c.curved) return somethingBehindPlane(c.normal, c.origin);
    for (const auto& [m, t] : p.chartTriangles[ci]) {
      const Vec3 n = triangleNormal(scene.meshes[m], t);
      if (n != Vec3(0.0f) && somethingBehindPlane(n, scene.meshes[m].positions[scene.meshes[m].triangles[t][0]])) return true;
    }
    return false;
  };
  for (uint32_t ci = 0; ci < chartCount; ++ci) {
    const auto& [m, t] = p.chartTriangles[ci][0];  // a chart's triangles are connected: one surface
    Chart front = p.charts[ci];
    const bool twoSided = isRoughGlassChart(front, scene.materials[front.material].bsdf) ||
                          (front.kind != ChartKind::Specular && openTriangle[meshBase[m] + t] != 0 && somethingBehind(front, ci));
    front.sides = twoSided ? 2 : 1;
    charts.push_back(front);
    chartTriangles.push_back(p.chartTriangles[ci]);
    chartArea.push_back(p.chartArea[ci]);
    if (!twoSided) continue;
    Chart back = front;
    back.isBack = true;
    back.normal = -front.normal;
    charts.push_back(back);
    chartTriangles.push_back(p.chartTriangles[ci]);
    chartArea.push_back(p.chartArea[ci]);
  }
  p.charts = std::move(charts);
  p.chartTriangles = std::move(chartTriangles);
  p.chartArea = std::move(chartArea);
}

/// Tixel layout: every record's first tixel and value in record order, triangleChart (to the
/// front records), and the per-tixel arrays fillTixels fills, allocated (sun masks all lit).
void layOutTixels(const Scene& scene, const BakeSettings& settings, Parameterisation& p) {
  p.triangleChart.resize(scene.meshes.size());
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) p.triangleChart[m].assign(scene.meshes[m].triangles.size(), 0);
  const size_t recordCount = p.charts.size();
  for (uint32_t ci = 0; ci < recordCount; ++ci) {
    Chart& c = p.charts[ci];
    c.firstTixel = p.tixelCount;
    c.firstValue = p.valueCount;
    p.tixelCount += c.tixelCount();
    p.valueCount += c.tixelCount() * c.valuesPerTixel();
    if (!c.isBack)
      for (const auto& [m, t] : p.chartTriangles[ci]) p.triangleChart[m][t] = ci;
  }
  p.tixelChart.resize(p.tixelCount);
  p.gatherPoint.resize(p.tixelCount);
  p.gatherNormal.resize(p.tixelCount);
  if (std::any_of(p.charts.begin(), p.charts.end(), [](const Chart& c) { return c.directionalIrradiance; }))
    p.transportTiltWeights.resize(p.tixelCount);
  p.coverage.resize(p.tixelCount);
  p.borrowedPoint.assign(p.tixelCount, 0);
  p.transportAlbedo.resize(p.tixelCount);
  if (std::any_of(p.charts.begin(), p.charts.end(), [&](const Chart& c) { return perTixelSpecularF0(scene, c); }))
    p.specularF0.resize(p.tixelCount);
  if (std::any_of(p.charts.begin(), p.charts.end(), [&](const Chart& c) { return perTixelLobeWidth(scene, c); }))
    p.lobeAlpha.resize(p.tixelCount);
  if (std::any_of(p.charts.begin(), p.charts.end(), [&](const Chart& c) { return texturedEmitter(scene, c); })) {
    p.emissionModulation.assign(p.tixelCount, Rgb(1.0f));
    p.emitterTriangle.resize(p.tixelCount);
  }
  if (settings.sunMasks) p.sunMaskLights = sunMaskLights(scene);
  SunMaskSlots allLit;
  allLit.fill(SunMask(0xffffu));
  p.sunMask.assign(p.tixelCount, allLit);
  for (uint32_t ci = 0; ci < recordCount; ++ci)
    std::fill_n(p.tixelChart.begin() + int64_t(p.charts[ci].firstTixel), p.charts[ci].tixelCount(), ci);
}

}  // namespace

Parameterisation buildCharts(const Scene& scene, const Accel& accel, const BakeSettings& settings) {
  Vec3 lo, hi;
  scene.bounds(lo, hi);
  const float diagonal = glm::length(hi - lo);
  // 1e-5 of the diagonal keeps the welded (quantised) coordinates within 21 bits per axis.
  const std::vector<TriangleInfo> tris = weldTriangles(scene, lo, 1e-5f * diagonal);
  const EdgeAdjacency adjacency = edgeAdjacency(tris);
  const std::vector<uint8_t> curvedMaterial = curvedMaterials(scene, settings);
  const float cosTol = std::cos(kChartNormalToleranceDegrees * kPi / 180.0f);
  Parameterisation p;
  const std::vector<uint8_t> chartCurved = growCharts(scene, tris, adjacency, curvedMaterial, SmoothEdgeRule(scene, tris),
                                                      kChartPlaneTolerance * diagonal, cosTol, p.chartTriangles);
  const std::vector<uint8_t> openTriangle = openSurfaceTriangles(tris, adjacency);
  frameCharts(scene, accel, settings, curvedMaterial, chartCurved, cosTol, p);
  addBackSides(scene, openTriangle, lo, hi, diagonal, p);
  layOutTixels(scene, settings, p);
  return p;
}

}  // namespace pl
