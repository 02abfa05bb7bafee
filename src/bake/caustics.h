#pragma once
// Caustics (docs/design.md "Caustics"): the light that reaches a diffuse tixel from an
// emissive surface only through ideal-specular surfaces — mirrors, smooth glass, thin glass
// sheets (the light field's specular charts) — shot from the emitters as photons, instead of
// being found by the few gather rays whose specular chain happens to end on the emitter.
//
// The partition (so that nothing is counted twice): a path emissive triangle → specular+ →
// diffuse tixel, the emitter on a non-specular chart, is counted by this pass alone; the gather
// of a diffuse tixel then drops the emission its specular chains reach (propagation.cpp
// gatherEmission, viaMirror entries). Everything else is as before: direct light by shadow
// rays and gather (MIS), the sky through chains by the gather, glossy tixels gather emitters
// through chains themselves, and the scene's lights (point, spot, directional, sphere), which
// no gather ray finds, reach tixels by shadow rays only (through thin glass) — their light
// through mirrors and solid glass is not in the light field, nor in the path tracer. Sphere
// lights shoot photons too, but only those whose first hit is a mirror-like lobe count (the
// path tracer finds that light by next-event estimation at the lobe; they take the photons'
// share of the spheres' power, after the triangles' photon indices).
//
// Photons: N photons (BakeSettings::causticPhotons) from the emissive triangles, by the light
// sampler (light/light.h sampleEmitterPoint: a triangle ∝ power, a point uniform by area) and a
// cosine-weighted direction on the emitting side (one of the two, each with probability ½,
// when the material is two-sided): flux Φ = π·Le / (areaPdf · P(side) · N) (W). A photon
// whose first hit is not a specular chart is dropped (that light is direct); otherwise its
// chain is followed with the light field's own step (lookup.h followSpecular: the same
// stochastic branch, Beer–Lambert and roulette as the gather rays), its weight turned from
// radiance to flux (× η'² at a refraction of solid glass: flux is not compressed into a
// smaller solid angle as radiance is), up to settings.mirrorDepth steps. Where it lands on
// the front record of a diffuse chart (or the back record of a two-sided one) it is splatted
// over the 2×2 tixels of its bilinear footprint — the adjoint of the lookup a gather ray makes
// there — as irradiance w·Φ/(tixelSize²·coverage) (W·m⁻²) per tixel of weight w: the
// tent-kernel density estimate of the tixel's irradiance, whose kernel integrates to 1 over a
// fully covered chart. Landing on a glossy chart, or on a one-sided chart from behind, it
// deposits nothing.
//
// Determinism: photon i's numbers depend only on (seed, i) — an Owen-scrambled Sobol point
// for the emitter point and one from a shuffled index for the direction — and the deposits
// come back in photon order whatever the thread count.
#include <cstdint>
#include <vector>

#include "bake/parameterisation.h"
#include "light/light.h"

namespace pl {

class Accel;
class Progress;

/// One photon's contribution to one tixel.
struct CausticDeposit {
  uint64_t tixel = 0;
  Vec3 wi{0.0f};        ///< unit, world: the direction the light arrives from (towards the last specular hit)
  Rgb irradiance{0.0f}; ///< W·m⁻² added to the tixel's irradiance E
};

struct CausticPhotons {
  std::vector<CausticDeposit> deposits;  ///< in photon order
  uint64_t photons = 0;  ///< emitted
  uint64_t landed = 0;   ///< that reached a diffuse tixel through ≥ 1 specular surface
  uint64_t rays = 0;     ///< traced
  double seconds = 0.0;
};

/// Whether the scene has caustics for this pass to shoot: photons requested, an emissive
/// triangle and a specular chart.
bool shootsCaustics(const Parameterisation& param, const LightSampler& lights, const BakeSettings& settings);

/// Traces settings.causticPhotons photons (see the top of this file) with `lights` (the
/// scene's light sampler); nothing when !shootsCaustics. Parallel; `progress` (may be null)
/// advances by photons.
CausticPhotons traceCausticPhotons(const Scene& scene, const Accel& accel, const Parameterisation& param,
                                   const LightSampler& lights, const BakeSettings& settings, Progress* progress = nullptr);

}  // namespace pl
