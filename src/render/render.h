#pragma once
// The straightforward light-field renderer: the reference the fast renderer must match.
//
// Per camera sample: the primary hit (Embree, 16-wide packets per tile) → SurfaceHit → the
// hit triangle's chart → exitantRadiance() of lightfield/lookup.h (the one 16-neighbour
// lookup: bilinear in position × bilinear in paraboloid direction; diffuse charts get their
// albedo texture at the mip level of the sample's ray cone, lookup.h albedoTextureLod, or at
// full resolution with RenderSettings::textureLod off). Ideal-specular charts (mirrors, glass) store nothing:
// the view ray is reflected or refracted by followSpecular (lightfield/lookup.h: the
// mirror's reflectance; for glass one Fresnel branch chosen stochastically with the right
// weight), and followed, up to mirrorDepth steps; a chain longer than that contributes
// nothing, as in the bake. Rays that leave the scene see backgroundRadiance()
// (lightfield/render_settings.h).
//
// Pixel value = mean over the pixel's samples of (camera weight × radiance), in
// W·sr⁻¹·m⁻² (camera weight = cos⁴θ with vignetting, else 1). No exposure or tone mapping
// here: the caller writes the image through ViewSettings::writeImage (jobs/jobs.h), as
// `trace` does, so both renderers' files are directly comparable.
//
// Sampling: with one sample per pixel the ray goes through the pixel centre (and the lens
// centre); with N > 1 samples, sample k of pixel (x, y) takes its film and lens positions from
// pixelSample (render_settings.h: a ZSobol sequence, stratified per pixel), so an image
// depends on the seed only, never on the thread count.
#include <cstdint>

#include "core/math.h"
#include "image/image.h"
#include "lightfield/lightfield.h"
#include "lightfield/render_settings.h"

namespace pl {

class Accel;
class Camera;
struct RayHit;

/// Renders the light field from `camera` (camera.width() × camera.height() pixels). `accel`
/// must have been built over lightField.scene.
Image renderLightField(const LightField& lightField, const Accel& accel, const Camera& camera,
                       const RenderSettings& settings);

}  // namespace pl
