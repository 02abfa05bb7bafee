// The 16-neighbour light-field lookup (seed slide 36).
#include "lightfield/lookup.h"

#include "lightfield/paraboloid.h"

namespace pl {

Rgb interpolateChartValues(const LightField& lf, const Chart& c, Vec2 grid, Vec2 st) {
  return interpolateValues(lf.values.data(), c, grid, st);
}

Rgb interpolateValues(const Rgb* values, const Chart& c, Vec2 grid, Vec2 st) {
  if (c.kind == ChartKind::Specular || c.dirRes == 0) return Rgb(0.0f);
  const LinearTap tu = linearTap(grid.x, c.resU);
  const LinearTap tv = linearTap(grid.y, c.resV);
  const uint32_t is[2] = {tu.i0, tu.i1}, js[2] = {tv.i0, tv.i1};
  const float wu[2] = {1.0f - tu.f, tu.f}, wv[2] = {1.0f - tv.f, tv.f};
  Rgb sum(0.0f);
  if (c.dirRes == 1) {
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) sum += (wu[x] * wv[y]) * values[c.valueIndex(is[x], js[y])];
    return sum;
  }
  const LinearTap ta = linearTap(paraboloidTexelCoordinate(st.x, c.dirRes), c.dirRes);
  const LinearTap tb = linearTap(paraboloidTexelCoordinate(st.y, c.dirRes), c.dirRes);
  const uint32_t as[2] = {ta.i0, ta.i1}, bs[2] = {tb.i0, tb.i1};
  const float wa[2] = {1.0f - ta.f, ta.f}, wb[2] = {1.0f - tb.f, tb.f};
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) {
      const float wPos = wu[x] * wv[y];
      if (wPos == 0.0f) continue;
      Rgb inner(0.0f);
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a) inner += (wa[a] * wb[b]) * values[c.valueIndex(is[x], js[y], as[a], bs[b])];
      sum += wPos * inner;
    }
  return sum;
}

Rgb diffuseAlbedoAt(const Scene& scene, uint32_t material, Vec2 uv) {
  SurfaceHit hit;
  hit.material = material;
  hit.uv = uv;
  const Bsdf bsdf = bsdfAt(scene, hit);
  if (const auto* lambert = std::get_if<LambertBsdf>(&bsdf)) return lambert->albedo;
  // Any other model a chart was classified diffuse for: its hemispherical reflectance.
  return albedo(bsdf, Vec3(0.0f, 0.0f, 1.0f));
}

ChartShading chartShading(const Scene& scene, const Chart& c) {
  const Material& material = scene.materials[c.material];
  ChartShading shading;
  shading.emission = material.emission;
  shading.twoSidedEmission = material.twoSidedEmission;
  shading.texturedAlbedo = material.albedoTexture >= 0;
  if (c.kind == ChartKind::Diffuse && !shading.texturedAlbedo) shading.albedo = diffuseAlbedoAt(scene, c.material, Vec2(0.0f));
  return shading;
}

Rgb exitantRadiance(const Scene& scene, const Chart& c, const ChartShading& shading, const Rgb* values,
                    const Vec3& worldPosition, const Vec3& worldDirectionTowardsViewer, Vec2 uv) {
  if (c.kind == ChartKind::Specular) return Rgb(0.0f);
  const Vec2 grid = tixelGridCoordinates(c, worldPosition);
  const Vec3 local = chartLocalDirection(c, worldDirectionTowardsViewer);
  // emittedRadiance (above) on the precomputed emission.
  const Rgb emitted = (local.z > 0.0f || shading.twoSidedEmission) ? shading.emission : Rgb(0.0f);
  if (c.kind == ChartKind::Diffuse) {
    const Rgb irradiance = interpolateValues(values, c, grid, Vec2(0.0f));
    const Rgb albedo = shading.texturedAlbedo ? diffuseAlbedoAt(scene, c.material, uv) : shading.albedo;
    return emitted + albedo * irradiance * kInvPi;
  }
  // Glossy: the stored values already include emission towards the front side.
  const Rgb stored = interpolateValues(values, c, grid, directionToParaboloid(local));
  if (local.z >= 0.0f) return stored;
  // Behind a one-sided chart: its front-side value at the horizon, minus the one-sided
  // emission it contains, plus the back-side emission (nonzero only for two-sided emitters).
  return glm::max(stored - shading.emission, Rgb(0.0f)) + emitted;
}

Rgb exitantRadiance(const LightField& lf, uint32_t chart, const Vec3& worldPosition,
                    const Vec3& worldDirectionTowardsViewer, Vec2 uv) {
  const Chart& c = lf.charts[chart];
  if (c.kind == ChartKind::Specular) return Rgb(0.0f);
  return exitantRadiance(lf.scene, c, chartShading(lf.scene, c), lf.values.data(), worldPosition,
                         worldDirectionTowardsViewer, uv);
}

Rgb exitantRadiance(const LightField& lf, const SurfaceHit& hit, const Vec3& worldDirectionTowardsViewer) {
  const uint32_t chart = lf.triangleChart[hit.mesh][hit.triangle];
  return exitantRadiance(lf, chart, hit.position, worldDirectionTowardsViewer, hit.uv);
}

}  // namespace pl
