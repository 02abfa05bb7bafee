// The 16-neighbour light-field lookup (seed slide 36).
#include "lightfield/lookup.h"

#include "lightfield/paraboloid.h"

namespace pl {

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
  shading.emission = lanes4(material.emission);
  shading.emissive = !isBlack(material.emission);
  shading.inverseTixelSize = 1.0f / c.tixelSize;
  shading.twoSidedEmission = material.twoSidedEmission;
  shading.texturedAlbedo = material.albedoTexture >= 0;
  if (c.kind == ChartKind::Diffuse && !shading.texturedAlbedo)
    shading.albedoOverPi = lanes4(diffuseAlbedoAt(scene, c.material, Vec2(0.0f)) * kInvPi);
  shading.needsUv = c.kind == ChartKind::Diffuse && shading.texturedAlbedo;
  return shading;
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
