#pragma once
// Looking the light field up: the 16-neighbour interpolation of seed slide 36 — bilinear over
// the 2×2 nearest tixels (position) × bilinear over the 2×2 nearest paraboloid texels
// (direction). Used by the renderers and, through the same functions, by the bake itself.
//
// Interpolation conventions (match lightfield.h):
//   tixel (i, j) has its centre at continuous grid coordinate (i, j), where a world point p has
//   grid coordinates ((p − origin)·axisU / tixelSize − ½, (p − origin)·axisV / tixelSize − ½);
//   paraboloid texel (a, b) has its centre at continuous coordinate (a, b), see paraboloid.h.
//   Outside the outermost centres the edge values are held (clamp-to-edge), never extrapolated.
#include "core/math.h"
#include "lightfield/lightfield.h"
#include "lightfield/paraboloid.h"
#include "scene/scene.h"

#include <cstdint>

namespace pl {

/// One axis of a clamp-to-edge bilinear interpolation: value = (1−f)·v[i0] + f·v[i1].
struct LinearTap {
  uint32_t i0 = 0, i1 = 0;
  float f = 0.0f;
};

/// The tap for continuous coordinate x over `count` samples centred at 0 … count−1:
///   x ≤ 0 or NaN   → (0, 0, f = 0)            (hold the first sample)
///   x ≥ count − 1  → (count−1, count−1, f = 0) (hold the last sample)
///   otherwise      → (⌊x⌋, ⌊x⌋ + 1, x − ⌊x⌋).
/// Written without branches (the renderers call it four times per pixel with data-dependent
/// clamping): the clamp compiles to maxss/minss, `x > 0 ? x : 0` maps NaN to 0, and the
/// upper index is ⌊x⌋ + [x > 0] capped at count − 1, which is exactly the case list above.
inline LinearTap linearTap(float x, uint32_t count) {
  const uint32_t last = count - 1;
  const float positive = x > 0.0f ? x : 0.0f;  // NaN → 0
  const float lastF = float(last);
  const float clamped = positive < lastF ? positive : lastF;
  LinearTap tap;
  tap.i0 = uint32_t(clamped);
  const uint32_t next = tap.i0 + uint32_t(clamped > 0.0f);
  tap.i1 = next < last ? next : last;
  tap.f = clamped - float(tap.i0);
  return tap;
}

/// Continuous tixel grid coordinates of world point p on chart c (p need not lie on it).
inline Vec2 tixelGridCoordinates(const Chart& c, const Vec3& p) {
  const Vec3 d = p - c.origin;
  const float inv = 1.0f / c.tixelSize;
  return {glm::dot(d, c.axisU) * inv - 0.5f, glm::dot(d, c.axisV) * inv - 0.5f};
}

/// A world direction in the chart's local frame (z along the chart normal).
inline Vec3 chartLocalDirection(const Chart& c, const Vec3& w) {
  return {glm::dot(w, c.axisU), glm::dot(w, c.axisV), glm::dot(w, c.normal)};
}
inline Vec3 chartWorldDirection(const Chart& c, const Vec3& local) {
  return local.x * c.axisU + local.y * c.axisV + local.z * c.normal;
}

/// Bilinear × bilinear interpolation over a raw value array laid out like LightField::values
/// (the bake uses it on its working arrays). Specular charts give 0.
inline Rgb interpolateValues(const Rgb* values, const Chart& c, Vec2 grid, Vec2 st) {
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

/// Diffuse albedo of `material` at surface uv: the Lambertian albedo times its albedo texture
/// (if any) sampled at full resolution, exactly as the path tracer's bsdfAt does.
Rgb diffuseAlbedoAt(const Scene& scene, uint32_t material, Vec2 uv);

/// Emitted radiance of `material` towards local direction cosθ (chart frame, z = front side):
/// one-sided along the geometric normal unless the material is two-sided.
inline Rgb emittedRadiance(const Material& m, float cosTheta) {
  return (cosTheta > 0.0f || m.twoSidedEmission) ? m.emission : Rgb(0.0f);
}

/// The per-chart constants of exitantRadiance (its material's emission and, when no texture
/// varies it, its diffuse albedo). The fast renderer (src/realtime) precomputes one per chart;
/// the plain exitantRadiance below builds it on the fly, so both run the same formula.
struct ChartShading {
  Rgb emission{0.0f};             ///< Le of the chart's material (W·sr⁻¹·m⁻²)
  bool twoSidedEmission = false;
  bool texturedAlbedo = false;    ///< diffuse albedo varies with uv: diffuseAlbedoAt per point
  Rgb albedo{0.0f};               ///< diffuse albedo when !texturedAlbedo (diffuse charts only)
};
ChartShading chartShading(const Scene& scene, const Chart& c);

/// Exitant radiance (W·sr⁻¹·m⁻²) of chart `chart` at worldPosition towards the viewer:
///   diffuse chart:  Le + albedo(uv)·E/π with E bilinearly interpolated over the 2×2 nearest
///                   tixels and the albedo texture applied at full resolution at `uv`;
///   glossy chart:   the 16-neighbour interpolation of the stored exitant radiance;
///   specular chart: 0 — the caller follows the mirrored ray (reordering) and looks up what it
///                   sees.
/// A viewer behind the chart (one-sided parameterisation) sees the front-side reflected
/// radiance; emission there follows emittedRadiance.
Rgb exitantRadiance(const LightField& lf, uint32_t chart, const Vec3& worldPosition,
                    const Vec3& worldDirectionTowardsViewer, Vec2 uv);

/// The same for a ray hit (chart from lf.triangleChart, uv from the hit).
Rgb exitantRadiance(const LightField& lf, const SurfaceHit& hit, const Vec3& worldDirectionTowardsViewer);

/// exitantRadiance given the chart's precomputed shading and a value array laid out like
/// LightField::values: the one implementation every caller goes through. Defined inline so
/// that the fast renderer's per-pixel loop inlines it instead of calling across files.
inline Rgb exitantRadiance(const Scene& scene, const Chart& c, const ChartShading& shading, const Rgb* values,
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

}  // namespace pl
