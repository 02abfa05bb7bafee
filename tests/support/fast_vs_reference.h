#pragma once
// Test support (header-only; include as "support/fast_vs_reference.h"): the fast renderer
// (src/realtime) against the reference light-field renderer (src/render) on one light field and
// camera. The caller links pl_realtime, pl_render, pl_image.
#include "accel/accel.h"
#include "camera/camera.h"
#include "image/compare.h"
#include "lightfield/lightfield.h"
#include "realtime/realtime.h"
#include "render/render.h"

namespace pl::test_support {

/// Both renderers' pictures at `samplesPerPixel`, compared (the fast one against the reference).
inline ImageComparison fastAgainstReferenceRenderer(const LightField& lf, const Accel& accel, const Camera& camera,
                                                    int samplesPerPixel) {
  const FastRenderer fast(lf, accel);
  RenderSettings render;
  render.samplesPerPixel = samplesPerPixel;
  render.showProgress = false;
  return compareImages(fast.render(camera, render), renderLightField(lf, accel, camera, render));
}

}  // namespace pl::test_support
