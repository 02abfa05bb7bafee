#pragma once
// Parameterisation of a scene's surfaces for the light-field bake (DESIGN.md "Light-field
// pipeline" step 1; seed slides 9–17).
//
// Charts: maximal sets of edge-connected triangles that share a material and a plane. Two
// triangles sharing an edge (vertices welded by position, so split vertices still connect)
// join when their normals differ by less than kChartNormalToleranceDegrees and the far
// triangle's vertices lie within kChartPlaneTolerance × (scene diagonal) of the seed
// triangle's plane. Each chart gets an orthonormal frame — normal = the area-weighted mean of
// its triangles' winding normals (the emitting/front side), axisU along the polygon edge that
// gives the smallest bounding rectangle — and a square tixel grid over that rectangle.
//
// Tixel size: 1 / tixelsPerUnit (or scene's largest extent / tixelsAcrossScene when
// tixelsPerUnit is 0), enlarged for a chart whose rectangle would need more than
// maxTixelsPerChartSide tixels along a side. The grid is centred on the rectangle.
//
// Directional resolution by material (chartKindOf / directionalResolution):
//   Lambertian → Diffuse, dirRes 1 (irradiance);
//   ideal mirror → Specular, dirRes 0 (a reordering, nothing stored);
//   Blinn-Phong / GGX → Glossy, dirRes from the lobe width (see the .cpp), capped by
//   glossyDirRes.
//
// Sides (lightfield.h "Sides"): the diffuse and glossy charts of an open surface — a connected
// set of triangles (welded edges, any material) that is not closed and consistently wound —
// get a back record right after their front record, unless nothing can light or see the back
// (black environment, no punctual light behind, the scene's bounding box on or in front of the
// plane: its radiance is exactly 0); closed surfaces stay one-sided.
//
// Every tixel gets a gather point on the polygon: its centre when the centre lies on one of
// the chart's triangles, otherwise the closest point of the polygon (pulled slightly inside),
// so tixels outside the polygon still get valid values from a nearby real surface point.
#include "core/math.h"
#include "lightfield/lightfield.h"
#include "scene/scene.h"

#include <cstdint>
#include <utility>
#include <vector>

namespace pl {

inline constexpr float kChartNormalToleranceDegrees = 2.0f;
inline constexpr float kChartPlaneTolerance = 0.005f;  ///< relative to the scene diagonal

/// What the bake needs per tixel beyond the stored Chart records.
struct Parameterisation {
  std::vector<Chart> charts;
  std::vector<std::vector<uint32_t>> triangleChart;  ///< [mesh][triangle] → chart
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> chartTriangles;  ///< chart → (mesh, triangle)
  std::vector<double> chartArea;    ///< sum of the chart's triangle areas (scene units²)
  uint64_t tixelCount = 0;
  uint64_t valueCount = 0;
  // Per tixel, by global tixel index (Chart::firstTixel + i + j·resU):
  std::vector<uint32_t> tixelChart;   ///< owning chart
  std::vector<Vec3> gatherPoint;      ///< world point on the polygon the tixel gathers from
  std::vector<float> coverage;        ///< fraction of the tixel's square covered by the polygon
  std::vector<Rgb> transportAlbedo;   ///< diffuse charts: mean albedo over the tixel's footprint
};

ChartKind chartKindOf(const Bsdf& bsdf);
/// Paraboloid map resolution for a material (1 diffuse, 0 specular, glossy from its lobe).
uint32_t directionalResolution(const Bsdf& bsdf, const BakeSettings& settings);
/// World-space tixel size before the per-chart cap.
float baseTixelSize(const Scene& scene, const BakeSettings& settings);

/// Builds charts, tixel grids and per-tixel data. Deterministic for a given scene + settings.
Parameterisation buildParameterisation(const Scene& scene, const BakeSettings& settings);

}  // namespace pl
