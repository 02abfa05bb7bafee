#pragma once
// Test support (header-only; include as "support/light_field_vs_trace.h"): the light field of
// a scene against the path tracer from one camera — what the accuracy tests of src/render
// (rough glass, curved glossy charts) compare. The caller links pl_bake, pl_render, pl_trace.
#include "accel/accel.h"
#include "bake/bake.h"
#include "camera/camera.h"
#include "image/image.h"
#include "render/render.h"
#include "scene/scene.h"
#include "trace/trace.h"

#include <functional>
#include <vector>

namespace pl::test_support {

struct LightFieldAndReference {
  Image reference;        ///< path traced, referenceSpp samples per pixel
  LightField lightField;  ///< baked with the given settings
  Image image;            ///< the light field rendered by the reference renderer
};

inline LightFieldAndReference lightFieldAndReference(const Scene& scene, const Camera& camera, int referenceSpp,
                                                     const BakeSettings& settings, int lightFieldSamples) {
  LightFieldAndReference out;
  {
    const Accel accel(scene);
    const PathTracer tracer(scene, accel);
    TraceSettings trace;
    trace.spp = referenceSpp;
    trace.showProgress = false;
    out.reference = tracer.render(camera, trace).radiance;
  }
  out.lightField = bake(Scene(scene), settings);
  const Accel accel(out.lightField.scene);
  RenderSettings render;
  render.samplesPerPixel = lightFieldSamples;
  out.image = renderLightField(out.lightField, accel, camera, render);
  return out;
}

/// Per pixel (y·width + x), what the ray through its centre hits: the pixels a comparison
/// keeps to one surface (a ball, the spheres, a sheet).
inline std::vector<RayHit> pixelCentreHits(const Accel& accel, const Camera& camera) {
  std::vector<RayHit> hits(size_t(camera.width()) * size_t(camera.height()));
  for (int y = 0; y < camera.height(); ++y)
    for (int x = 0; x < camera.width(); ++x)
      accel.intersect(camera.generateRay(Vec2(float(x) + 0.5f, float(y) + 0.5f), Vec2(0.5f)).ray,
                      hits[size_t(y) * size_t(camera.width()) + size_t(x)]);
  return hits;
}

/// The ratio of `image`'s to `reference`'s mean luminance over the pixels whose centre ray hits
/// a surface `keep(hit)` accepts (hits: pixelCentreHits), and how many pixels that is (0 when
/// none: the ratio is then 0).
struct RegionRatio {
  double ratio = 0.0;
  int pixels = 0;
};
inline RegionRatio regionLuminanceRatio(const Image& image, const Image& reference, const std::vector<RayHit>& hits,
                                        const std::function<bool(const RayHit&)>& keep) {
  double imageSum = 0.0, referenceSum = 0.0;
  RegionRatio region;
  for (size_t i = 0; i < hits.size(); ++i) {
    if (!hits[i].hit() || !keep(hits[i])) continue;
    imageSum += luminance(image.pixels[i]);
    referenceSum += luminance(reference.pixels[i]);
    ++region.pixels;
  }
  region.ratio = referenceSum > 0.0 ? imageSum / referenceSum : 0.0;
  return region;
}

}  // namespace pl::test_support
