// The 16-neighbour light-field lookup (seed slide 36).
#include "lightfield/lookup.h"

#include "lightfield/paraboloid.h"
#include "lightfield/render_settings.h"

#include <algorithm>
#include <bit>
#include <optional>

#include "core/rng.h"
#include "core/sampler.h"

namespace pl {

Rgb backgroundRadiance(const Environment& environment, const Vec3& direction) {
  return environment.radiance(direction);
}

Rgb diffuseAlbedoAt(const Scene& scene, uint32_t material, const AlbedoPoint& p) {
  // Lambert (every diffuse chart of an OBJ scene): bsdfAt's albedo, the model's albedo times
  // the modulation, without building the BSDF (the renderers call this per textured pixel).
  const Material& m = scene.materials[material];
  const auto* lambert = std::get_if<LambertBsdf>(&m.bsdf);
  if (!m.modelVaries())
    return lambert ? lambert->albedo : albedo(m.bsdf, Vec3(0.0f, 0.0f, 1.0f));
  if (m.metallicRoughness.texture >= 0) return albedo(materialModelAt(scene, m, p), Vec3(0.0f, 0.0f, 1.0f));
  const Rgb modulation = albedoModulation(scene, m, p);
  if (lambert) return lambert->albedo * modulation;
  // bsdfAt's texturing (the model's diffuse albedo times the modulation), then the directional
  // albedo at normal incidence: for a model other than Lambert, a chart was classified
  // diffuse for its hemispherical reflectance.
  return albedo(withDiffuseAlbedo(m.bsdf, diffuseAlbedo(m.bsdf) * modulation), Vec3(0.0f, 0.0f, 1.0f));
}

Rgb glossyDiffuseAlbedoAt(const Scene& scene, uint32_t material, const AlbedoPoint& p) {
  const Material& m = scene.materials[material];
  // With a metallic-roughness texture: the point's model's diffuse albedo (the renderers take
  // its k(μo) too, glossyDiffuseReflectanceAt).
  if (m.metallicRoughness.texture >= 0) return diffuseAlbedo(materialModelAt(scene, m, p));
  const Rgb rho = diffuseAlbedo(m.bsdf);
  return m.albedoVaries() ? rho * albedoModulation(scene, m, p) : rho;
}

Rgb glossyDiffuseReflectanceAt(const Scene& scene, uint32_t material, const AlbedoPoint& p, float cosViewer) {
  const Bsdf model = materialModelAt(scene, scene.materials[material], p);
  return diffuseAlbedo(model) * diffuseDirectionalFactor(model, cosViewer) * kInvPi;
}

namespace {

/// A 64-bit hash of the ray's bits (origin and direction): the source of followSpecular's
/// two uniform numbers, the branch (bits 40–63) and the roulette (bits 16–39).
uint64_t specularRayHash(const Ray& ray) {
  uint64_t h = 0x5350454355ULL;
  for (const float v : {ray.origin.x, ray.origin.y, ray.origin.z, ray.direction.x, ray.direction.y, ray.direction.z})
    h = hashCombine(h, std::bit_cast<uint32_t>(v));
  return h;
}

}  // namespace

float specularBranchU(const Ray& ray) { return float(specularRayHash(ray) >> 40) * 0x1p-24f; }

float specularRouletteU(const Ray& ray) { return float((specularRayHash(ray) >> 16) & 0xffffffULL) * 0x1p-24f; }

namespace {

/// Two uniform numbers in [0, 1) from a hash of the ray's bits and `salt`. Sample k > 0 of a
/// split (firstHitLobeSamples) is point k of the 2-D Sobol sequence (a (0,2)-sequence, core/
/// sampler.h) shifted by sample 0's numbers modulo 1 (a Cranley–Patterson rotation): every
/// sample is uniform on its own, sample 0 keeps the numbers unsplit rays always had (the bake's
/// and every later hit's), and the split's 2^j samples are stratified — one in each of the
/// rotated elementary intervals of area 2^-j — instead of independent.
Vec2 rayHashU2(const Ray& ray, uint64_t salt, uint32_t sample) {
  const uint64_t h = hashCombine(specularRayHash(ray), salt);
  // 24-bit fixed point: sample 0's numbers, then the rotation added modulo 2^24 (exact).
  uint32_t x = uint32_t(h >> 40), y = uint32_t((h >> 16) & 0xffffffULL);
  if (sample > 0) {
    x = (x + (reverseBits32(reversedSobolPoint(sample, 0)) >> 8)) & 0xffffffu;
    y = (y + (reverseBits32(reversedSobolPoint(sample, 1)) >> 8)) & 0xffffffu;
  }
  return Vec2(float(x) * 0x1p-24f, float(y) * 0x1p-24f);
}

}  // namespace

Vec2 specularLobeU(const Ray& ray, uint32_t sample) { return rayHashU2(ray, 0x4c4f4245ULL, sample); }

Vec2 nextEventU(const Ray& ray, uint32_t sample) { return rayHashU2(ray, 0x4e45454cULL, sample); }

uint32_t firstHitLobeSamples(const LightField& lf, uint32_t chart) {
  const Chart& c = lf.charts[chart];
  return isMirrorLikeRecord(c, lf.scene.materials[c.material].bsdf) ? kFirstHitLobeSamples : 1;
}

bool followSpecular(const Scene& scene, const Ray& ray, const RayHit& hit, uint32_t step, uint32_t stepLimit,
                    Rgb& emitted, Ray& next, Rgb& weight, SpecularStep* sampled, uint32_t lobeSample) {
  const SurfaceHit surface = surfaceAt(scene, hit.mesh, hit.triangle, hit.barycentrics);
  const Material& material = scene.materials[surface.material];
  const Vec3 wo = -ray.direction;
  const float cosWoGeometric = glm::dot(surface.geometricNormal, wo);
  const Rgb attenuation = interiorTransmittance(material, cosWoGeometric, hit.t);  // Beer–Lambert (scene.h)
  emitted = emittedRadiance(material, cosWoGeometric) *
            emissionModulation(scene, material, hit.mesh, hit.triangle, hit.barycentrics) * attenuation;
  if (step >= stepLimit) return false;
  Bsdf bsdf = bsdfAt(scene, surface);
  // Rough glass is a glossy chart and never comes here, except in a .plf baked before it was
  // (where it was a specular chart): followed as smooth, as that bake followed it.
  if (auto* glass = std::get_if<DielectricBsdf>(&bsdf)) glass->alpha = 0.0f;
  const ScatteringFrame scattering = scatteringFrame(surface, wo, bsdf);  // sidedness: scene.h
  if (!usableSide(wo, scattering.woLocal, scattering.geometricNormal, bsdf)) return false;
  // The one bounce (scene.h scatter), about the shading normal as in the path tracer: a
  // delta lobe's branch, or (a mirror-like lobe, bake/parameterisation.h isMirrorLike) a
  // direction importance-sampled from the lobe, weighted f·cos θ/pdf.
  const bool lobe = !isDelta(bsdf);
  const std::optional<Scattered> bs = scatter(scattering, bsdf, lobe ? specularLobeU(ray, lobeSample) : Vec2(specularBranchU(ray), 0.5f));
  if (!bs || (!lobe && !bs->sample.delta)) return false;
  next = Ray{offsetRayOrigin(surface.position, scattering.geometricNormal, bs->wi), bs->wi, 0.0f, kInfinity};
  weight = bs->sample.weight * attenuation;
  if (sampled != nullptr) {
    const auto* sheet = std::get_if<DielectricBsdf>(&bsdf);
    *sampled = SpecularStep{lobe ? bs->sample.pdf : 0.0f,
                            sheet != nullptr && sheet->thin && scattering.woLocal.z * bs->sample.wi.z < 0.0f};
  }
  if (step >= kSpecularRouletteStep) {
    // Russian roulette on the branch weight: continue with probability q = min(1, max
    // channel) and divide by q, so the expected weight is unchanged (unbiased). Weights ≥ 1
    // (glass reflection, refraction out of glass) always continue.
    const float survival = std::min(1.0f, maxComponent(weight));
    if (!(specularRouletteU(ray) < survival)) return false;
    weight /= survival;
  }
  return true;
}

SunLights sunLightsOf(const LightField& lf) {
  // sunMaskLights' lights, the scene's first directional ones, taken without its allocation
  // and material scan (the reference lookup calls this per sample): a light field has masks
  // only when its scene has no thin glass (the bake and the .plf reader make sure).
  SunLights sun;
  for (size_t i = 0; i < lf.scene.lights.size() && sun.count < lf.sunMaskLightCount; ++i)
    if (const std::optional<ParallelLight> light = parallelLight(lf.scene.lights[i])) {
      sun.towardsLight[sun.count] = light->towardsLight;
      sun.irradiance[sun.count] = lanes4(light->irradiance);
      ++sun.count;
    }
  if (sun.count != lf.sunMaskLightCount)
    fail("{}: the light field has sun masks for {} light(s), its scene {} directional light(s)", lf.scene.sourcePath,
         lf.sunMaskLightCount, sun.count);
  return sun;
}

ChartShading chartShading(const LightField& lf, uint32_t chart, const SunLights& sun) {
  const Scene& scene = lf.scene;
  const Chart& c = lf.charts[chart];
  const Material& material = scene.materials[c.material];
  ChartShading shading;
  // Emission towards the record's own front (a back record's is zero for one-sided emitters).
  const Rgb emission = chartEmittedRadiance(material, c, 1.0f);
  shading.emission = lanes4(emission);
  shading.emissive = !isBlack(emission);
  shading.inverseTixelSize = 1.0f / c.tixelSize;
  shading.twoSidedEmission = material.twoSidedEmission;
  shading.texturedAlbedo = material.modelVaries();
  if (c.kind == ChartKind::Diffuse && !shading.texturedAlbedo)
    shading.albedoOverPi = lanes4(diffuseAlbedoAt(scene, c.material, AlbedoPoint{}) * kInvPi);
  if (c.diffuseValue && !shading.texturedAlbedo)
    shading.albedoOverPi = lanes4(glossyDiffuseAlbedoAt(scene, c.material, AlbedoPoint{}) * kInvPi);
  shading.texturedEmission = shading.emissive && c.kind == ChartKind::Diffuse && material.emissionTexture >= 0;
  shading.needsUv = ((c.kind == ChartKind::Diffuse || c.diffuseValue) && shading.texturedAlbedo) || shading.texturedEmission;
  shading.normalMapped = (c.kind == ChartKind::Glossy || c.directionalIrradiance) && material.normalTexture >= 0;
  shading.curvedGlossy = c.kind == ChartKind::Glossy && c.curved;
  if (c.kind == ChartKind::Diffuse && sun.count > 0 &&
      (c.firstTixel + c.tixelCount()) * sun.count <= lf.sunMasks.size()) {
    shading.sunMasks = lf.sunMasks.data() + c.firstTixel * sun.count;
    shading.sun = &sun;
  }
  return shading;
}

Vec3 normalMappedLookupDirection(const Vec3& mapNormal, const Vec3& shadingNormal, const Vec3& wo) {
  // The viewer's side: a back-side viewer (one-sided chart) sees the front, as without a map.
  if (!(glm::dot(wo, mapNormal) > 0.0f)) return wo;
  const Vec3 mirrored = 2.0f * glm::dot(wo, shadingNormal) * shadingNormal - wo;  // about n'
  const Vec3 d = 2.0f * glm::dot(mirrored, mapNormal) * mapNormal - mirrored;     // about n
  return glm::dot(d, mapNormal) > 0.0f ? glm::normalize(d) : wo;
}

Rgb exitantRadiance(const LightField& lf, uint32_t chart, const Vec3& worldPosition,
                    const Vec3& worldDirectionTowardsViewer, Vec2 uv) {
  // No triangle here: the chart normal decides the side (exact for planar charts).
  chart = facingChart(lf.charts.data(), chart, worldDirectionTowardsViewer, lf.charts[chart].normal);
  const Chart& c = lf.charts[chart];
  if (c.kind == ChartKind::Specular) return Rgb(0.0f);
  const SunLights sun = sunLightsOf(lf);
  return exitantRadiance(lf.scene, c, chartShading(lf, chart, sun), lf.values.data(), worldPosition,
                         worldDirectionTowardsViewer, c.normal, c.normal, AlbedoPoint{uv, kFullResolution, Rgb(1.0f)});
}

Rgb exitantRadiance(const LightField& lf, const RayHit& hit, const Vec3& worldPosition,
                    const Vec3& worldDirectionTowardsViewer, float coneWidth) {
  // The chart facing the viewer (a two-sided surface's back record when seen from behind; none
  // behind a one-sided curved one), then what the lookup needs at the hit — the fast
  // renderer's lookupInputs. The shading is made once per call.
  const uint32_t chart = viewedChart(lf.charts.data(), lf.triangleChart[hit.mesh][hit.triangle], worldDirectionTowardsViewer,
                                     lf.scene.meshes[hit.mesh], hit.triangle);
  if (chart == kNoChartRecord) return Rgb(0.0f);  // inside a closed smooth mesh
  const Chart& c = lf.charts[chart];
  if (c.kind == ChartKind::Specular) return Rgb(0.0f);
  const SunLights sun = sunLightsOf(lf);
  const ChartShading shading = chartShading(lf, chart, sun);
  AlbedoPoint albedo;
  Vec3 lookupNormal, mappedNormal;
  lookupInputs(lf.scene, c, shading, hit, worldDirectionTowardsViewer, coneWidth, albedo, lookupNormal, mappedNormal);
  return exitantRadiance(lf.scene, c, shading, lf.values.data(), worldPosition, worldDirectionTowardsViewer, lookupNormal,
                         mappedNormal, albedo);
}

bool isMirrorLikeRecord(const Chart& c, const Bsdf& model) {
  return c.kind == ChartKind::Specular && !isDelta(model) && !hasTransmission(model);
}

PunctualHighlights::PunctualHighlights(const LightField& lf, const Accel& accel)
    : lf_(lf), glossyCharts_(lf.settings.punctualHighlights) {
  // Mirror-like charts have no maps to keep them in: theirs are always evaluated here.
  const bool mirrorLike = std::any_of(lf.charts.begin(), lf.charts.end(), [&](const Chart& c) {
    return isMirrorLikeRecord(c, lf.scene.materials[c.material].bsdf);
  });
  if (!glossyCharts_ && !mirrorLike) return;
  for (const Light& light : lf.scene.lights)
    if (isDeltaLight(light)) lights_.push_back(light);  // the others are in the maps
  if (lights_.empty()) return;
  shadows_.emplace(lf.scene, accel);
  for (const Material& m : lf.scene.materials) withoutDiffuse_.push_back(withDiffuseAlbedo(m.bsdf, Rgb(0.0f)));
}

Rgb PunctualHighlights::radiance(uint32_t chart, const RayHit& hit, const Vec3& towardsViewer) const {
  const Chart& c = lf_.charts[chart];
  if (lights_.empty() || c.kind == ChartKind::Diffuse) return Rgb(0.0f);
  const Scene& scene = lf_.scene;
  const Bsdf& model = scene.materials[c.material].bsdf;
  // A specular chart's only when mirror-like (a mirror's are 0).
  if (c.kind == ChartKind::Specular ? !isMirrorLikeRecord(c, model) : !glossyCharts_) return Rgb(0.0f);
  if (isRoughGlassChart(c, model)) return Rgb(0.0f);  // rough glass keeps them in its maps
  // The model the maps hold (the bake's first shot: without the diffuse part when Ẽ keeps it);
  // with a metallic-roughness texture the point's own, as the path tracer's bsdfAt makes it.
  const bool perPoint = scene.materials[c.material].metallicRoughness.texture >= 0;
  Bsdf pointModel;
  if (perPoint) {
    pointModel = materialModelAt(scene, scene.materials[c.material],
                                 albedoPointAt(scene, hit.mesh, hit.triangle, hit.barycentrics));
    if (c.diffuseValue) pointModel = withDiffuseAlbedo(pointModel, Rgb(0.0f));
  }
  const Bsdf& bsdf = perPoint ? pointModel : c.diffuseValue ? withoutDiffuse_[c.material] : model;
  const SurfaceHit surface = surfaceAt(scene, hit.mesh, hit.triangle, hit.barycentrics);
  const ScatteringFrame scattering = scatteringFrame(surface, towardsViewer, bsdf);  // the sidedness rule (scene.h)
  const auto& [geometricNormal, frame, woLocal] = scattering;
  if (!usableSide(towardsViewer, woLocal, geometricNormal, bsdf)) return Rgb(0.0f);
  Rgb sum(0.0f);
  uint64_t shadowRays = 0;  // ShadowRays counts them; no renderer reports them
  for (const Light& light : lights_) {
    const std::optional<IncidentLight> in = sampleLight(light, surface.position, Vec2(0.5f));
    if (!in) continue;
    const Vec3& wi = in->wi;
    const Rgb& incident = in->incident;
    const Vec3 wiLocal = frame.toLocal(wi);
    if (!usableSide(wi, wiLocal, geometricNormal, bsdf)) continue;
    const Rgb f = eval(bsdf, woLocal, wiLocal);
    const float cosIn = std::abs(wiLocal.z);
    if (isBlack(f) || !(cosIn > 0.0f) || isBlack(incident)) continue;
    const std::optional<Ray> shadow = shadowRayTowards(offsetRayOrigin(surface.position, geometricNormal, wi), *in);
    if (!shadow) continue;
    const Rgb visible = shadows_->transmittance(*shadow, shadowRays);
    if (!isBlack(visible)) sum += visible * f * cosIn * incident;
  }
  return sum;
}

MirrorLikeLights::MirrorLikeLights(const LightField& lf, const Accel& accel) : lf_(lf) {
  const bool mirrorLike = std::any_of(lf.charts.begin(), lf.charts.end(), [&](const Chart& c) {
    return isMirrorLikeRecord(c, lf.scene.materials[c.material].bsdf);
  });
  if (!mirrorLike) return;
  LightSampler sampler(lf.scene);
  if (sampler.emissiveTriangleCount() == 0 && !sampler.hasEnvironment() && !sampler.hasSphereLights()) return;
  sampler_.emplace(std::move(sampler));
  shadows_.emplace(lf.scene, accel);
}

Rgb MirrorLikeLights::radiance(uint32_t chart, const Ray& ray, const RayHit& hit, uint32_t sample) const {
  const Scene& scene = lf_.scene;
  const Chart& c = lf_.charts[chart];
  if (!sampler_ || !isMirrorLikeRecord(c, scene.materials[c.material].bsdf)) return Rgb(0.0f);
  // The frame and model followSpecular samples the lobe in, so the two densities agree.
  const SurfaceHit surface = surfaceAt(scene, hit.mesh, hit.triangle, hit.barycentrics);
  const Bsdf bsdf = bsdfAt(scene, surface);
  const Vec3 wo = -ray.direction;
  const ScatteringFrame scattering = scatteringFrame(surface, wo, bsdf);
  if (!usableSide(wo, scattering.woLocal, scattering.geometricNormal, bsdf)) return Rgb(0.0f);
  uint64_t rays = 0;  // no renderer reports them
  return nextEventEstimate(*sampler_, *shadows_, surface.position, scattering, bsdf, nextEventU(ray, sample),
                           NextEvent::MisExceptDelta, rays);
}

float MirrorLikeLights::emissionWeight(const Ray& ray, const RayHit& hit, const LobeChain& chain) const {
  if (!sampler_ || !(chain.pdf > 0.0f)) return 1.0f;
  const float cosLight = std::abs(glm::dot(triangleNormal(lf_.scene.meshes[hit.mesh], hit.triangle), ray.direction));
  return powerHeuristic(chain.pdf, sampler_->emitterPdf(hit.mesh, hit.triangle, chain.distance + hit.t, cosLight));
}

float MirrorLikeLights::environmentWeight(const Vec3& direction, const LobeChain& chain) const {
  if (!sampler_ || !(chain.pdf > 0.0f) || !sampler_->hasEnvironment()) return 1.0f;
  return powerHeuristic(chain.pdf, sampler_->environmentPdf(direction));
}

Rgb MirrorLikeLights::sphereEmission(const Ray& ray, float tHit, const LobeChain& chain) const {
  if (!sampler_ || !(chain.pdf > 0.0f) || !sampler_->hasSphereLights()) return Rgb(0.0f);
  Ray segment = ray;
  segment.tMax = tHit;
  // The lobe's vertex: chain.distance back along the ray (straight passes of thin sheets).
  const std::optional<LightSampler::SphereCrossing> sphere =
      sampler_->sphereLightAlong(segment, ray.origin - chain.distance * ray.direction);
  return sphere ? sphere->radiance * powerHeuristic(chain.pdf, sphere->pdf) : Rgb(0.0f);
}

Rgb MirrorLikeLights::overcountedEmission(const Ray& ray, const RayHit& hit, const LobeChain& chain) const {
  if (!sampler_ || !(chain.pdf > 0.0f)) return Rgb(0.0f);
  const Scene& scene = lf_.scene;
  const Mesh& mesh = scene.meshes[hit.mesh];
  const Material& material = scene.materials[mesh.materials[hit.triangle]];
  const float cosFront = glm::dot(triangleNormal(mesh, hit.triangle), -ray.direction);
  const Rgb le = emittedRadiance(material, cosFront);
  if (isBlack(le)) return Rgb(0.0f);
  return (1.0f - emissionWeight(ray, hit, chain)) * le *
         emissionModulation(scene, material, hit.mesh, hit.triangle, hit.barycentrics);
}

}  // namespace pl
