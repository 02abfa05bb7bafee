#pragma once
// Relighting (docs/design.md, Relighting): a baked light field changed for new light — a
// light's colour or intensity (off = black), a light moved or turned (a sun's direction, a
// point or spot light's position and axis), a material's emission, the environment, a
// Lambertian material's albedo — by re-propagating from the visibility field in memory,
// warm-started from the current solution, one iteration at a time. Geometry is not traced
// again, except the shadow rays and sun masks of a light that moved.
//
// What each change recomputes. The first shot is linear in the sources:
//     direct = Σ_l E_l ⊙ D_l + D_e,
// D_l scene light l's first shot at unit emission (shootShadowRays of that light alone, with
// its intensity or irradiance set to 1; E_l its emission, per channel) and D_e that of the
// emissive surfaces and the environment (their shadow rays, gatherEmission, caustics). So
//   * a light's colour or intensity traces nothing: direct is recombined;
//   * a light that moved or turned gets its D_l again — a sun-masked light (lightfield.h "Sun
//     masks") its masks first (recomputeSunMasks), the rest of its D_l is those masks on
//     diffuse tixels and shadow rays from glossy ones;
//   * an emission or environment change gets D_e again, but when the one emissive material of
//     a scene under a black environment is only recoloured (every sample, MIS weight and photon
//     stays the same) it is D_e scaled per channel;
//   * a Lambertian albedo changes the transport albedo of its tixels (the first shot of a
//     diffuse tixel is irradiance, which the albedo does not enter).
// Warm start: the iterate L of L = direct + M·L moves to max(0, L + direct_new − direct_old),
// or, when the new direct is the old one scaled per channel by one factor k (every source
// that is not black scaled by k), to k ⊙ L — the exact solution of the scaled problem, so a
// converged field stays converged. Then the bake's iteration and stopping rule
// (propagation.h iterateTransport, StoppingRule) run until the bake's tolerance.
//
// Refused, with the reason and the command that re-bakes (pl::Error, no state changed):
// geometry or anything else the visibility field depends on (visibilityHash), a material's
// model or any parameter but a Lambertian albedo, an emission texture or emission turned on
// where the charts would differ (curved charts, which emitters do not get), a light added,
// removed or of another type, and a light that would light the back of a one-sided open
// surface under a black environment (the bake would have given it a back side).
// Changes the stored field serves approximately: turning an emitter off keeps its planar
// charts (a fresh bake might curve them), and a light that no longer lights a two-sided
// chart's back keeps the back record (its values go to 0).
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "bake/parameterisation.h"
#include "bake/visibility.h"
#include "lightfield/lightfield.h"

namespace pl {

/// After an iteration of Relighter::relight (iteration 0: the first shot is updated and the
/// warm start made, before any iteration: the first frame that shows the change).
struct RelightProgress {
  uint32_t iteration = 0;
  double residual = 0.0;   ///< StoppingRule's |ΔP|/P of this iteration (0 at iteration 0)
  bool converged = false;
  double seconds = 0.0;    ///< since relight() started
};
/// Returns false to stop (the state stays consistent; the next relight() goes on from it).
using RelightCallback = std::function<bool(const RelightProgress&)>;

/// What one relight() did, stage by stage (seconds).
struct RelightStats {
  uint32_t lightsShot = 0;        ///< lights whose D_l was traced again
  uint32_t sunMasksTraced = 0;    ///< masked lights whose masks were traced again
  bool emittersShot = false;      ///< D_e traced again
  bool emittersScaled = false;    ///< D_e scaled per channel instead
  bool scaledWarmStart = false;   ///< warm start by k ⊙ L (else L + Δdirect)
  double sunMaskSeconds = 0.0;
  double firstShotSeconds = 0.0;  ///< the lights' and emitters' first shot (sun masks excluded)
  double warmStartSeconds = 0.0;  ///< albedo, combining direct, warm start, transport refresh
  double firstFrameSeconds = 0.0; ///< all of the above: until iteration 0's callback
  uint32_t iterations = 0;
  double residual = 0.0;
  bool converged = false;
  bool cancelled = false;
  double seconds = 0.0;           ///< the whole relight()
};

/// A light field being relit: the scene, parameterisation, BVH, visibility field and the
/// transport state of its propagation, and the current solution. Edits are recorded by the
/// set… calls (checked at once) and applied by relight().
class Relighter {
 public:
  /// From a light field (its scene, settings and values: the warm start) and its visibility
  /// field (the whole field). The parameterisation is rebuilt (deterministic: the bake's), or
  /// taken when given. Throws pl::Error when the field or the values do not belong to the
  /// light field. `log` receives one-line notes (may be empty).
  Relighter(const LightField& lightField, VisibilityShard visibility,
            const std::function<void(const std::string&)>& log = {});
  Relighter(const LightField& lightField, VisibilityShard visibility, Parameterisation param,
            const std::function<void(const std::string&)>& log = {});
  /// The same with the visibility field read from `visibilityPath` (a .plv); pl::Error naming
  /// it when it is missing or was traced for another scene or settings. The parameterisation's
  /// charts are rebuilt (buildCharts: about a second on Crytek Sponza) and its tixel setup read
  /// from the .plt the bake wrote beside the .plv, keyed against the light field's scene
  /// (parameterisation.h reuseTixelSetup: a changed material's charts filled again, a moved
  /// sun's masks traced again; a .plt without keys taken as it is, readTixelSetup), or, when
  /// there is none for this .plv, filled again (fillTixels: minutes on a large scene; `log`
  /// says why). The first shot by source is read from the .pls beside the .plv when one was
  /// written for this light field (bake/first_shot.h), else shot (`log` says why when a file
  /// is there but does not fit); when it is read, the field itself is read (and checked) only
  /// when a relight() first gathers through it — an iteration, or D_e shot again — its header
  /// checked at once, so an edit that needs no iteration never decodes it. The field is held decoded (VisibilityShard::decoded, decoded as it is checked:
  /// every iteration's gather then reads it directly) when that takes at most `decodedBudget`
  /// bytes (bake.h decodedFieldBudget); 0: kept compact.
  Relighter(const LightField& lightField, const std::string& visibilityPath,
            const std::function<void(const std::string&)>& log = {}, uint64_t decodedBudget = 0);
  ~Relighter();
  Relighter(Relighter&&) noexcept;
  Relighter& operator=(Relighter&&) noexcept;

  /// The scene with every edit so far (applied or pending).
  const Scene& scene() const;
  /// The parameterisation (its sun masks follow the applied edits).
  const Parameterisation& parameterisation() const;

  /// Light `index`'s emission (intensity or irradiance; black = off).
  void setLightEmission(uint32_t index, const Rgb& emission);
  /// Light `index` replaced by `light` (the same type).
  void setLight(uint32_t index, const Light& light);
  /// Material `index`'s emitted radiance.
  void setEmission(uint32_t material, const Rgb& emission);
  /// A Lambertian material's albedo.
  void setAlbedo(uint32_t material, const Rgb& albedo);
  /// Every difference between `edited` and scene() (lights, emission, albedo, environment),
  /// after checking that nothing else the light field depends on changed.
  void setScene(const Scene& edited);
  /// Whether edits wait for relight().
  bool pending() const;

  /// Applies the pending edits and iterates to the bake's tolerance (or maxIterations, or
  /// until onIteration returns false). With nothing pending and a converged state it returns
  /// at once. Not thread-safe against the set… calls or update().
  RelightStats relight(const RelightCallback& onIteration = {});

  /// Writes the current solution into `lf` (a light field of the same scene and
  /// parameterisation): values, sun masks, and the scene's lights, materials and environment.
  void update(LightField& lf) const;
  /// Writes the first shot by source of the scene the last relight() applied (no edit pending)
  /// as a .pls file (bake/first_shot.h), which a Relighter of the resulting light field reads
  /// instead of shooting again. Throws pl::Error when edits are pending or it cannot write.
  void saveFirstShot(const std::string& path) const;
  /// Whether the constructor read the first shot by source from a .pls instead of shooting it.
  bool firstShotRead() const;
  /// The current solution as a light field (a copy of the scene and charts).
  LightField lightField() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Where `plenoptic bake -o X.plf` saves the visibility field: X.plv.
std::string visibilityPathFor(const std::string& plfPath);
/// The command that re-bakes `scene` with `settings` (for the refusals' messages).
std::string rebakeCommand(const Scene& scene, const BakeSettings& settings);

}  // namespace pl
