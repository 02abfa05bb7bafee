#pragma once
// The straightforward light-field renderer: the reference the fast renderer must match.
//
// Per camera sample: the primary hit (Embree, 16-wide packets per tile) → SurfaceHit → the
// hit triangle's chart → exitantRadiance() of lightfield/lookup.h (the one 16-neighbour
// lookup: bilinear in position × bilinear in paraboloid direction; diffuse charts get their
// albedo texture at full resolution). Ideal-specular charts (mirrors, glass) store nothing:
// the view ray is reflected or refracted by followSpecular (lightfield/lookup.h: the
// mirror's reflectance; for glass one Fresnel branch chosen stochastically with the right
// weight), and followed, up to mirrorDepth steps; a chain longer than that contributes
// nothing, as in the bake. Rays that leave the scene see backgroundRadiance().
//
// Pixel value = mean over the pixel's samples of (camera weight × radiance), in
// W·sr⁻¹·m⁻² (camera weight = cos⁴θ with vignetting, else 1). No exposure or tone mapping
// here: the caller writes the image through app/view_options (ViewOptions::writeImage), as
// `trace` does, so both renderers' files are directly comparable.
//
// Sampling: with one sample per pixel the ray goes through the pixel centre (and the lens
// centre); with N > 1 samples, sample k of pixel p uses the random stream
// Pcg32::forKey(p, k, seed) for a jittered film position and a lens position, so an image
// depends on the seed only, never on the thread count.
#include <cstdint>

#include "core/math.h"
#include "image/image.h"
#include "lightfield/lightfield.h"

namespace pl {

class Accel;
class Camera;
struct Environment;
struct RayHit;

struct RenderSettings {
  /// Camera samples per pixel; 0 = automatic: 1 (pixel centre) for a pinhole camera,
  /// kThinLensSamples for a thin lens (its defocus blur needs several aperture samples).
  int samplesPerPixel = 0;
  static constexpr int kThinLensSamples = 16;
  static constexpr int kMaxSamplesPerPixel = 1 << 16;  ///< upper bound the commands accept
  /// Mirror reflections followed; -1 = the bake's own BakeSettings::mirrorDepth, so the
  /// render sees exactly the chains the propagation accounted for.
  int mirrorDepth = -1;
  static constexpr int kMaxMirrorDepth = 1000;  ///< upper bound the commands accept
  uint64_t seed = 0;
  int tileSize = 16;  ///< square tiles rendered in parallel
  bool showProgress = false;  ///< progress bar (for single large renders, not timing loops)
};

/// Renders the light field from `camera` (camera.width() × camera.height() pixels). `accel`
/// must have been built over lightField.scene.
Image renderLightField(const LightField& lightField, const Accel& accel, const Camera& camera,
                       const RenderSettings& settings);

/// Radiance from infinity towards −direction for a ray leaving the scene along `direction`.
/// The only place the renderer reads the environment (an environment map plugs in here).
Rgb backgroundRadiance(const Environment& environment, const Vec3& direction);

}  // namespace pl
