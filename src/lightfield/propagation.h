#pragma once
// Propagation (DESIGN.md "Light-field pipeline" step 3; seed slides 8, 18–27): solves
// L = Le + M L over the parameterised surfaces by a Neumann series, with the transport operator
// M split into gathering through the visibility field and a local BRDF operator per tixel.
//
// Quantities per tixel (the LightField value layout):
//   diffuse  irradiance E (W·m⁻²); its transport radiance is ρ̄·E/π, ρ̄ the footprint albedo;
//   glossy   exitant radiance per paraboloid texel, without emission during the iteration
//            (emission is added when the values are written out).
//
// First shot (constant over the iteration, "direct"):
//   * point, spot and directional lights: shadow rays from every tixel's gather point;
//   * emissive surfaces: areaLightSamples shadow rays per tixel towards emissive triangles
//     (chosen ∝ area·luminance(Le)) combined by the power heuristic with the gather rays
//     that hit emitters directly (emitters seen through mirrors come through the gather only);
//   * the environment (Environment::radiance of the leaving direction) through gather rays
//     that escape, directly or after mirrors.
// Iteration (block Gauss–Seidel over batches of whole charts, over-relaxed with ω = 1.2,
// deterministic; see the .cpp):
// R ← direct + M R, where M gathers the transport radiance of the seen
// tixels (bilinear over 2×2 tixels, and for glossy targets bilinear over 2×2 directional
// texels) and applies the local operator:
//   diffuse  E = (π/N) Σ_k L_k                      (each gather cell has projected solid angle π/N)
//   glossy   Lo(c) = Σ_k W[c][k] L_k,  W[c][k] = mean over output texel c of ∫_cell k f cos θ dω
//            (precomputed per material by sub-sampling both the output texel and the cell,
//            and applied as a constant floor plus a sparse lobe, which keeps each row's sum)
//   rough glass  as glossy, on each record (front, back) the reflection of its own gather
//            plus the transmission of its twin record's: Lo_s = R_s L_s + T_s L_other
//            (GlossyMaterial in the .cpp); first-shot lights on both sides of the surface
//   mirror   already folded into the visibility field (a reordering of what is seen).
// Gather rays that arrive at a two-sided chart from behind see its back record (facingChart);
// those that hit a one-sided chart from behind (the inside of a closed solid) bring no
// reflected light, only two-sided emission (lightfield.h "Sides").
// It stops when the relative change of the total outgoing power Σ area·(exitant flux density)
// drops below the tolerance and so does the error this leaves, estimated from the L1 change
// of the values and its measured rate of convergence (see the .cpp), or at maxIterations.
#include "lightfield/parameterisation.h"
#include "lightfield/visibility.h"

#include <functional>
#include <vector>

namespace pl {

class Accel;

struct PropagationResult {
  std::vector<Rgb> values;  ///< in LightField::values layout, emission included for glossy charts
  uint32_t iterations = 0;
  double residual = 0.0;    ///< relative change of total outgoing power at the last iteration
  double seconds = 0.0;
  double firstShotSeconds = 0.0;  ///< of `seconds`: operators, shadow rays, constant gather part
  uint64_t shadowRays = 0;
};

PropagationResult propagate(const Scene& scene, const Accel& accel, const Parameterisation& param,
                            const VisibilityField& visibility, const BakeSettings& settings);

/// The same, with the visibility field supplied late: `visibility` is called once, after the
/// shadow rays of the first shot (which do not need the field), so that reading a saved field
/// can overlap them. Its field must have param.tixelCount tixels and the settings' gather grid.
/// The time spent inside `visibility` is excluded from `seconds` and `firstShotSeconds`.
PropagationResult propagate(const Scene& scene, const Accel& accel, const Parameterisation& param,
                            const std::function<const VisibilityField&()>& visibility, const BakeSettings& settings);

/// The glossy operator W of one material for an R-texel output map and an m × m gather grid:
/// R² × m² RGB weights, row c (output texel a + b·R) times column k (gather cell).
/// For rough glass (lightfield.h "Rough glass") the output map and the gather grid may each
/// belong to the back record (outputOnBack, gatherOnBack: directions turned into the BSDF's
/// frame by glassBsdfDirection): reflection on the front (false, false) or back (true, true),
/// transmission into the front of the light the back gathers (false, true) and into the back
/// of the front's (true, false). Other models use (false, false) for either record.
std::vector<Rgb> glossyOperator(const Bsdf& bsdf, uint32_t dirRes, uint32_t gridSide, bool outputOnBack = false,
                                bool gatherOnBack = false);

}  // namespace pl
