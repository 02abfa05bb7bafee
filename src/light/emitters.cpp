// Emitters (see emitters.h): emissive triangles and the environment light.
#include "light/emitters.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/sampling.h"

namespace pl {

Vec2 EmissiveTriangle::barycentricsAt(Vec2 u) const { return sampleUniformTriangle(u); }

Rgb meanEmissionModulation(const Scene& scene, uint32_t meshIndex, uint32_t triangle) {
  const Mesh& mesh = scene.meshes[meshIndex];
  const Material& material = scene.materials[mesh.materials[triangle]];
  if (material.emissionTexture < 0) return Rgb(1.0f);
  const Texture& texture = scene.textures[size_t(material.emissionTexture)];
  const Vec2 corner[3] = {uvAt(mesh, triangle, Vec2(0.0f), material.emissionMapping),
                          uvAt(mesh, triangle, Vec2(1.0f, 0.0f), material.emissionMapping),
                          uvAt(mesh, triangle, Vec2(0.0f, 1.0f), material.emissionMapping)};
  const Vec2 e1 = corner[1] - corner[0], e2 = corner[2] - corner[0];
  const double texels = 0.5 * std::abs(double(e1.x) * e2.y - double(e1.y) * e2.x) * texture.image.width *
                        texture.image.height;
  const int n = int(std::clamp(std::ceil(2.0 * std::sqrt(std::isfinite(texels) ? texels : 0.0)), 4.0, 128.0));
  // Centroids of the n² sub-triangles: the upward ones (i, j ≥ 0, i + j ≤ n − 1) at
  // ((i + ⅓)/n, (j + ⅓)/n), the downward ones (i + j ≤ n − 2) at ((i + ⅔)/n, (j + ⅔)/n).
  DVec3 sum(0.0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      for (const float third : {1.0f / 3.0f, 2.0f / 3.0f}) {
        if (third > 0.5f && i + j > n - 2) continue;
        const Vec2 b((float(i) + third) / float(n), (float(j) + third) / float(n));
        sum += DVec3(emissionModulation(scene, material, meshIndex, triangle, b));
      }
    }
  const double count = double(n) * double(n);
  const Rgb mean(sum / count);
  if (!isBlack(mean)) return mean;
  const Vec2 lo = glm::min(corner[0], glm::min(corner[1], corner[2]));
  const Vec2 hi = glm::max(corner[0], glm::max(corner[1], corner[2]));
  return texture.maxOver(lo, hi) / float(count);
}

std::vector<EmissiveTriangle> emissiveTriangles(const Scene& scene) {
  std::vector<EmissiveTriangle> list;
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      const Material& material = scene.materials[mesh.materials[t]];
      if (!material.isEmissive()) continue;
      const UVec3 tri = mesh.triangles[t];
      EmissiveTriangle e;
      e.mesh = m;
      e.triangle = t;
      e.material = mesh.materials[t];
      e.p0 = mesh.positions[tri.x];
      e.edge1 = mesh.positions[tri.y] - e.p0;
      e.edge2 = mesh.positions[tri.z] - e.p0;
      const Vec3 cross = glm::cross(e.edge1, e.edge2);
      const float length = glm::length(cross);
      if (!(length > 0.0f)) continue;  // degenerate: cannot emit (and finalize() drops these)
      e.normal = cross / length;
      e.area = 0.5f * length;
      e.radiance = material.emission;
      e.textured = material.emissionTexture >= 0;
      if (e.textured) e.meanModulation = meanEmissionModulation(scene, m, t);
      e.twoSided = material.twoSidedEmission;
      list.push_back(e);
    }
  }
  return list;
}

EnvironmentLight::EnvironmentLight(const Rgb& constant, std::shared_ptr<const EnvironmentMap> map)
    : constant_(constant), isBlackConstant_(pl::isBlack(constant)), map_(std::move(map)) {
  if (!isFinite(constant) || constant.r < 0.0f || constant.g < 0.0f || constant.b < 0.0f)
    fail("environment constant radiance must be finite and ≥ 0 (got {}, {}, {})", constant.r, constant.g, constant.b);
  const double constantPower = 4.0 * kPiD * double(luminance(constant));
  const double mapPower = map_ ? map_->integratedLuminance() : 0.0;
  integratedLuminance_ = constantPower + mapPower;
  if (map_ && mapPower > 0.0) mapProbability_ = float(mapPower / (constantPower + mapPower));
}

EnvironmentSample EnvironmentLight::sample(Vec2 u) const {
  EnvironmentSample s;
  if (isBlack()) return s;
  // The mixture's pdf and radiance need the map's pdf and radiance at the chosen direction;
  // a map sample already carries both (same formulas as pdf() and radiance()), so only a
  // uniform sample looks them up.
  float mapPdf = 0.0f;
  Rgb mapRadiance(0.0f);
  if (u.x < mapProbability_) {
    u.x = std::min(u.x / mapProbability_, 0x1.fffffep-1f);
    const EnvironmentSample fromMap = map_->sample(u);
    s.direction = fromMap.direction;
    mapPdf = fromMap.pdf;
    mapRadiance = fromMap.radiance;
  } else {
    u.x = std::min((u.x - mapProbability_) / (1.0f - mapProbability_), 0x1.fffffep-1f);
    s.direction = sampleUniformSphere(u);
    if (map_) {
      if (mapProbability_ > 0.0f) mapPdf = map_->pdf(s.direction);
      mapRadiance = map_->radiance(s.direction);
    }
  }
  s.pdf = (1.0f - mapProbability_) * kUniformSpherePdf + mapProbability_ * mapPdf;
  s.radiance = constant_ + mapRadiance;
  return s;
}

float EnvironmentLight::pdf(const Vec3& dir) const {
  if (isBlack()) return 0.0f;
  const float uniform = (1.0f - mapProbability_) * kUniformSpherePdf;
  return mapProbability_ > 0.0f ? uniform + mapProbability_ * map_->pdf(dir) : uniform;
}

}  // namespace pl
