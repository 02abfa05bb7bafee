#pragma once
// Propagation (docs/design.md, Propagation; seed slides 8, 18–27): solves
// L = Le + M L over the parameterised surfaces by a Neumann series, with the transport operator
// M split into gathering through the visibility field and a local BRDF operator per tixel.
//
// Quantities per tixel (the LightField value layout):
//   diffuse  irradiance E (W·m⁻²); its transport radiance is ρ̄·E/π, ρ̄ the footprint albedo;
//   glossy   exitant radiance per paraboloid texel, without emission during the iteration
//            (emission is added when the values are written out).
//
// First shot (constant over the iteration, "direct"):
//   * the scene's lights (light/lights.h): shadow rays from every tixel's gather point, one
//     towards a delta light, max(1, areaLightSamples) sampled ones towards any other;
//   * emissive surfaces: areaLightSamples shadow rays per tixel towards emissive triangles
//     (chosen ∝ area·luminance(Le)) combined by the power heuristic with the gather rays
//     that hit emitters directly (emitters seen through mirrors and glass come through the
//     gather only, or on diffuse tixels through the caustic pass below);
//   * the environment (Environment::radiance of the leaving direction) through gather rays
//     that escape, directly or after mirrors;
//   * caustics (caustics.h): photons from the emissive surfaces through mirrors and glass,
//     deposited as irradiance on diffuse tixels, whose gather then leaves out the emission its
//     mirror and glass chains reach (the partition is in caustics.h).
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
#include "bake/first_shot.h"
#include "bake/parameterisation.h"
#include "bake/resume.h"
#include "bake/visibility.h"

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

namespace pl {

class Accel;
class Progress;

struct PropagationResult {
  std::vector<Rgb> values;  ///< in LightField::values layout, emission included for glossy charts
  std::vector<Rgb> direct;  ///< the first shot (this rank's view after the exchange)
  /// The first shot by source (bake/first_shot.h), when PropagationOptions::keepFirstShotBySource
  /// asked for it and the first shot was shot (not resumed from a checkpoint).
  std::optional<FirstShotBySource> firstShotBySource;
  uint32_t iterations = 0;
  double residual = 0.0;    ///< relative change of total outgoing power at the last iteration
  double seconds = 0.0;
  double firstShotSeconds = 0.0;  ///< of `seconds`: operators, shadow rays, constant gather part
  uint64_t shadowRays = 0;         ///< of every rank
  // Distributed propagation (0 in one process): what this rank received from the others and
  // the time it spent in the exchanges (waiting for the slowest rank included).
  uint64_t exchangeBytes = 0;
  double exchangeSeconds = 0.0;
  /// Of `seconds`: in gatherIteration (the part of an iteration that the ranks share; the rest
  /// — transport refresh, change, power sums — every rank does for all tixels).
  double gatherSeconds = 0.0;
  /// Of `seconds`: in the iteration, the work every rank does for all tixels whoever updated
  /// them — the transport refresh, the change of the other ranks' tixels, the copy of the
  /// starting values and the power sums of the stopping rule (measured, not derived).
  double repeatedSeconds = 0.0;
  uint64_t causticPhotons = 0, causticPhotonsLanded = 0;  ///< the caustic pass's (caustics.h)
  double causticSeconds = 0.0;                            ///< of firstShotSeconds
  /// The subsurface operator (subsurface.h; all 0 without subsurface charts): its build time
  /// (of firstShotSeconds, its exchange included), tixels, walks (every rank's, and this
  /// rank's share), their rays, its entries and bytes.
  double subsurfaceSeconds = 0.0;
  uint64_t subsurfaceTixels = 0, subsurfaceWalks = 0, subsurfaceWalkedHere = 0, subsurfaceRays = 0, subsurfaceEntries = 0,
           subsurfaceBytes = 0;
};

PropagationResult propagate(const Scene& scene, const Accel& accel, const Parameterisation& param,
                            const VisibilityField& visibility, const BakeSettings& settings);

class Communicator;
struct ShardPlan;
struct TransportState;

/// The same, with the visibility field supplied late: `visibility` is called once, after the
/// shadow rays of the first shot (which do not need the field), so that reading a saved field
/// can overlap them. Its field must have param.tixelCount tixels and the settings' gather grid.
/// The time spent inside `visibility` is excluded from `seconds` and `firstShotSeconds`.
PropagationResult propagate(const Scene& scene, const Accel& accel, const Parameterisation& param,
                            const std::function<const VisibilityField&()>& visibility, const BakeSettings& settings);

/// What a propagation keeps and where it starts: saving and resuming the iteration (resume.h;
/// docs/design.md, Resuming an interrupted bake) and the first shot by source.
struct PropagationOptions {
  /// Start after this checkpoint's iterations, from its first shot and iterate, instead of
  /// shooting the first shot (the visibility field is still obtained). Null: from the start.
  const PropagationCheckpoint* from = nullptr;
  /// Called after every iteration (the last included) with where the propagation stands and
  /// its state, whose direct, punctualGlossy and current arrays a checkpoint keeps. May be empty.
  std::function<void(const PropagationProgress&, const TransportState&)> save;
  /// Keep the first shot by source in PropagationResult::firstShotBySource (one process: the
  /// arrays of this rank's tixels only otherwise). Each scene light's at unit emission and the
  /// rest's: (lights × 2 + 1) × values × 12 bytes more at most.
  bool keepFirstShotBySource = false;
};

/// One rank of a distributed propagation (shard.h): this rank (comm.rank() of plan.ranks)
/// shoots the first shot of its own tixels, gathers through its shard of the field and updates
/// its part of every batch; after each batch the parts are exchanged (comm.allgatherv of the
/// values), so every rank holds all values, computes the stopping rule from them itself (the
/// same sums in the same order: no reduction is needed) and returns the same values — the
/// single-process result, bit for bit. `visibility` must hold visibilityRanges(plan, rank).
/// Only rank 0 should show progress bars (Progress::setEnabled).
PropagationResult propagate(const Scene& scene, const Accel& accel, const Parameterisation& param,
                            const std::function<const VisibilityShard&()>& visibility, const BakeSettings& settings,
                            Communicator& comm, const ShardPlan& plan, const PropagationOptions& options = {});

/// Batches of whole charts in tixel order, each ≥ 2048 tixels (and at most ~16000 of them):
/// batch b is tixels [result[b], result[b + 1]).
std::vector<uint64_t> propagationBatches(const Parameterisation& param);

// ---- The stages, over an explicit transport state -------------------------------------------
// propagate() above is: TransportState → shootShadowRays (all tixels) → [the visibility field]
// → gatherEmission (all tixels) → shootCaustics → finishFirstShot → beginIteration → per iteration, for each
// batch of state.batchStart: gatherIteration + updateTransport → finishTransport. Every stage that
// works per tixel takes a range [begin, end) of tixel indices, so that a distributed bake can
// shard the tixels: the results for a range depend only on the state, never on the other
// ranges being run or on thread timing (the first shot is per tixel; an iteration update of
// a range reads the other ranges' current values and its own previous ones).

/// What the stages share. Values are in LightField::values layout.
struct TransportState {
  /// Builds the glossy operators, the light sampler, the batches and the subsurface operator
  /// (subsurface.h; its walks split between the ranks of `comm` when given, which makes this a
  /// collective); `direct` all zero. The scene, accel and parameterisation must outlive the state.
  TransportState(const Scene& scene, const Accel& accel, const Parameterisation& param, const BakeSettings& settings,
                 Communicator* comm = nullptr);
  ~TransportState();
  TransportState(const TransportState&) = delete;
  TransportState& operator=(const TransportState&) = delete;

  const Scene& scene;
  const Accel& accel;
  const Parameterisation& param;
  const BakeSettings settings;
  uint32_t gridSide = 0, n = 0;    ///< gather grid side, gather directions per tixel (n = side²)
  std::vector<Rgb> direct;          ///< the first shot, constant over the iteration (glossy: no emission)
  /// The part of `direct` that punctual lights reflect directly off glossy charts other than
  /// rough glass (BakeSettings::punctualHighlights; empty when there is none): transported like
  /// the rest, then taken out of the stored maps by finishTransport (lightfield.h "Punctual
  /// highlights"). Exchanged between ranks like `direct`.
  std::vector<Rgb> punctualGlossy;
  std::vector<Rgb> current;         ///< the iterate (from beginIteration on)
  std::vector<Rgb> previousValues;  ///< current as it was before this iteration (needed with glossy charts)
  std::vector<float> change;        ///< per tixel, |Δ exitance| of its last update (W·m⁻², luminance)
  std::atomic<uint64_t> shadowRays{0};
  /// Whether the caustic pass runs (caustics.h shootsCaustics): diffuse tixels' gather then
  /// leaves out emission reached through mirrors and glass.
  bool caustics = false;
  uint64_t causticPhotons = 0, causticPhotonsLanded = 0;  ///< shootCaustics's
  double causticSeconds = 0.0;
  std::vector<uint64_t> batchStart;  ///< propagationBatches(param)

  struct Operators;  ///< glossy operators, lights, transport quads (propagation.cpp)
  std::unique_ptr<Operators> ops;
};

/// Which sources shootShadowRays shoots: by default every scene light and the emissive
/// surfaces; the first shot by source (shootFirstShot, relight.h) shoots each light on its own.
struct ShadowRaySources {
  std::vector<uint8_t> lights;  ///< per scene light, whether it is shot; empty = every one
  bool emitters = true;         ///< the emissive surfaces' light samples
  bool unitEmission = false;    ///< the lights shot as if their emission were 1 (D_l of relight.h)
};

/// The first shot from its parts by source: Σ_l E_l ⊙ perLight[l] over the scene lights in
/// order (E_l = lightEmission; a black light or an empty array adds nothing), then + `rest`
/// when not empty — the one order of these sums, so that a bake's first shot and a relight's
/// of the same parts are equal bit for bit.
std::vector<Rgb> combineFirstShot(const Scene& scene, const std::vector<std::vector<Rgb>>& perLight,
                                  const std::vector<Rgb>& rest);

/// First shot, shadow rays: the scene's lights and emissive surfaces seen from
/// tixels [begin, end) are added to state.direct. Needs no visibility field. Advances
/// `progress` (may be null) by the tixels done.
void shootShadowRays(TransportState& state, uint64_t begin, uint64_t end, Progress* progress = nullptr,
                     const ShadowRaySources& sources = {});
/// Sun masks (lightfield.h): the slot of scene light `light` among param.sunMaskLights, or −1.
int sunMaskSlot(const Parameterisation& param, uint32_t light);
/// What masked light `light` (slot `slot`) adds to diffuse tixel `tixel`'s irradiance in the
/// first shot: its irradiance × max(0, cos θ) at the tixel's normal × the lit fraction of the
/// tixel's mask (W·m⁻²).
Rgb sunMaskedIrradiance(const Parameterisation& param, const Light& light, uint64_t tixel, size_t slot);
/// Takes the masked lights' first shot (sunMaskedIrradiance) back out of every diffuse
/// tixel's final irradiance: the light field stores the rest, and the renderers add those
/// lights at each point through the masks (lightfield.h "Sun masks"). Clamped at 0.
void removeSunMaskedDirect(const Scene& scene, const Parameterisation& param, std::vector<Rgb>& values);
/// The charts, values and sun masks of `lf` from the parameterisation and the propagated
/// values (moved out of `values`): the masked lights leave the stored irradiance
/// (removeSunMaskedDirect) and go with the masks. lf.scene must be the propagation's scene.
void storeLightField(LightField& lf, const Parameterisation& param, std::vector<Rgb>&& values);
/// First shot, gather: emission and environment arriving along the gather rays of tixels
/// [begin, end) are added to state.direct. Throws pl::Error when `vis` does not hold the range
/// or has another gather grid.
void gatherEmission(TransportState& state, const VisibilityShard& vis, uint64_t begin, uint64_t end);
/// First shot, caustics (caustics.h): traces the photons and adds their irradiance to the
/// diffuse tixels they land on in state.direct (and to their tilted irradiances on
/// directionalIrradiance charts). The photons land anywhere, so every rank of a distributed
/// bake shoots all of them (the same ones) and adds them to every tixel. Nothing unless
/// state.caustics. Advances `progress` (may be null) by photons.
void shootCaustics(TransportState& state, Progress* progress = nullptr);
/// Ends the first shot once every range has gathered: each rough-glass record adds the
/// transmission of what its twin gathered.
void finishFirstShot(TransportState& state);
/// Starts the iteration: checks direct is finite, current = direct, every tixel's transport.
void beginIteration(TransportState& state);
/// One update of tixels [begin, end): current ← max(0, current + ω·(direct + M·current −
/// current)), over-relaxation ω = omega; state.change gets each tixel's change. Charts
/// overlapping the range are looked up at state.previousValues (Jacobi inside the range, so no
/// value is read while it is written), the others at current (Gauss–Seidel between ranges).
/// Diffuse charts are looked up through their transport, refreshed by updateTransport.
/// A range that is only part of a batch (a rank's part) gives its tixels the same values as
/// the whole batch would: the batch's other glossy charts, not yet updated, still hold their
/// previous values in current. `vis` must hold [begin, end) (and rough-glass twins).
void gatherIteration(TransportState& state, const VisibilityShard& vis, uint64_t begin, uint64_t end, float omega);
/// state.change of tixels [begin, end) from `before` (the values at the start of the
/// iteration) to current: what gatherIteration stores, for the tixels another rank updated.
void recomputeChange(TransportState& state, const std::vector<Rgb>& before, uint64_t begin, uint64_t end);
/// Refreshes the transport (the bilinear interpolants of ρ̄E/π) of tixels [begin, end) from current.
void updateTransport(TransportState& state, uint64_t begin, uint64_t end);
/// A change `delta` of the first shot (per value, as state.direct) made the change of the values
/// it causes at once, for a relighting's warm start: on subsurface tixels the change of the
/// irradiance entering them leaves through the object, K·delta/ρ̄ (applySubsurface's
/// convention); every other value keeps its delta. Nothing without subsurface charts.
void subsurfaceDirectChange(const TransportState& state, std::vector<Rgb>& delta);
/// Σ area × exitance luminance of `values` (W): the total outgoing power the stopping rule watches.
double transportPower(const TransportState& state, const std::vector<Rgb>& values);
/// Σ area × state.change (W): the L1 change of the last iteration.
double transportChange(const TransportState& state);
/// Rebuilds what the first shot derives from the scene's emissive surfaces (the light sampler,
/// its area densities, whether caustics are shot) after their emission changed (relight.h).
void refreshEmitters(TransportState& state);

/// Over-relaxation of the iteration (SOR; the .cpp explains the choice).
inline constexpr float kOverRelaxation = 1.2f;

/// When to stop. The residual is the relative change of the total outgoing power, |ΔP| / P,
/// and iteration stops once it is below the tolerance — and once, too, the error that remains is:
///   * with over-relaxation, changes of opposite sign in different tixels could cancel in ΔP
///     while the values still swing, so the L1 change δ = Σ area·|Δ exitance| / P is tracked
///     (for plain Gauss–Seidel every change is ≥ 0 and δ = |ΔP|/P);
///   * the error left after a change δ is the rest of a geometric series, δ·ρ̂/(1 − ρ̂), with
///     ρ̂ = δ_k / δ_{k−1} the measured contraction: below δ while ρ̂ < ½, but 9·δ for a bright
///     closed scene converging at ρ̂ = 0.9, where the last change alone would stop too early.
/// Both |ΔP|/P and δ·ρ̂/(1 − ρ̂) must be below the tolerance. It also owns ω, which falls back to
/// 1 when δ grows after the second iteration.
class StoppingRule {
 public:
  StoppingRule(double startPower, float tolerance) : previousPower_(startPower), tolerance_(tolerance) {}
  /// The rule as it stood after the iterations of `at` (a resumed propagation, resume.h).
  StoppingRule(const PropagationProgress& at, float tolerance)
      : previousPower_(at.previousPower), previousL1Change_(at.previousL1Change), tolerance_(tolerance), omega_(at.omega) {}
  /// Its state, for a checkpoint: previous power and L1 change, and ω (into `at`).
  void save(PropagationProgress& at) const {
    at.previousPower = previousPower_;
    at.previousL1Change = previousL1Change_;
    at.omega = omega_;
  }

  /// After iteration `iteration` (from 1) with total power `power` and L1 change `changed`
  /// (transportPower, transportChange): sets result.iterations and result.residual, and
  /// whether to stop.
  bool converged(uint32_t iteration, double power, double changed, PropagationResult& result) {
    const double l1Change = power > 0.0 ? changed / power : 0.0;
    if (iteration > 2 && l1Change > previousL1Change_) omega_ = 1.0f;
    const double contraction = previousL1Change_ > 0.0 ? l1Change / previousL1Change_ : 1.0;
    const double remainingError = l1Change == 0.0 ? 0.0 : (contraction < 1.0 ? l1Change * contraction / (1.0 - contraction) : kInfinity);
    result.iterations = iteration;
    result.residual = power > 0.0 ? std::abs(power - previousPower_) / power : 0.0;
    previousPower_ = power;
    previousL1Change_ = l1Change;
    return result.residual < tolerance_ && remainingError < tolerance_;
  }
  /// The over-relaxation of the next iteration.
  float omega() const { return omega_; }

 private:
  double previousPower_, previousL1Change_ = 0.0;
  float tolerance_;
  float omega_ = kOverRelaxation;
};

/// Whether the iteration keeps state.previousValues (the parameterisation has glossy charts).
bool keepsPreviousValues(const Parameterisation& param);
/// One iteration of one process, as propagate() runs it: every batch in order, gathered
/// (gatherIteration with over-relaxation `omega`) and its transport refreshed. Starts from
/// state.current and the transport quads as they are (beginIteration, or a warm start whose
/// quads updateTransport refreshed).
void iterateTransport(TransportState& state, const VisibilityShard& vis, float omega);

/// Ends the propagation: glossy values get their emission. state.current is then the result.
void finishTransport(TransportState& state);
/// finishTransport's step on `values` (an iterate in state.current's layout) instead of state.current.
void finishValues(const TransportState& state, std::vector<Rgb>& values);

/// A reflected lobe (Blinn-Phong, GGX) whose full width at half maximum spans fewer than
/// kNarrowLobeSubsamples of glossyOperator's cell sub-samples: its operator is built by
/// sampling the lobe, and the first shot's light samples read the BSDF from it per cell.
inline constexpr float kNarrowLobeSubsamples = 2.0f;
bool isNarrowLobe(const Bsdf& bsdf, uint32_t gridSide);

/// The glossy operator W of one material for an R-texel output map and an m × m gather grid:
/// R² × m² RGB weights, row c (output texel a + b·R) times column k (gather cell).
/// For rough glass (lightfield.h "Rough glass") the output map and the gather grid may each
/// belong to the back record (outputOnBack, gatherOnBack: directions turned into the BSDF's
/// frame by glassBsdfDirection): reflection on the front (false, false) or back (true, true),
/// transmission into the front of the light the back gathers (false, true) and into the back
/// of the front's (true, false). Other models use (false, false) for either record.
/// A lobe narrower than the sub-samples that glossyOperator integrates each cell with
/// (reflected FWHM below kNarrowLobeSubsamples of their spacing) is integrated by
/// importance-sampling the lobe instead (isNarrowLobe): reflecting models only.
std::vector<Rgb> glossyOperator(const Bsdf& bsdf, uint32_t dirRes, uint32_t gridSide, bool outputOnBack = false,
                                bool gatherOnBack = false);

}  // namespace pl
