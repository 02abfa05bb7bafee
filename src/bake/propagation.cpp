// Propagation: first shot + Neumann-series iteration (see propagation.h).
#include "bake/propagation.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <variant>

#include "accel/accel.h"
#include "bake/bake.h"
#include "bake/caustics.h"
#include "bake/shard.h"
#include "bake/subsurface.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/timing.h"
#include "core/progress.h"
#include "core/sampler.h"
#include "core/sampling.h"
#include "core/simd4.h"
#include "distributed/communicator.h"
#include "light/light.h"
#include "lightfield/lookup.h"
#include "lightfield/paraboloid.h"

namespace pl {

namespace {

// Sub-samples per side of an output texel (directions averaged over the texel's part inside the
// disk) and of a gather cell (directions averaged over the cell) for the glossy operator.
constexpr int kOutputSubsamples = 3;
constexpr int kCellSubsamples = 4;

/// Directions sub-sampling output texel (a, b) of an R-texel map, inside the disk only; the
/// texel's representative direction when none of them is inside.
std::vector<Vec3> outputTexelDirections(uint32_t a, uint32_t b, uint32_t res) {
  std::vector<Vec3> dirs;
  const float size = 2.0f / float(res);
  for (int y = 0; y < kOutputSubsamples; ++y)
    for (int x = 0; x < kOutputSubsamples; ++x) {
      const Vec2 st(-1.0f + (float(a) + (x + 0.5f) / kOutputSubsamples) * size,
                    -1.0f + (float(b) + (y + 0.5f) / kOutputSubsamples) * size);
      if (st.x * st.x + st.y * st.y < kHorizonRadius * kHorizonRadius) dirs.push_back(paraboloidToDirection(st));
    }
  if (dirs.empty()) dirs.push_back(paraboloidTexelDirection(a, b, res));
  return dirs;
}

/// f(wo, wi) for directions in a record's local frame: in the record's own frame, or, for a
/// rough-glass record (glass non-null), in its BSDF's frame (glassBsdfDirection).
Rgb recordEval(const Bsdf& bsdf, const Chart* glass, const Vec3& wo, const Vec3& wi) {
  if (!glass) return eval(bsdf, wo, wi);
  return eval(bsdf, glassBsdfDirection(glass->isBack, wo), glassBsdfDirection(glass->isBack, wi));
}

/// Mean of f(wo, wi) over the output texel's sub-sample directions (recordEval).
Rgb texelAverageBsdf(const Bsdf& bsdf, const std::vector<Vec3>& outputs, const Vec3& wi, const Chart* glass = nullptr) {
  Rgb sum(0.0f);
  for (const Vec3& wo : outputs) sum += recordEval(bsdf, glass, wo, wi);
  return sum / float(outputs.size());
}

/// The tixel of the other record of rough-glass tixel g (its twin: the back record follows
/// the front one, with the same grid).
uint64_t twinTixel(const Parameterisation& param, uint64_t g) {
  const uint32_t ci = param.tixelChart[g];
  const Chart& c = param.charts[ci];
  return param.charts[c.isBack ? ci - 1 : ci + 1].firstTixel + (g - c.firstTixel);
}

// Entries of a glossy operator row below this fraction of the row's largest (above-floor)
// entry are folded into the row's constant floor (see SparseOperator).
constexpr float kSparseThreshold = 1e-3f;

/// The glossy operator W (R² × N) stored as, per row c, a constant floor b_c (weights every
/// gather cell alike — the diffuse part of the BSDF and far-tail of the lobe) plus a sparse
/// list of the entries that rise above it (the lobe):  Lo(c) = b_c·Σ_k L_k + Σ_sparse w_k L_k.
/// Entries whose excess over the floor is below kSparseThreshold × the row's largest excess
/// are dropped and their sum is spread evenly over the floor, so every row keeps its exact
/// total (energy) and only a negligible amount of light is moved in angle. For a narrow lobe
/// this replaces N multiply-adds per output texel by a few dozen.
struct SparseOperator {
  std::vector<Lanes4> floor;        ///< per row
  std::vector<uint32_t> rowStart;   ///< R² + 1
  std::vector<uint32_t> column;     ///< gather cell k
  std::vector<Lanes4> weight;       ///< excess over the floor

  static SparseOperator fromDense(const std::vector<Rgb>& dense, uint32_t rows, uint32_t n) {
    SparseOperator op;
    op.floor.resize(rows);
    op.rowStart.push_back(0);
    for (uint32_t c = 0; c < rows; ++c) {
      const Rgb* row = dense.data() + size_t(c) * n;
      Rgb lo(kInfinity);
      for (uint32_t k = 0; k < n; ++k) lo = glm::min(lo, row[k]);
      float largest = 0.0f;
      for (uint32_t k = 0; k < n; ++k) largest = std::max(largest, maxComponent(row[k] - lo));
      Rgb dropped(0.0f);
      for (uint32_t k = 0; k < n; ++k) {
        const Rgb excess = row[k] - lo;
        if (maxComponent(excess) > kSparseThreshold * largest) {
          op.column.push_back(k);
          op.weight.push_back(lanes4(excess));
        } else {
          dropped += excess;
        }
      }
      op.floor[c] = lanes4(lo + dropped / float(n));
      op.rowStart.push_back(uint32_t(op.column.size()));
    }
    return op;
  }

  /// out[c] += Lo(c) for incoming radiance per gather cell (and its sum), lane-wise the same
  /// products and sums, in the same order, as floor·ΣL + Σ w·L in RGB.
  void apply(const Lanes4* incoming, F4 incomingSum, Rgb* out) const {
    for (size_t c = 0; c < floor.size(); ++c) {
      F4 sum = f4Mul(f4Load(floor[c].v), incomingSum);
      for (uint32_t e = rowStart[c]; e < rowStart[c + 1]; ++e)
        sum = f4Add(sum, f4Mul(f4Load(weight[e].v), f4Load(incoming[column[e]].v)));
      out[c] += f4Rgb(sum);
    }
  }
};

struct GlossyMaterial {
  uint32_t dirRes = 0;
  SparseOperator op;  ///< reflection (of a rough-glass material: the front record's)
  // Rough glass (isRoughGlassChart): the back record's reflection, and per side s (0 front,
  // 1 back) the transmission into that side of the light the other record gathers:
  //   Lo_s(c) = Σ_k R_s[c][k] L_s,k + Σ_k T_s[c][k] L_other,k,
  // each W[c][k] = mean over output texel c of ∫_cell k f |cos θ| dω with f the dielectric
  // BSDF in its own frame (glossyOperator's sides). f is the radiance form of bsdf.h, so T already
  // carries the 1/η'² by which radiance changes across the interface.
  bool glass = false;
  SparseOperator backReflection;
  SparseOperator transmission[2];
  const SparseOperator& reflection(const Chart& c) const { return glass && c.isBack ? backReflection : op; }
  // A narrow lobe (isNarrowLobe): per output texel and gather cell, the BSDF as the operator
  // sees it, constant over the cell: W[c][k] / ∫_cell k cos θ dω = W[c][k]·N/π. The first
  // shot's light samples use it, so that both strategies of its MIS estimate the same
  // cell-constant f, where f at the sample direction itself would be a spike or nothing.
  std::vector<Rgb> cellBsdf;
  uint32_t gridSide = 0;
  std::vector<std::vector<Vec3>> outputs;     ///< per output texel, its sub-sample directions
  std::vector<Vec3> centres;                  ///< per output texel, its representative direction
  std::vector<float> projectedSolidAngle;     ///< per output texel, ≈ Ω·cos θ (for the power sum)
  // The diffuse part of a model that has one (Chart::diffuseValue, lightfield.h): op above is
  // then the model without it (`specular`), and each tixel keeps Ẽ = Σ_k w_k L_k after its
  // map, w_k = ∫_cell k(μ) cos θ dω (diffuseDirectionalFactor). Its radiant exitance per unit
  // area is ρ·Ẽ·diffuseExitance, diffuseExitance = (1/π) Σ_k w_k = (1/π) ∫ k(μ) cos θ dω.
  bool diffuse = false;
  Bsdf specular;
  std::vector<Lanes4> diffuseWeight;  ///< w_k per gather cell
  Rgb diffuseExitance{0.0f};
  // Per-tixel f0 (perTixelSpecularF0: a metallic-roughness texture; not for narrow lobes,
  // whose operator is sampled): op above is the mapped model's at f0 = 0 and f0Slope the
  // change per unit f0 — Schlick's F = f0 (1 − m⁵) + f90 m⁵ is linear in f0 and nothing else
  // of the model depends on it — so that a tixel of f0 f reflects op·L + f ⊙ (f0Slope·L).
  bool tixelF0 = false;
  SparseOperator f0Slope;
  /// The lobe's model: the material's, or a bin's (below) with the bin's α. The first shot
  /// evaluates it (its diffuse part's k(μ) too).
  Bsdf model;
  // Per-tixel lobe widths (perTixelLobeWidth): the material's α bins (lobeAlphaBins,
  // ascending) and per bin the operators above built for the material's model with the bin's
  // α (outputs, centres and projectedSolidAngle stay the material's). A tixel takes the bin
  // nearest its Parameterisation::lobeAlpha (lobeAt); the material's own operators are then
  // not built.
  std::vector<float> binAlpha;
  std::vector<GlossyMaterial> bins;
  /// The operators of tixel g's lobe: its bin's, or the material's.
  const GlossyMaterial& lobeAt(const Parameterisation& param, uint64_t g) const {
    return bins.empty() ? *this : bins[nearestLobeBin(binAlpha, param.lobeAlpha[g])];
  }
  /// out[c] += Lo(c), the chart's reflection of incoming radiance (and its sum) at tixel g.
  void reflect(const Chart& c, const Parameterisation& param, uint64_t g, const Lanes4* incoming, F4 incomingSum,
               Rgb* out) const {
    reflection(c).apply(incoming, incomingSum, out);
    if (!tixelF0) return;
    thread_local std::vector<Rgb> slope;
    slope.assign(f0Slope.floor.size(), Rgb(0.0f));
    f0Slope.apply(incoming, incomingSum, slope.data());
    const Rgb f0 = param.specularF0[g];
    for (size_t t = 0; t < slope.size(); ++t) out[t] += f0 * slope[t];
  }
  /// The model the first shot evaluates for tixel g's map: the mapped model, with the tixel's
  /// f0 where it has its own.
  Bsdf mappedAt(const Bsdf& mapped, const Parameterisation& param, uint64_t g) const {
    return tixelF0 ? withSpecularF0(mapped, param.specularF0[g]) : mapped;
  }
  /// out[directionTexels] += Σ_k w_k L_k (a chart with a diffuse value; nothing otherwise).
  void addDiffuse(const Chart& c, const Lanes4* incoming, Rgb* out) const {
    if (!diffuse) return;
    F4 sum = f4Zero();
    for (size_t k = 0; k < diffuseWeight.size(); ++k) sum = f4Add(sum, f4Mul(f4Load(diffuseWeight[k].v), f4Load(incoming[k].v)));
    out[c.directionTexels()] += f4Rgb(sum);
  }
};

// ---- Rough glass (lightfield.h "Rough glass") -------------------------------------------------
/// The rough-glass operators of g (the front reflection, g.op, is already built): the back
/// record's reflection and the transmission into each side.
void addGlassOperators(GlossyMaterial& g, const Bsdf& bsdf, uint32_t gridSide) {
  const uint32_t rows = g.dirRes * g.dirRes, n = gridSide * gridSide;
  g.glass = true;
  g.backReflection = SparseOperator::fromDense(glossyOperator(bsdf, g.dirRes, gridSide, true, true), rows, n);
  g.transmission[0] = SparseOperator::fromDense(glossyOperator(bsdf, g.dirRes, gridSide, false, true), rows, n);
  g.transmission[1] = SparseOperator::fromDense(glossyOperator(bsdf, g.dirRes, gridSide, true, false), rows, n);
}

/// The light the rough-glass tixels gather in the first shot (emission and sky, constant over
/// the iteration), per gather cell, kept so that each record can transmit its twin's.
class GlassFirstShot {
 public:
  GlassFirstShot(const Scene& scene, const Parameterisation& param, uint32_t n) : n_(n), slotOfChart_(param.charts.size(), kNone) {
    uint64_t slots = 0;
    for (size_t ci = 0; ci < param.charts.size(); ++ci) {
      const Chart& c = param.charts[ci];
      if (!isRoughGlassChart(c, scene.materials[c.material].bsdf)) continue;
      slotOfChart_[ci] = slots;
      slots += c.tixelCount();
    }
    incoming_.resize(slots * n);
  }
  /// Where tixel g (of chart ci) keeps its n cells; null for tixels that are not rough glass.
  Lanes4* cells(const Parameterisation& param, uint64_t g) {
    const uint32_t ci = param.tixelChart[g];
    if (slotOfChart_[ci] == kNone) return nullptr;
    return incoming_.data() + (slotOfChart_[ci] + (g - param.charts[ci].firstTixel)) * n_;
  }
  /// Adds to every rough-glass tixel's first shot the transmission of what its twin gathered.
  void addTransmission(const Parameterisation& param, const std::vector<GlossyMaterial>& glossy, std::vector<Rgb>& direct) {
    if (incoming_.empty()) return;
    parallelFor(param.charts.size(), [&](uint64_t ci) {
      if (slotOfChart_[ci] == kNone) return;
      const Chart& c = param.charts[ci];
      const SparseOperator& transmission = glossy[c.material].transmission[c.isBack ? 1 : 0];
      for (uint64_t local = 0; local < c.tixelCount(); ++local) {
        const Lanes4* twin = cells(param, twinTixel(param, c.firstTixel + local));
        F4 sum = f4Zero();
        for (uint32_t k = 0; k < n_; ++k) sum = f4Add(sum, f4Load(twin[k].v));
        transmission.apply(twin, sum, direct.data() + c.firstValue + local * c.valuesPerTixel());
      }
    });
  }

 private:
  static constexpr uint64_t kNone = ~uint64_t(0);
  uint32_t n_;
  std::vector<uint64_t> slotOfChart_;  ///< per chart: slot of its tixel 0, kNone if not rough glass
  std::vector<Lanes4> incoming_;       ///< per slot, n gather cells
};

// ---- The gather kernel of the iteration ------------------------------------------------------
/// The transport radiance ρ̄·E/π (W·sr⁻¹·m⁻²) around a diffuse tixel g, as the coefficients of
/// the bilinear interpolant over g and its neighbours t₀₀ = (i, j), t₁₀ = (i+1, j), t₀₁ = (i, j+1),
/// t₁₁ = (i+1, j+1) in g's chart:
///     L(fu, fv) = a + fu·b + fv·(c + fu·d),
///     a = t₀₀,  b = t₁₀ − t₀₀,  c = t₀₁ − t₀₀,  d = t₁₁ − t₁₀ − t₀₁ + t₀₀,
/// everything a lookup at g needs in one 64-byte cache line, and 3 multiply-adds per lookup
/// instead of the 4 weights and 4 multiply-adds of the tap form. Neighbours outside the chart
/// and non-diffuse tixels count as 0 (a visibility entry never gives them a non-zero weight:
/// linearTap holds the last row and column, so fu or fv is exactly 0 there).
struct alignas(64) TransportQuad {
  float coefficient[4][4];  ///< [a, b, c, d][r, g, b, 0]
};

/// The bilinear fractions (fu, fv) of an entry in lanes 0 and 1 (lanes 2, 3: 0).
inline F4 entryFractions(VisibilityEntry e) {
#if defined(__SSE2__)
  // The entry's bytes as 16-bit lanes [target lo, target hi, fu, fv]: shift fu, fv down, widen to
  // 32 bits and convert — exactly float(fu), float(fv), as in the portable branch.
  static_assert(offsetof(VisibilityEntry, fu) == 4 && offsetof(VisibilityEntry, fv) == 6);
  const __m128i raw = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(&e));
  const __m128i wide = _mm_unpacklo_epi16(_mm_srli_epi64(raw, 32), _mm_setzero_si128());
  return _mm_mul_ps(_mm_cvtepi32_ps(wide), _mm_set1_ps(1.0f / 65535.0f));
#else
  return {{float(e.fu) * (1.0f / 65535.0f), float(e.fv) * (1.0f / 65535.0f), 0.0f, 0.0f}};
#endif
}

/// Bilinear lookup of visibility entry e in the quads: a + fu·b + fv·(c + fu·d), lane-wise.
inline F4 lookupQuad(const TransportQuad& q, VisibilityEntry e) {
  const F4 f = entryFractions(e);
#if defined(__SSE2__)
  const F4 fu = _mm_shuffle_ps(f, f, _MM_SHUFFLE(0, 0, 0, 0)), fv = _mm_shuffle_ps(f, f, _MM_SHUFFLE(1, 1, 1, 1));
#else
  const F4 fu = f4Splat(f.v[0]), fv = f4Splat(f.v[1]);
#endif
  const F4 inner = f4Add(f4Load(q.coefficient[2]), f4Mul(fu, f4Load(q.coefficient[3])));
  const F4 row = f4Add(f4Load(q.coefficient[0]), f4Mul(fu, f4Load(q.coefficient[1])));
  return f4Add(row, f4Mul(fv, inner));
}

// How many entries ahead the quad of a gather ray is prefetched: the quads are read in
// visibility order, i.e. at random, and are larger than L2 at the default preset, so each
// lookup would otherwise wait for an L3 (or memory) access.
constexpr uint32_t kPrefetchDistance = 16;

/// Σ_k L_k over one tixel's n visibility entries, in gather order k = 0 … n−1 (also writing
/// each L_k to incoming when KeepIncoming). Entries without an extra record that hit a front
/// side are direct views of diffuse tixels (a mirror-free path to a glossy chart always has
/// one), looked up in the quads; entries with an extra record go through slowPath(entry,
/// extra), which returns their radiance; escaped entries and back sides without an extra bring
/// nothing. `extraCount` is the tixel's number of extra records, `scratch` room for that many
/// values. `ahead`: the entries of the tixel gathered next (n of them), whose quads are
/// prefetched one per entry gathered here, a whole tixel's gather before they are read; or
/// nullptr, and the quads of this tixel's own entries kPrefetchDistance ahead are. Prefetches
/// read quad quadCount − 1 (all zero) for the escaped entries.
///
/// The entries with an extra record are evaluated first, into `scratch`, so that the loop that
/// sums makes no call; the values and the order of the additions are those of evaluating each
/// entry in turn, so the sum is the same to the bit. Not inlined: inside gatherIteration's
/// loop, where values live across calls, the compiler kept `sum` in memory, which chained the
/// additions through a store and a reload each.
template <bool KeepIncoming, typename SlowPath>
[[gnu::noinline]] F4 gatherTixel(const VisibilityEntry* entries, const VisibilityEntry* ahead, uint32_t n,
                                 const TransportQuad* quads, uint64_t quadCount, const VisibilityExtra* extras,
                                 uint64_t extraCount, Lanes4* scratch, Lanes4* incoming, SlowPath&& slowPath) {
  if (extraCount > 0) {
    const VisibilityExtra* extra = extras;
    Lanes4* out = scratch;
    for (uint32_t k = 0; k < n; ++k)
      if (entries[k].hasExtra()) *out++ = lanes4(slowPath(entries[k], extra++));
  }
  const Lanes4* slow = scratch;
  F4 sum = f4Zero();
  auto add = [&](uint32_t k) [[gnu::always_inline]] {
    const VisibilityEntry e = entries[k];
    // The flags are the target's top bits, so one comparison finds the direct views of a
    // front side: below kEscape, with neither flag.
    if (e.target < VisibilityEntry::kEscape) {
      const F4 L = lookupQuad(quads[e.tixel()], e);
      sum = f4Add(sum, L);
      if constexpr (KeepIncoming) incoming[k] = lanes4(L);
    } else if (e.hasExtra()) {
      const F4 L = f4Load((slow++)->v);  // slowPath's radiance
      sum = f4Add(sum, L);
      if constexpr (KeepIncoming) incoming[k] = lanes4(L);
    } else {
      // Escaped, or a back side without an extra: nothing arrives (as slowPathRadiance says),
      // and adding +0 would leave the sum as it is (it starts at +0, so it is never −0).
      if constexpr (KeepIncoming) incoming[k] = Lanes4{};
    }
  };
  if (ahead) {
    for (uint32_t k = 0; k < n; ++k) {
      __builtin_prefetch(quads + std::min<uint64_t>(ahead[k].tixel(), quadCount - 1));
      add(k);
    }
    return sum;
  }
  // The entries kPrefetchDistance ahead exist up to n − kPrefetchDistance: two loops, so that
  // neither tests for it.
  const uint32_t prefetched = n > kPrefetchDistance ? n - kPrefetchDistance : 0;
  for (uint32_t k = 0; k < prefetched; ++k) {
    __builtin_prefetch(quads + std::min<uint64_t>(entries[k + kPrefetchDistance].tixel(), quadCount - 1));
    add(k);
  }
  for (uint32_t k = prefetched; k < n; ++k) add(k);
  return sum;
}

/// A thread's walk over the entries of the tixels it gathers, in order, one tixel ahead: before
/// it gathers a tixel it decodes the entries of the next (or finds them in the decoded field),
/// so that gatherTixel prefetches the quads those will read while it works. Each quad so
/// arrives a whole tixel's gather before it is read, where prefetching kPrefetchDistance entries
/// ahead inside the tixel left every tixel's first entries and its short tixels waiting on
/// memory (the quads are read at random and, on a large scene, mostly miss every cache).
class EntryPipeline {
 public:
  EntryPipeline(EntryReader& reader, uint32_t n)
      : reader_(reader), n_(n), buffer_{std::vector<VisibilityEntry>(n), std::vector<VisibilityEntry>(n)} {}

  /// Tixel g's entries: those ahead(g) prepared, else decoded now (and their quads prefetched
  /// at once). Valid until the second ahead() after.
  const VisibilityEntry* take(uint64_t g, const TransportQuad* quads, uint64_t quadCount) {
    if (g == aheadTixel_) {
      slot_ ^= 1;
      aheadTixel_ = kNone;
      return aheadEntries_;
    }
    const VisibilityEntry* entries = reader_.entries(g, buffer_[slot_].data());
    for (uint32_t k = 0; k < n_; ++k) __builtin_prefetch(quads + std::min<uint64_t>(entries[k].tixel(), quadCount - 1));
    return entries;
  }
  /// Prepares tixel g's entries, to be taken next (the buffer take() did not return); returns them.
  const VisibilityEntry* ahead(uint64_t g) {
    aheadTixel_ = g;
    aheadEntries_ = reader_.entries(g, buffer_[slot_ ^ 1].data());
    return aheadEntries_;
  }

 private:
  static constexpr uint64_t kNone = ~uint64_t(0);
  EntryReader& reader_;
  uint32_t n_;
  std::vector<VisibilityEntry> buffer_[2];
  uint32_t slot_ = 0;  ///< the buffer take() decodes into; ahead() uses the other
  uint64_t aheadTixel_ = kNone;
  const VisibilityEntry* aheadEntries_ = nullptr;
};

/// The scene's brightest emitter, for messages: "material 'NAME' (emission R G B)" or
/// "point light I (intensity R G B)"; empty when nothing emits.
std::string brightestEmitter(const Scene& scene) {
  std::string name;
  float brightest = 0.0f;
  auto consider = [&](const Rgb& value, const std::string& what, const char* quantity) {
    if (!(maxComponent(value) > brightest)) return;
    brightest = maxComponent(value);
    name = fmt::format("{} ({} {:.3g} {:.3g} {:.3g})", what, quantity, value.r, value.g, value.b);
  };
  for (const Material& m : scene.materials) consider(m.emission, fmt::format("material '{}'", m.name), "emission");
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& light = scene.lights[i];
    consider(lightEmission(light), fmt::format("{} light {}", lightTypeName(light), i), lightEmissionName(light));
  }
  return name;
}

/// Fails when `values` holds a NaN or an infinity (32-bit floats overflowed: an emission or
/// light so strong that sums of it exceed 3.4e38), naming the first chart and material where
/// one is, the stage, and the brightest emitter. Without this check the bake would finish,
/// write the non-finite values and a NaN residual, and the file's own reader refuse it.
void requireFiniteValues(const Scene& scene, const Parameterisation& param, const std::vector<Rgb>& values,
                         const std::string& stage) {
  for (size_t ci = 0; ci < param.charts.size(); ++ci) {
    const Chart& c = param.charts[ci];
    const uint64_t count = c.kind == ChartKind::Specular ? 0 : c.tixelCount() * c.valuesPerTixel();
    for (uint64_t v = c.firstValue; v < c.firstValue + count; ++v) {
      if (isFinite(values[v])) continue;
      const std::string emitter = brightestEmitter(scene);
      fail("{}: light propagation overflowed {}: non-finite radiance in chart {} (material '{}'){}; "
           "scale the emission down",
           scene.sourcePath, stage, ci, scene.materials[c.material].name,
           emitter.empty() ? std::string() : fmt::format("; the brightest emitter is {}", emitter));
    }
  }
}

}  // namespace

namespace {

/// The incident sub-sample directions of every gather cell, kCellSubsamples² per cell in cell
/// order: cosine-distributed, so a mean over a cell's directions times π/N is ∫_cell … cos θ dω.
std::vector<Vec3> gatherCellSubsampleDirections(uint32_t gridSide) {
  const uint32_t n = gridSide * gridSide;
  std::vector<Vec3> cellDirs(size_t(n) * kCellSubsamples * kCellSubsamples);
  for (uint32_t k = 0; k < n; ++k) {
    const float a = float(k % gridSide), b = float(k / gridSide);
    for (int y = 0; y < kCellSubsamples; ++y)
      for (int x = 0; x < kCellSubsamples; ++x) {
        const Vec2 u((a + (x + 0.5f) / kCellSubsamples) / gridSide, (b + (y + 0.5f) / kCellSubsamples) / gridSide);
        cellDirs[(size_t(k) * kCellSubsamples + y) * kCellSubsamples + x] = sampleCosineHemisphere(u);
      }
  }
  return cellDirs;
}

/// GlossyMaterial's diffuse part of model `bsdf` (which has one): the model without it, and
/// per gather cell w_k = (π/N) · mean over the cell's sub-sample directions of k(μ).
void addDiffusePart(GlossyMaterial& g, const Bsdf& bsdf, uint32_t gridSide) {
  const uint32_t n = gridSide * gridSide, perCell = kCellSubsamples * kCellSubsamples;
  const std::vector<Vec3> cellDirs = gatherCellSubsampleDirections(gridSide);
  g.diffuse = true;
  g.specular = withDiffuseAlbedo(bsdf, Rgb(0.0f));
  g.diffuseWeight.resize(n);
  Rgb total(0.0f);
  for (uint32_t k = 0; k < n; ++k) {
    Rgb sum(0.0f);
    for (uint32_t s = 0; s < perCell; ++s) sum += diffuseDirectionalFactor(bsdf, cellDirs[size_t(k) * perCell + s].z);
    const Rgb w = sum * (kPi / float(n * perCell));
    g.diffuseWeight[k] = lanes4(w);
    total += w;
  }
  g.diffuseExitance = total * kInvPi;
}

/// g's operators for one lobe of model `bsdf` on glossy chart c (GlossyMaterial): the
/// reflection (with the per-tixel f0 slope where the tixels keep their own f0), the diffuse
/// part's weights, and a narrow lobe's cell-constant BSDF.
void buildGlossyLobe(GlossyMaterial& g, const Scene& scene, const Chart& c, const Bsdf& bsdf, uint32_t gridSide) {
  const uint32_t n = gridSide * gridSide;
  g.dirRes = c.dirRes;
  g.model = bsdf;
  if (c.diffuseValue) addDiffusePart(g, bsdf, gridSide);
  const Bsdf& mapped = g.diffuse ? g.specular : bsdf;
  g.tixelF0 = perTixelSpecularF0(scene, c) && !isNarrowLobe(mapped, gridSide) && !hasTransmission(mapped);
  std::vector<Rgb> dense = glossyOperator(g.tixelF0 ? withSpecularF0(mapped, Rgb(0.0f)) : mapped, c.dirRes, gridSide);
  g.op = SparseOperator::fromDense(dense, c.dirRes * c.dirRes, n);
  if (g.tixelF0) {
    std::vector<Rgb> slope = glossyOperator(withSpecularF0(mapped, Rgb(1.0f)), c.dirRes, gridSide);
    for (size_t e = 0; e < slope.size(); ++e) slope[e] -= dense[e];
    g.f0Slope = SparseOperator::fromDense(slope, c.dirRes * c.dirRes, n);
  }
  if (isNarrowLobe(mapped, gridSide)) {
    for (Rgb& w : dense) w *= float(n) * kInvPi;
    g.cellBsdf = std::move(dense);
    g.gridSide = gridSide;
  }
}

}  // namespace

bool isNarrowLobe(const Bsdf& bsdf, uint32_t gridSide) {
  if (hasTransmission(bsdf) || isDelta(bsdf) || isDiffuse(bsdf)) return false;
  // The cell sub-samples lie ≈ 2/(gridSide·kCellSubsamples) radians apart near the normal
  // (the concentric disk's diameter 2 over gridSide·kCellSubsamples of them).
  const float spacing = 2.0f / float(gridSide * kCellSubsamples);
  return 4.0f * lobeHalfWidth(bsdf) < kNarrowLobeSubsamples * spacing;
}

namespace {

/// glossyOperator for a narrow lobe (isNarrowLobe): per output sub-direction wo, kLobeSamples²
/// stratified directions importance-sampled from the lobe, each adding f·cos θ/pdf to the cell
/// it falls in (gatherCellOf). Unbiased for any lobe width, and each row sums to the model's
/// directional albedo up to the sampling error, where fixed sub-samples would miss the lobe.
std::vector<Rgb> sampledGlossyOperator(const Bsdf& bsdf, uint32_t dirRes, uint32_t gridSide) {
  constexpr int kLobeSamples = 32;
  const uint32_t n = gridSide * gridSide, texels = dirRes * dirRes;
  std::vector<Rgb> op(size_t(texels) * n);
  parallelFor(texels, [&](uint64_t c) {
    const std::vector<Vec3> outputs = outputTexelDirections(uint32_t(c % dirRes), uint32_t(c / dirRes), dirRes);
    const float norm = 1.0f / float(outputs.size() * kLobeSamples * kLobeSamples);
    Rgb* row = op.data() + c * n;
    for (const Vec3& wo : outputs)
      for (int y = 0; y < kLobeSamples; ++y)
        for (int x = 0; x < kLobeSamples; ++x) {
          const Vec2 u((float(x) + 0.5f) / kLobeSamples, (float(y) + 0.5f) / kLobeSamples);
          const std::optional<BsdfSample> bs = sample(bsdf, wo, u);
          if (!bs || !(bs->wi.z > 0.0f)) continue;
          row[gatherCellOf(bs->wi, gridSide)] += bs->weight * norm;
        }
  });
  return op;
}

}  // namespace

std::vector<Rgb> glossyOperator(const Bsdf& bsdf, uint32_t dirRes, uint32_t gridSide, bool outputOnBack, bool gatherOnBack) {
  if (isNarrowLobe(bsdf, gridSide)) return sampledGlossyOperator(bsdf, dirRes, gridSide);
  const uint32_t n = gridSide * gridSide, texels = dirRes * dirRes;
  std::vector<Rgb> op(size_t(texels) * n);
  // Incident sub-sample directions of every cell (same for every output texel).
  const std::vector<Vec3> cellDirs = gatherCellSubsampleDirections(gridSide);
  // ∫_cell f cos θ dω = (π/N)·E[f] over cosine-distributed directions in the cell.
  const float cellWeight = kPi / float(n);
  parallelFor(texels, [&](uint64_t c) {
    const std::vector<Vec3> outputs = outputTexelDirections(uint32_t(c % dirRes), uint32_t(c / dirRes), dirRes);
    const float norm = cellWeight / float(outputs.size() * kCellSubsamples * kCellSubsamples);
    for (uint32_t k = 0; k < n; ++k) {
      Rgb sum(0.0f);
      for (const Vec3& wo : outputs)
        for (int s = 0; s < kCellSubsamples * kCellSubsamples; ++s)
          sum += eval(bsdf, glassBsdfDirection(outputOnBack, wo),
                      glassBsdfDirection(gatherOnBack, cellDirs[size_t(k) * kCellSubsamples * kCellSubsamples + s]));
      op[c * n + k] = sum * norm;
    }
  });
  return op;
}

// ---- The transport state and the stages ---------------------------------------------------

/// What the stages share beyond the public fields: per-material glossy operators, the light
/// sampler and shadow rays of the first shot, and the transport quads of the iteration.
struct TransportState::Operators {
  std::vector<GlossyMaterial> glossy;  ///< per material; dirRes 0 = not used by a glossy chart
  LightSampler lights;
  std::vector<float> areaPdf;          ///< per untextured material: the emitter area density
  uint32_t lightSamples = 0;           ///< area-light shadow rays per tixel (0 without emitters)
  uint32_t sceneLightSamples = 1;      ///< shadow rays per tixel towards each non-delta scene light
  std::optional<ShadowRays> shadows;
  /// The first-shot gather of rough-glass tixels, kept until every range has gathered, when
  /// each record adds the transmission of its twin's (beginIteration).
  std::optional<GlassFirstShot> glassFirstShot;
  /// The quads (TransportQuad) of every tixel, plus one, all zero, for the entries that
  /// escaped (see gatherTixel).
  std::vector<TransportQuad> quads;
  /// Normal-mapped charts (lightfield.h "Normal-mapped diffuse charts"), per material of a
  /// directionalIrradiance chart (empty for the others): per gather direction — cell k with
  /// jitter sub-cell j at [k·kGatherJitterSide² + j] — its share of each tilted irradiance in
  /// the gather frame, π/n · max(0, b_i·ω)/cos θ · tiltFactor (lanes R, G, B and 0).
  std::vector<std::vector<std::array<Lanes4, kTiltedNormals>>> tiltShares;
  /// Subsurface charts (subsurface.h; all empty when there is none): the operator, per chart
  /// whether it is one, and per tixel the irradiance a subsurface tixel gathered at its last
  /// update (its own value is the operator's product of these: applySubsurface).
  SubsurfaceOperator subsurface;
  std::vector<uint8_t> subsurfaceChart;
  std::vector<Rgb> subsurfaceIrradiance;
};

namespace {

uint64_t valueBase(uint64_t g, const Chart& c) { return c.firstValue + (g - c.firstTixel) * c.valuesPerTixel(); }

// Σ over tixels of perTixel(g, chart, first value) · coverage · tixel area, summed per chart and
// then over charts in chart order (deterministic whatever the thread timing).
template <typename PerTixel>
double areaWeightedSum(const Parameterisation& param, PerTixel&& perTixel) {
  std::vector<double> perChart(param.charts.size(), 0.0);
  parallelFor(param.charts.size(), [&](uint64_t ci) {
    const Chart& c = param.charts[ci];
    if (c.kind == ChartKind::Specular) return;
    double sum = 0.0;
    const double tixelArea = double(c.tixelSize) * c.tixelSize;
    for (uint64_t local = 0; local < c.tixelCount(); ++local) {
      const uint64_t g = c.firstTixel + local;
      sum += perTixel(g, c, c.firstValue + local * c.valuesPerTixel()) * param.coverage[g] * tixelArea;
    }
    perChart[ci] = sum;
  });
  double total = 0.0;
  for (double p : perChart) total += p;
  return total;
}
// Luminance of the radiant exitance per unit area (W·m⁻²) of the values of tixel g:
// diffuse ρ̄E, glossy Σ Lo·cosθ·Ω.
double exitance(const TransportState& state, const Rgb* values, uint64_t g, const Chart& c) {
  if (c.kind == ChartKind::Diffuse) return double(luminance(state.param.transportAlbedo[g] * values[0]));
  double sum = 0.0;
  const GlossyMaterial& gm = state.ops->glossy[c.material];
  for (uint32_t t = 0; t < c.directionTexels(); ++t) sum += double(luminance(values[t])) * gm.projectedSolidAngle[t];
  if (c.diffuseValue)
    sum += double(luminance(state.param.transportAlbedo[g] * values[c.directionTexels()] *
                            gm.lobeAt(state.param, g).diffuseExitance));
  return sum;
}
// |change| of that exitance from `before` to `after`, texel by texel (so that changes of
// opposite sign in different texels do not cancel).
float exitanceChange(const TransportState& state, const Rgb* before, const Rgb* after, uint64_t g, const Chart& c) {
  if (c.kind == ChartKind::Diffuse) return std::abs(luminance(state.param.transportAlbedo[g] * (after[0] - before[0])));
  float sum = 0.0f;
  const GlossyMaterial& gm = state.ops->glossy[c.material];
  for (uint32_t t = 0; t < c.directionTexels(); ++t) sum += std::abs(luminance(after[t] - before[t])) * gm.projectedSolidAngle[t];
  if (c.diffuseValue) {
    const uint64_t d = c.directionTexels();
    sum += std::abs(luminance(state.param.transportAlbedo[g] * (after[d] - before[d]) * gm.lobeAt(state.param, g).diffuseExitance));
  }
  return sum;
}

/// The irradiance tixel g of chart c sends on, from its irradiance values[0] (a diffuse
/// chart's E, a glossy chart's Ẽ): values[0] itself, or on a directionalIrradiance chart
/// Parameterisation::transportTiltWeights applied to it and the tilted irradiances after it,
/// clamped at 0 (a normal-mapped surface sends on its irradiance about the footprint's mapped
/// normals).
Rgb transportIrradiance(const Parameterisation& param, const Chart& c, uint64_t g, const Rgb* values) {
  if (!c.directionalIrradiance) return values[0];
  const TiltWeights& w = param.transportTiltWeights[g];
  Rgb e = values[0] * w.irradiance;
  for (uint32_t k = 0; k < kTiltedNormals; ++k) e += values[1 + k] * w.tilted[k];
  return glm::max(e, Rgb(0.0f));
}

/// The diffuse part of a glossy diffuseValue chart c's exitant radiance towards paraboloid
/// direction st at grid position `grid`: k(μo)/π · the bilinear interpolation of ρ̄·Ẽ over the
/// tixels (ρ̄ the transport albedo, Ẽ transportIrradiance's; as the diffuse quads interpolate ρ̄·E).
Rgb glossyDiffuseRadiance(const TransportState& state, const Rgb* values, const Chart& c, Vec2 grid, Vec2 st) {
  const std::vector<Rgb>& albedo = state.param.transportAlbedo;
  const float cosine = paraboloidToDirection(st).z;
  const GlossyMaterial& gm = state.ops->glossy[c.material];
  const bool perTixel = !gm.bins.empty();  // per-tixel lobe widths: each tixel's k(μo) its own lobe's
  const F4 e = bilinearOverTixels(c, grid, [&](uint32_t i, uint32_t j) {
    const uint64_t tixel = c.firstTixel + uint64_t(j) * c.resU + i;
    const Rgb radiance = albedo[tixel] * transportIrradiance(state.param, c, tixel, &values[c.diffuseValueIndex(i, j)]);
    return f4FromRgb(perTixel ? radiance * diffuseDirectionalFactor(gm.lobeAt(state.param, tixel).model, cosine) : radiance);
  });
  const Rgb factor = perTixel ? Rgb(1.0f) : diffuseDirectionalFactor(state.scene.materials[c.material].bsdf, cosine);
  return f4Rgb(e) * kInvPi * factor;
}

/// The weight of light arriving at cos θ = `cosine` to tilted normal b_k in chart c's tilted
/// irradiances, beyond the cosine: 1 on a diffuse chart, the diffuse part's k(b_k·ω) on a
/// glossy one (its Ẽ_k weigh the light as Ẽ does, lightfield.h).
Rgb tiltFactor(const Chart& c, const Bsdf& bsdf, float cosine) {
  return c.kind == ChartKind::Glossy ? diffuseDirectionalFactor(bsdf, cosine) : Rgb(1.0f);
}

/// The tilted irradiances (lightfield.h "Normal-mapped diffuse charts") that light of
/// irradiance `irradiance` (W·m⁻², already × cos θ at the tixel's normal) arriving from world
/// direction wi adds to directionalIrradiance tixel g of chart c: irradiance ·
/// max(0, b_k·wi) / cos θ · tiltFactor for each tilted normal b_k, added to
/// tilted[0 … kTiltedNormals − 1].
void addTiltedIrradiance(const Scene& scene, const Parameterisation& param, const Chart& c, uint64_t g, const Vec3& wi,
                         const Rgb& irradiance, Rgb* tilted) {
  const Vec3 local = tiltFrame(param, c, g).toLocal(wi);
  if (!(local.z > 0.0f)) return;
  const Bsdf& bsdf = scene.materials[c.material].bsdf;
  for (uint32_t k = 0; k < kTiltedNormals; ++k) {
    const float cosine = glm::dot(local, tiltedNormal(k));
    tilted[k] += irradiance * (std::max(0.0f, cosine) / local.z) * tiltFactor(c, bsdf, cosine);
  }
}

/// The same for the radiances incoming[k] (W·sr⁻¹·m⁻²) of tixel g's n gather rays
/// (cosine-distributed, so each stands for π/n · L / cos θ of irradiance): the gather's
/// estimate of ∫ L max(0, b_k·ω) dω. subCells: gatherSubCells' scratch for the tixel.
/// The shares are tabulated in the gather frame (tiltShares); on a curved chart, whose gather
/// frame (tixelFrameAround) turns about the normal against its tilt frame, the values are
/// moved into the tilt frame through the model of lightfield.h: their mean Ē does not depend
/// on the frame, and E_k = Ē + sin β·g·t_k with g = 2/(3 sin β)·Σ_k E_k·t_k turned between the
/// frames.
void addTiltedGather(const TransportState& state, const Chart& c, uint64_t g, const Lanes4* incoming,
                     std::vector<uint8_t>& subCells, Rgb* tilted) {
  const Parameterisation& param = state.param;
  const auto& shares = state.ops->tiltShares[c.material];
  gatherSubCells(g, state.gridSide, state.settings.seed, subCells);
  // Σ_k L_k · share_t, lane-wise (the colour channels; the fourth lane is unused).
  F4 lanes[kTiltedNormals] = {f4Zero(), f4Zero(), f4Zero()};
  for (uint32_t k = 0; k < state.n; ++k) {
    const F4 L = f4Load(incoming[k].v);
    const std::array<Lanes4, kTiltedNormals>& share = shares[size_t(k) * kGatherJitterSide * kGatherJitterSide + subCells[k]];
    for (uint32_t t = 0; t < kTiltedNormals; ++t) lanes[t] = f4Add(lanes[t], f4Mul(L, f4Load(share[t].v)));
  }
  Rgb sum[kTiltedNormals] = {f4Rgb(lanes[0]), f4Rgb(lanes[1]), f4Rgb(lanes[2])};
  if (c.curved) {
    const TixelFrame from = tixelFrame(param, c, g), to = tiltFrame(param, c, g);
    constexpr float kGradient = 2.0f / (3.0f * kNormalTiltSine);
    Rgb mean(0.0f), gx(0.0f), gy(0.0f);  // Ē and g in the gather frame
    for (uint32_t t = 0; t < kTiltedNormals; ++t) {
      mean += sum[t] / float(kTiltedNormals);
      gx += sum[t] * (kGradient * kTiltAcross[t][0]);
      gy += sum[t] * (kGradient * kTiltAcross[t][1]);
    }
    // g's components along the tilt frame's axes.
    const Rgb tx = gx * glm::dot(from.u, to.u) + gy * glm::dot(from.v, to.u);
    const Rgb ty = gx * glm::dot(from.u, to.v) + gy * glm::dot(from.v, to.v);
    for (uint32_t t = 0; t < kTiltedNormals; ++t) {
      // E_k = Ē + sin β·g·t_k.
      sum[t] = glm::max(Rgb(0.0f), mean + (tx * kTiltAcross[t][0] + ty * kTiltAcross[t][1]) * kNormalTiltSine);
    }
  }
  for (uint32_t t = 0; t < kTiltedNormals; ++t) tilted[t] += sum[t];
}

}  // namespace

TransportState::TransportState(const Scene& sceneIn, const Accel& accelIn, const Parameterisation& paramIn,
                               const BakeSettings& settingsIn, Communicator* comm)
    : scene(sceneIn), accel(accelIn), param(paramIn), settings(settingsIn), ops(std::make_unique<Operators>()) {
  // The gather grid follows from the settings (the field's hash covers them); the field itself
  // is first needed after the shadow rays of the first shot.
  gridSide = gatherGridSide(settings.gatherDirections);
  n = gridSide * gridSide;
  const uint64_t tixels = param.tixelCount;
  std::vector<GlossyMaterial>& glossy = ops->glossy;
  glossy.resize(scene.materials.size());
  // Glossy operators, one per material used by a glossy chart.
  for (const Chart& c : param.charts) {
    if (c.kind != ChartKind::Glossy || glossy[c.material].dirRes != 0) continue;
    GlossyMaterial& g = glossy[c.material];
    const Bsdf& bsdf = scene.materials[c.material].bsdf;
    if (perTixelLobeWidth(scene, c)) {
      g.dirRes = c.dirRes;
      g.model = bsdf;
      g.binAlpha = lobeAlphaBins(scene, scene.materials[c.material], c.dirRes);
      g.bins.resize(g.binAlpha.size());
      for (size_t b = 0; b < g.bins.size(); ++b)
        buildGlossyLobe(g.bins[b], scene, c, withGgxLobeAlpha(bsdf, g.binAlpha[b]), gridSide);
    } else {
      buildGlossyLobe(g, scene, c, bsdf, gridSide);
    }
    if (isRoughGlassChart(c, scene.materials[c.material].bsdf)) addGlassOperators(g, scene.materials[c.material].bsdf, gridSide);
    const std::vector<float>& omega = paraboloidTexelSolidAngles(c.dirRes);
    for (uint32_t t = 0; t < c.dirRes * c.dirRes; ++t) {
      g.outputs.push_back(outputTexelDirections(t % c.dirRes, t / c.dirRes, c.dirRes));
      g.centres.push_back(paraboloidTexelDirection(t % c.dirRes, t / c.dirRes, c.dirRes));
      g.projectedSolidAngle.push_back(omega[t] * std::max(0.0f, paraboloidTexelDirection(t % c.dirRes, t / c.dirRes, c.dirRes).z));
    }
  }

  refreshEmitters(*this);
  // The gather never finds the scene's lights (they are no geometry): a non-delta one gets
  // shadow rays even when the preset gives emissive surfaces none.
  ops->sceneLightSamples = std::max(1u, settings.areaLightSamples);
  // The scene's lights pass thin glass (windows) as in the path tracer. Emissive surfaces'
  // shadow rays stop at all glass: emitters behind glass reach the tixel along the
  // gather chains, which count them with full weight (viaMirror), or on diffuse tixels by the
  // caustic pass (caustics.h), so crossing glass here too would count them twice.
  ops->shadows.emplace(scene, accel);
  ops->glassFirstShot.emplace(scene, param, n);

  direct.assign(param.valueCount, Rgb(0.0f));
  const bool glossyReflector = std::any_of(param.charts.begin(), param.charts.end(), [&](const Chart& c) {
    return c.kind == ChartKind::Glossy && !isRoughGlassChart(c, scene.materials[c.material].bsdf);
  });
  if (settings.punctualHighlights && std::any_of(scene.lights.begin(), scene.lights.end(), isDeltaLight) && glossyReflector)
    punctualGlossy.assign(param.valueCount, Rgb(0.0f));
  change.assign(tixels, 0.0f);
  batchStart = propagationBatches(param);
  SingleProcess single;
  ops->subsurface =
      buildSubsurfaceOperator(scene, accel, param, settings.subsurfaceWalks, settings.seed, comm ? *comm : single);
  if (!ops->subsurface.empty()) {
    ops->subsurfaceChart.resize(param.charts.size());
    for (size_t ci = 0; ci < param.charts.size(); ++ci) ops->subsurfaceChart[ci] = isSubsurfaceChart(scene, param.charts[ci]);
    ops->subsurfaceIrradiance.assign(tixels, Rgb(0.0f));
  }
  ops->tiltShares.resize(scene.materials.size());
  for (const Chart& c : param.charts) {
    std::vector<std::array<Lanes4, kTiltedNormals>>& shares = ops->tiltShares[c.material];
    if (!c.directionalIrradiance || !shares.empty()) continue;
    const Bsdf& bsdf = scene.materials[c.material].bsdf;
    constexpr uint32_t kJitters = kGatherJitterSide * kGatherJitterSide;
    shares.resize(size_t(n) * kJitters);
    for (uint32_t k = 0; k < n; ++k)
      for (uint32_t j = 0; j < kJitters; ++j) {
        const Vec3 w = gatherCellDirection(k, j, gridSide, settings.seed);
        for (uint32_t t = 0; t < kTiltedNormals; ++t) {
          const float cosine = glm::dot(w, tiltedNormal(t));
          shares[size_t(k) * kJitters + j][t] = lanes4(
              w.z > 0.0f ? Rgb(kPi / float(n) * std::max(0.0f, cosine) / w.z) * tiltFactor(c, bsdf, cosine) : Rgb(0.0f));
        }
      }
  }
}

void refreshEmitters(TransportState& state) {
  const Scene& scene = state.scene;
  TransportState::Operators& ops = *state.ops;
  // The light sampler the path tracer uses (light/light.h): emissive triangles chosen ∝ their
  // power and sampled by area, whose area density is then constant per untextured material
  // (a textured one's varies by triangle: the gather reads it per tixel, emitterAreaPdfOf).
  ops.lights = LightSampler(scene);
  ops.areaPdf.assign(scene.materials.size(), 0.0f);
  for (uint32_t mesh = 0; mesh < scene.meshes.size(); ++mesh)
    for (uint32_t t = 0; t < scene.meshes[mesh].triangles.size(); ++t) {
      const uint32_t m = scene.meshes[mesh].materials[t];
      if (scene.materials[m].emissionTexture < 0) ops.areaPdf[m] = std::max(ops.areaPdf[m], ops.lights.emitterAreaPdf(mesh, t));
    }
  ops.lightSamples = ops.lights.emissiveTriangleCount() == 0 ? 0 : state.settings.areaLightSamples;
  state.caustics = shootsCaustics(state.param, ops.lights, state.settings);
}

std::vector<uint64_t> propagationBatches(const Parameterisation& param) {
  // At least 2048 tixels per batch, and at most ~16000 batches.
  const uint64_t tixels = param.tixelCount;
  const uint64_t kBatchTixels = std::max<uint64_t>(2048, tixels / 16000 + 1);
  std::vector<uint64_t> batchStart(1, 0);
  uint64_t count = 0;
  for (size_t ci = 0; ci < param.charts.size(); ++ci) {
    count += param.charts[ci].tixelCount();
    if (count >= kBatchTixels) {
      batchStart.push_back(param.charts[ci].firstTixel + param.charts[ci].tixelCount());
      count = 0;
    }
  }
  if (batchStart.back() != tixels) batchStart.push_back(tixels);
  return batchStart;
}

TransportState::~TransportState() = default;

int sunMaskSlot(const Parameterisation& param, uint32_t light) {
  const auto at = std::find(param.sunMaskLights.begin(), param.sunMaskLights.end(), light);
  return at == param.sunMaskLights.end() ? -1 : int(at - param.sunMaskLights.begin());
}

Rgb sunMaskedIrradiance(const Parameterisation& param, const Light& light, uint64_t tixel, size_t slot) {
  const Chart& c = param.charts[param.tixelChart[tixel]];
  // A masked light is a delta light at infinity: the same wi and irradiance everywhere.
  const std::optional<IncidentLight> in = sampleLight(light, param.gatherPoint[tixel], Vec2(0.5f));
  if (!in) return Rgb(0.0f);
  const float cosTheta = glm::dot(tixelFrame(param, c, tixel).n, in->wi);
  if (!(cosTheta > 0.0f)) return Rgb(0.0f);
  return in->incident * (cosTheta * sunMaskFraction(param.sunMask[tixel][slot]));
}

void removeSunMaskedDirect(const Scene& scene, const Parameterisation& param, std::vector<Rgb>& values) {
  if (param.sunMaskLights.empty()) return;
  std::vector<Light> lights;
  for (uint32_t index : param.sunMaskLights) lights.push_back(scene.lights[index]);
  parallelForRange(param.tixelCount, 4096, [&](uint64_t begin, uint64_t end) {
    for (uint64_t g = begin; g < end; ++g) {
      const Chart& c = param.charts[param.tixelChart[g]];
      if (c.kind != ChartKind::Diffuse) continue;
      Rgb* value = &values[valueBase(g, c)];
      for (size_t slot = 0; slot < lights.size(); ++slot) {
        const Rgb masked = sunMaskedIrradiance(param, lights[slot], g, slot);
        value[0] -= masked;
        if (!c.directionalIrradiance) continue;
        Rgb tilted[kTiltedNormals] = {Rgb(0.0f), Rgb(0.0f), Rgb(0.0f)};  // what the first shot added
        addTiltedIrradiance(scene, param, c, g, parallelLight(lights[slot])->towardsLight, masked, tilted);
        for (uint32_t k = 0; k < kTiltedNormals; ++k) value[1 + k] -= tilted[k];
      }
      for (uint64_t v = 0; v < c.valuesPerTixel(); ++v)
        value[v] = glm::max(value[v], Rgb(0.0f));  // what rounding leaves below the other terms
    }
  });
}

void storeLightField(LightField& lf, const Parameterisation& param, std::vector<Rgb>&& values) {
  lf.charts = param.charts;
  lf.triangleChart = param.triangleChart;
  lf.values = std::move(values);
  removeSunMaskedDirect(lf.scene, param, lf.values);
  lf.sunMaskLightCount = uint32_t(param.sunMaskLights.size());
  lf.sunMasks.reserve(param.tixelCount * lf.sunMaskLightCount);
  for (uint64_t g = 0; g < param.tixelCount && lf.sunMaskLightCount > 0; ++g)
    lf.sunMasks.insert(lf.sunMasks.end(), param.sunMask[g].begin(), param.sunMask[g].begin() + lf.sunMaskLightCount);
}

void shootShadowRays(TransportState& state, uint64_t begin, uint64_t end, Progress* progress,
                     const ShadowRaySources& sources) {
  if (!sources.lights.empty() && sources.lights.size() != state.scene.lights.size())
    fail("{}: shadow-ray sources name {} lights, the scene has {}", state.scene.sourcePath, sources.lights.size(),
         state.scene.lights.size());
  const Scene& scene = state.scene;
  const Accel& accel = state.accel;
  const Parameterisation& param = state.param;
  const BakeSettings& settings = state.settings;
  const TransportState::Operators& ops = *state.ops;
  const std::vector<GlossyMaterial>& glossy = ops.glossy;
  const LightSampler& lights = ops.lights;
  const uint32_t lightSamples = ops.lightSamples, n = state.n;
  // The lights as shot: each at unit emission for a first shot by source (its D_l).
  std::vector<Light> unitLights;
  if (sources.unitEmission) {
    unitLights = scene.lights;
    for (Light& light : unitLights) setLightEmission(light, Rgb(1.0f));
  }
  const std::vector<Light>& sceneLights = sources.unitEmission ? unitLights : scene.lights;
  const ShadowRays& shadows = *ops.shadows;
  // Per scene light: its sun-mask slot, or −1. And the lights shot (a first shot by source
  // runs once per light: each pass loops over its own light only).
  std::vector<int> maskSlot(sceneLights.size());
  std::vector<uint32_t> shotLights;
  for (size_t li = 0; li < sceneLights.size(); ++li) {
    maskSlot[li] = sunMaskSlot(param, uint32_t(li));
    if (sources.lights.empty() || sources.lights[li]) shotLights.push_back(uint32_t(li));
  }
  std::vector<Rgb>& direct = state.direct;
  std::vector<Rgb>& punctualGlossy = state.punctualGlossy;
  std::atomic<uint64_t>& shadowRays = state.shadowRays;
  const uint64_t tixelsPerBlock = 64;
  const uint64_t blocks = (end - begin + tixelsPerBlock - 1) / tixelsPerBlock;
  struct Pending {
    uint64_t tixel;
    Vec3 wi;
    Rgb irradiance;  ///< already multiplied by cos θ at the receiver (and MIS-weighted)
    /// A sample of an area light — an emissive surface or a non-delta scene light: a glossy map
    /// takes the texel-centre BSDF value, and it is no punctual highlight.
    bool areaSample;
  };
  parallelFor(blocks, [&](uint64_t block) {
    const uint64_t t0 = begin + block * tixelsPerBlock, t1 = std::min(end, t0 + tixelsPerBlock);
    std::vector<Ray> rays;
    std::vector<Pending> pending;  // one per ray, waiting for the batched occlusion test
    std::vector<Pending> seen;     // visibility already known (shadow rays through thin glass)
    uint64_t glassRays = 0;
    // At most one ray per delta light and area-light sample per tixel.
    rays.reserve((t1 - t0) * (shotLights.size() + lightSamples));
    pending.reserve(rays.capacity());
    for (uint64_t g = t0; g < t1; ++g) {
      const Chart& c = param.charts[param.tixelChart[g]];
      if (c.kind == ChartKind::Specular) continue;
      const Vec3 x = param.gatherPoint[g];
      const Vec3 normal = tixelFrame(param, c, g).n;  // the chart's normal, or a curved chart's tixel normal
      // Rough glass takes light from both sides: reflected from its own, transmitted from
      // the other (|cos θ|; the BSDF chooses, see the Pending loop below).
      const bool bothSides = isRoughGlassChart(c, scene.materials[c.material].bsdf);
      for (const uint32_t li : shotLights) {
        const Light& light = sceneLights[li];
        // A masked light on a diffuse tixel: its footprint's mean visibility, no ray
        // (lightfield.h "Sun masks"; sunMaskedIrradiance, which the bake takes back out).
        // (Not on a subsurface chart, whose light goes through the object: shadow rays.)
        if (maskSlot[li] >= 0 && c.kind == ChartKind::Diffuse && !isSubsurfaceChart(scene, c)) {
          const Rgb masked = sunMaskedIrradiance(param, light, g, size_t(maskSlot[li]));
          direct[valueBase(g, c)] += masked;
          if (c.directionalIrradiance)
            addTiltedIrradiance(scene, param, c, g, parallelLight(light)->towardsLight, masked, &direct[valueBase(g, c) + 1]);
          continue;
        }
        // One ray towards a delta light; sceneLightSamples towards any other, the tixel's own
        // (0,2)-net per light (as the area-light samples below), each weighted 1/(count·pdf).
        const bool delta = isDeltaLight(light);
        const uint32_t count = delta ? 1 : ops.sceneLightSamples;
        const ZSobolLayout layout =
            delta ? ZSobolLayout() : ZSobolLayout::forKey(g, int(count), settings.seed ^ 0x4c49474854ULL ^ (uint64_t(li) << 32));
        for (uint32_t s = 0; s < count; ++s) {
          const Vec2 u = delta ? Vec2(0.5f) : Sampler::sobol(layout, 0, 0, s).get2D();
          const std::optional<IncidentLight> in = sampleLight(light, x, u);
          if (!in) continue;
          const float cosTheta = bothSides ? std::abs(glm::dot(normal, in->wi)) : glm::dot(normal, in->wi);
          if (!(cosTheta > 0.0f) || isBlack(in->incident)) continue;
          const std::optional<Ray> ray = shadowRayTowards(offsetRayOrigin(x, normal, in->wi), *in);
          if (!ray) continue;
          const Rgb irradiance = in->incident * (cosTheta / (in->pdf * float(count)));
          if (shadows.passesThinGlass()) {
            const Rgb transmittance = shadows.transmittance(*ray, glassRays);
            if (!isBlack(transmittance)) seen.push_back({g, in->wi, irradiance * transmittance, !delta});
            continue;
          }
          rays.push_back(*ray);
          pending.push_back({g, in->wi, irradiance, !delta});
        }
      }
      if (lightSamples == 0 || !sources.emitters) continue;
      // Every accepted sample direction has cos θx > 0, so all of this tixel's shadow rays
      // start at the same offset origin (rough glass: one on each side).
      const Vec3 origin = offsetRayOrigin(x, normal, normal);
      const Vec3 originBehind = offsetRayOrigin(x, normal, -normal);
      // The tixel's S samples are an Owen-scrambled Sobol (0,2)-net of its own (a scramble
      // keyed by the tixel): the emitter choice, stretched back onto [0, 1), and the second
      // coordinate are stratified jointly, which (with the gather's multi-jitter) lowers the
      // noise between neighbouring tixels (docs/benchmarks.md, Per-tixel noise).
      const ZSobolLayout layout = ZSobolLayout::forKey(g, int(lightSamples), settings.seed ^ 0x4e4545ULL);
      for (uint32_t s = 0; s < lightSamples; ++s) {
        const EmitterPoint sample = lights.sampleEmitterPoint(Sampler::sobol(layout, 0, 0, s).get2D());
        const EmissiveTriangle& em = *sample.triangle;
        const Vec3 d = sample.point - x;
        const float dist2 = glm::dot(d, d);
        if (!(dist2 > 0.0f)) continue;
        const float dist = std::sqrt(dist2);
        const Vec3 wi = d * (1.0f / dist);
        const float cosSigned = glm::dot(normal, wi);
        const float cosX = bothSides ? std::abs(cosSigned) : cosSigned;
        float cosY = -glm::dot(em.normal, wi);
        if (!(cosX > 0.0f) || (cosY <= 0.0f && !em.twoSided)) continue;
        cosY = std::abs(cosY);
        if (!(cosY > 0.0f)) continue;
        // Power heuristic (β = 2) between this strategy (S samples, solid-angle pdf
        // pl = areaPdf·r²/cos θy) and the N cosine-distributed gather rays (pdf pg = cos θx/π):
        //   Le·cos θx/(S·pl) · (S·pl)²/((S·pl)² + (N·pg)²).
        // (The balance heuristic, S·pl/(S·pl + N·pg), would leave much of the weight to the
        // few gather rays that hit a small light from afar, whose count varies from tixel to
        // tixel: noise between neighbours; docs/benchmarks.md, Per-tixel noise.)
        const float sPl = float(lightSamples) * sample.areaPdf * dist2 / cosY;
        const float nPg = float(n) * kInvPi * cosX;
        const std::optional<Ray> ray =
            shadowRayTo(cosSigned < 0.0f ? originBehind : origin, emitterShadowTarget(sample.point, em.normal, wi));
        if (!ray) continue;
        rays.push_back(*ray);
        pending.push_back({g, wi, em.radiance * sample.modulation * (cosX / sPl * powerHeuristic(sPl, nPg)), true});
      }
    }
    std::vector<uint8_t> occluded(rays.size());
    // A tixel's rays leave one point towards the same lights: coherent.
    accel.occludedCoherent(rays, occluded);
    shadowRays += rays.size() + glassRays;
    for (size_t r = 0; r < rays.size(); ++r)
      if (!occluded[r]) seen.push_back(pending[r]);
    for (const Pending& p : seen) {
      const Chart& c = param.charts[param.tixelChart[p.tixel]];
      const uint64_t vb = valueBase(p.tixel, c);
      if (c.kind == ChartKind::Diffuse) {
        direct[vb] += p.irradiance;
        if (c.directionalIrradiance) addTiltedIrradiance(scene, param, c, p.tixel, p.wi, p.irradiance, &direct[vb + 1]);
      } else {
        const GlossyMaterial& gm = glossy[c.material];  // its texel directions
        const GlossyMaterial& lobe = gm.lobeAt(param, p.tixel);
        const Bsdf& bsdf = lobe.model;
        const Chart* glass = isRoughGlassChart(c, bsdf) ? &c : nullptr;
        const Vec3 wiLocal = tixelFrame(param, c, p.tixel).toLocal(p.wi);  // the map's frame (a curved chart's own)
        // Delta lights: the BSDF averaged over each output texel (a delta light would
        // otherwise alias between texel centres). Area-light samples are many per tixel and
        // already spread over the emitter: the texel-centre value suffices and costs 9× less.
        // The maps get the model without its diffuse part when the tixel keeps that part's Ẽ.
        const Bsdf mapped = lobe.mappedAt(lobe.diffuse ? lobe.specular : bsdf, param, p.tixel);
        // A delta light's highlight on a reflecting glossy chart is also noted apart, to be
        // taken out of the stored maps at the end (punctualGlossy).
        const bool highlight = !p.areaSample && !glass && !punctualGlossy.empty();
        const Rgb* cellBsdf = lobe.cellBsdf.empty() || !(wiLocal.z > 0.0f)
                                  ? nullptr
                                  : lobe.cellBsdf.data() + gatherCellOf(wiLocal, lobe.gridSide);
        for (uint32_t t = 0; t < c.directionTexels(); ++t) {
          const Rgb reflected = (cellBsdf                ? cellBsdf[size_t(t) * lobe.gridSide * lobe.gridSide]
                                 : p.areaSample ? recordEval(mapped, glass, gm.centres[t], wiLocal)
                                                : texelAverageBsdf(mapped, gm.outputs[t], wiLocal, glass)) *
                                p.irradiance;
          direct[vb + t] += reflected;
          if (highlight) punctualGlossy[vb + t] += reflected;
        }
        if (lobe.diffuse) direct[vb + c.directionTexels()] += diffuseDirectionalFactor(bsdf, wiLocal.z) * p.irradiance;
        if (c.directionalIrradiance)
          addTiltedIrradiance(scene, param, c, p.tixel, p.wi, p.irradiance, &direct[vb + c.directionTexels() + 1]);
      }
    }
    if (progress) progress->advance(t1 - t0);
  });
}

void gatherEmission(TransportState& state, const VisibilityShard& vis, uint64_t begin, uint64_t end) {
  const Scene& scene = state.scene;
  const Parameterisation& param = state.param;
  const BakeSettings& settings = state.settings;
  const std::vector<GlossyMaterial>& glossy = state.ops->glossy;
  GlassFirstShot& glassFirstShot = *state.ops->glassFirstShot;
  const std::vector<float>& areaPdf = state.ops->areaPdf;
  const LightSampler& lights = state.ops->lights;
  // The light sampler's area density on the emitter a gather ray found in tixel `tixel` of
  // chart c: per material when untextured, else the triangle's under the tixel's gather point.
  auto emitterAreaPdfOf = [&](const Chart& c, uint64_t tixel) {
    if (!texturedEmitter(scene, c)) return areaPdf[c.material];
    const auto [mesh, triangle] = param.emitterTriangle[tixel];
    return lights.emitterAreaPdf(mesh, triangle);
  };
  const uint32_t lightSamples = state.ops->lightSamples, n = state.n;
  const uint64_t tixels = param.tixelCount;
  std::vector<Rgb>& direct = state.direct;
  if (!vis.holds(begin, end) || end > param.tixelCount || vis.field.gridSide != state.gridSide)
    fail("{}: the visibility field (holding {} tixels × {}² directions) does not fit tixels [{}, {}) of the "
         "parameterisation ({} tixels) and the settings ({}² directions)",
         scene.sourcePath, vis.field.tixelCount, vis.field.gridSide, begin, end, param.tixelCount, state.gridSide);

  // Emission and environment arriving through the gather rays (constant over the iteration).
  const Environment& environment = scene.environment;
  // Per tixel: whether its chart emits from the front (bit 0) and from the back (bit 1), so
  // that the pass below looks the seen chart and material up only for entries that see light.
  // One more element, for the escaped entries (kEscape is above every index): both bits when
  // the environment is lit. With it the test below needs no branch on escaped-or-not, which
  // would be mispredicted at random (a fifth to a half of the entries of an open scene escape).
  std::vector<uint8_t> tixelEmits(tixels + 1, 0);
  for (const Chart& c : param.charts) {
    const Material& material = scene.materials[c.material];
    if (!material.isEmissive()) continue;
    const uint8_t bits = uint8_t((isBlack(chartEmittedRadiance(material, c, 1.0f)) ? 0 : 1) |
                                 (isBlack(chartEmittedRadiance(material, c, -1.0f)) ? 0 : 2));
    std::fill_n(tixelEmits.begin() + int64_t(c.firstTixel), c.tixelCount(), bits);
  }
  tixelEmits[tixels] = environment.isBlack() ? 0 : 3;
  vis.forEachSpan(begin, end, 16, [&](uint64_t t0, uint64_t t1, EntryReader& reader) {
    std::vector<Lanes4> incoming(n);  // per gather cell, kept for glossy tixels
    std::vector<VisibilityEntry> decoded(n);
    std::vector<uint8_t> subCells;
    for (uint64_t g = t0; g < t1; ++g) {
      const Chart& c = param.charts[param.tixelChart[g]];
      if (c.kind == ChartKind::Specular) continue;
      const VisibilityEntry* entries = reader.entries(g, decoded.data());
      const VisibilityExtra* extras = vis.extras(g);
      uint64_t cursor = 0;
      const TixelFrame frame = tixelFrame(param, c, g);  // the gather rays' frame (visibility.cpp)
      subCells.clear();  // this tixel's gather sub-cells, computed when first needed
      auto direction = [&](uint32_t k) {
        if (subCells.empty()) gatherSubCells(g, state.gridSide, settings.seed, subCells);
        return gatherCellDirection(k, subCells[k], state.gridSide, settings.seed);
      };
      const bool keepIncoming = c.kind == ChartKind::Glossy || c.directionalIrradiance;
      // Emitters seen through mirrors and glass are the caustic pass's on diffuse tixels.
      const bool emittersViaMirror = !(state.caustics && c.kind == ChartKind::Diffuse);
      bool any = false;
      Rgb sum(0.0f);  // Σ_k L_k in gather order
      for (uint32_t k = 0; k < n; ++k) {
        const VisibilityEntry e = entries[k];
        const VisibilityExtra* extra = e.hasExtra() ? &extras[cursor++] : nullptr;
        // Most entries see neither a lit sky nor an emitter: they add nothing (skipping them
        // leaves every sum the same; this pass reads every entry of the field).
        if (((tixelEmits[std::min<uint64_t>(e.tixel(), tixels)] >> (e.backSide() ? 1 : 0)) & 1) == 0) {
          if (keepIncoming) incoming[k] = Lanes4{};
          continue;
        }
        Rgb L(0.0f);
        if (e.escaped()) {
          // The environment in the direction the path left: the gather direction itself, or
          // after mirrors the final direction stored with the path.
          const Vec3 leaving = extra ? octahedralDecode(extra->st)
                                     : frame.toWorld(direction(k));
          L = environment.radiance(leaving);
        } else {
          const Chart& seen = param.charts[param.tixelChart[e.tixel()]];
          const Rgb emitted = tixelEmittedRadiance(scene, param, seen, e.tixel(), e.backSide() ? -1.0f : 1.0f);
          if (!isBlack(emitted) && (emittersViaMirror || !(extra && extra->viaMirror))) {
            float weight = 1.0f;
            const float seenAreaPdf = emitterAreaPdfOf(seen, e.tixel());
            if (lightSamples > 0 && !(extra && extra->viaMirror) && seenAreaPdf > 0.0f) {
              // The same power heuristic as the shadow rays, evaluated for this gather ray
              // against the seen chart's plane (exact for a direct hit on a planar emitter).
              const Vec3 local = direction(k);
              const Vec3 w = glm::normalize(frame.toWorld(local));
              const Vec3 o = offsetRayOrigin(param.gatherPoint[g], frame.n, w);
              const float denom = glm::dot(w, seen.normal);
              const float t = denom != 0.0f ? glm::dot(seen.origin - o, seen.normal) / denom : 0.0f;
              const float cosY = std::abs(denom);
              const float pl = t > 0.0f && cosY > 0.0f ? seenAreaPdf * t * t / cosY : 0.0f;
              const float pg = local.z * kInvPi;
              weight = pl > 0.0f ? powerHeuristic(float(n) * pg, float(lightSamples) * pl) : 1.0f;
            }
            L = emitted * weight;
          }
        }
        if (extra) L *= extra->throughput;
        if (keepIncoming) incoming[k] = lanes4(L);
        sum += L;
        any = any || !isBlack(L);
      }
      if (Lanes4* glassCells = glassFirstShot.cells(param, g)) std::copy_n(incoming.data(), n, glassCells);
      if (!any) continue;
      const uint64_t vb = valueBase(g, c);
      if (c.kind == ChartKind::Diffuse) {
        direct[vb] += sum * (kPi / float(n));
        if (c.directionalIrradiance) addTiltedGather(state, c, g, incoming.data(), subCells, &direct[vb + 1]);
      } else {
        const GlossyMaterial& gm = glossy[c.material].lobeAt(param, g);
        gm.reflect(c, param, g, incoming.data(), f4FromRgb(sum), direct.data() + vb);
        gm.addDiffuse(c, incoming.data(), direct.data() + vb);
        if (c.directionalIrradiance)
          addTiltedGather(state, c, g, incoming.data(), subCells, direct.data() + vb + c.directionTexels() + 1);
      }
    }
  });
}

void shootCaustics(TransportState& state, Progress* progress) {
  if (!state.caustics) return;
  const Parameterisation& param = state.param;
  const CausticPhotons photons =
      traceCausticPhotons(state.scene, state.accel, param, state.ops->lights, state.settings, progress);
  // In photon order, one tixel at a time: the sums do not depend on the thread count.
  for (const CausticDeposit& d : photons.deposits) {
    const Chart& c = param.charts[param.tixelChart[d.tixel]];
    Rgb* values = &state.direct[valueBase(d.tixel, c)];
    values[0] += d.irradiance;
    if (c.directionalIrradiance) addTiltedIrradiance(state.scene, param, c, d.tixel, d.wi, d.irradiance, values + 1);
  }
  state.causticPhotons = photons.photons;
  state.causticPhotonsLanded = photons.landed;
  state.causticSeconds = photons.seconds;
}

void finishFirstShot(TransportState& state) {
  // Every range has gathered its first shot: each rough-glass record adds its twin's.
  state.ops->glassFirstShot->addTransmission(state.param, state.ops->glossy, state.direct);
}

namespace {

/// Subsurface charts (subsurface.h): every subsurface tixel j's value from the irradiance the
/// subsurface tixels gathered at their last update, M_j = Σ_i K[j ← i]·E_i, stored as M_j / ρ̄_j
/// (0 in a channel where the transport albedo ρ̄_j is 0) so that its transport quad, ρ̄·value/π,
/// and the renderers' albedo·value/π show M_j/π; with its change. The transport of the
/// subsurface charts is refreshed when `refresh` (beginIteration refreshes every tixel's).
void applySubsurface(TransportState& state, bool refresh) {
  TransportState::Operators& ops = *state.ops;
  if (ops.subsurface.empty()) return;
  const Parameterisation& param = state.param;
  std::vector<Rgb> exitance;
  applySubsurfaceOperator(ops.subsurface, ops.subsurfaceIrradiance, exitance);
  parallelForRange(exitance.size(), 1024, [&](uint64_t r0, uint64_t r1) {
    for (uint64_t r = r0; r < r1; ++r) {
      const uint64_t g = ops.subsurface.rowTixel[r];
      const Chart& c = param.charts[param.tixelChart[g]];
      const Rgb albedo = param.transportAlbedo[g];
      Rgb& value = state.current[valueBase(g, c)];
      const Rgb before = value;
      for (int k = 0; k < 3; ++k) value[k] = albedo[k] > 0.0f ? exitance[r][k] / albedo[k] : 0.0f;
      state.change[g] = exitanceChange(state, &before, &value, g, c);
    }
  });
  if (!refresh) return;
  for (size_t ci = 0; ci < param.charts.size(); ++ci)
    if (ops.subsurfaceChart[ci])
      updateTransport(state, param.charts[ci].firstTixel, param.charts[ci].firstTixel + param.charts[ci].tixelCount());
}

}  // namespace

void subsurfaceDirectChange(const TransportState& state, std::vector<Rgb>& delta) {
  const TransportState::Operators& ops = *state.ops;
  if (ops.subsurface.empty()) return;
  const Parameterisation& param = state.param;
  std::vector<Rgb> entering(param.tixelCount, Rgb(0.0f)), leaving;
  for (const uint64_t g : ops.subsurface.rowTixel) entering[g] = delta[valueBase(g, param.charts[param.tixelChart[g]])];
  applySubsurfaceOperator(ops.subsurface, entering, leaving);
  for (size_t r = 0; r < leaving.size(); ++r) {
    const uint64_t g = ops.subsurface.rowTixel[r];
    const Rgb albedo = param.transportAlbedo[g];
    Rgb& value = delta[valueBase(g, param.charts[param.tixelChart[g]])];
    for (int k = 0; k < 3; ++k) value[k] = albedo[k] > 0.0f ? leaving[r][k] / albedo[k] : 0.0f;
  }
}

void beginIteration(TransportState& state) {
  requireFiniteValues(state.scene, state.param, state.direct, "in the first shot (direct light)");
  state.current = state.direct;
  // Subsurface tixels: what leaves them of the first shot's light entering the object.
  for (const uint64_t g : state.ops->subsurface.rowTixel)
    state.ops->subsurfaceIrradiance[g] = state.direct[valueBase(g, state.param.charts[state.param.tixelChart[g]])];
  applySubsurface(state, false);
  state.ops->quads.assign(state.param.tixelCount + 1, TransportQuad{});
  updateTransport(state, 0, state.param.tixelCount);
}

void updateTransport(TransportState& state, uint64_t begin, uint64_t end) {
  const Parameterisation& param = state.param;
  TransportState::Operators& ops = *state.ops;
  const std::vector<Rgb>& current = state.current;
  // The quads of tixels [begin, end). A quad is rewritten only after its batch has been
  // updated, so during the batch it still holds the previous iteration's values (Gauss–Seidel
  // between batches, Jacobi inside).
  parallelForRange(end - begin, 256, [&](uint64_t t0, uint64_t t1) {
    for (uint64_t g = begin + t0; g < begin + t1; ++g) {
      const Chart& c = param.charts[param.tixelChart[g]];
      TransportQuad& q = ops.quads[g];
      q = TransportQuad{};
      if (c.kind != ChartKind::Diffuse) continue;
      const uint64_t local = g - c.firstTixel;
      const uint32_t i = uint32_t(local % c.resU), j = uint32_t(local / c.resU);
      auto transport = [&](uint64_t tixel) {
        const Rgb* values = &current[valueBase(tixel, c)];
        return param.transportAlbedo[tixel] * transportIrradiance(param, c, tixel, values) * kInvPi;
      };
      const bool right = i + 1 < c.resU, up = j + 1 < c.resV;
      const Rgb t00 = transport(g), t10 = right ? transport(g + 1) : Rgb(0.0f),
                t01 = up ? transport(g + c.resU) : Rgb(0.0f), t11 = right && up ? transport(g + c.resU + 1) : Rgb(0.0f);
      const Rgb coefficients[4] = {t00, t10 - t00, t01 - t00, t11 - t10 - t01 + t00};
      for (int k = 0; k < 4; ++k) {
        q.coefficient[k][0] = coefficients[k].r;
        q.coefficient[k][1] = coefficients[k].g;
        q.coefficient[k][2] = coefficients[k].b;
      }
    }
  });
}

namespace {

/// The radiance a gather entry with an extra record, or one that hit a back side, brings
/// (gatherTixel's slow path) while tixels [begin, end) are being updated: a glossy chart
/// overlapping that range is read at its previous values, every other chart at current.
Rgb slowPathRadiance(const TransportState& state, VisibilityEntry e, const VisibilityExtra* extra, uint64_t begin,
                     uint64_t end) {
  // Back-side hits see the inside of a closed solid (a two-sided chart's back is its
  // own record): no reflected light. Emission from behind is in the constant part.
  if (!extra || e.escaped() || e.backSide()) return Rgb(0.0f);
  const Parameterisation& param = state.param;
  const uint32_t base = e.tixel();
  const uint32_t seenChart = param.tixelChart[base];
  const Chart& seen = param.charts[seenChart];
  Rgb L(0.0f);
  if (seen.kind == ChartKind::Diffuse) {
    L = f4Rgb(lookupQuad(state.ops->quads[base], e));
  } else if (seen.kind == ChartKind::Glossy) {
    const bool sameBatch = seen.firstTixel < end && seen.firstTixel + seen.tixelCount() > begin;
    const float fu = float(e.fu) * (1.0f / 65535.0f), fv = float(e.fv) * (1.0f / 65535.0f);
    const uint64_t local = base - seen.firstTixel;
    const Vec2 grid(float(local % seen.resU) + fu, float(local / seen.resU) + fv);
    const Rgb* values = sameBatch ? state.previousValues.data() : state.current.data();
    L = interpolateValues(values, seen, grid, extra->st);
    if (seen.diffuseValue) L += glossyDiffuseRadiance(state, values, seen, grid, extra->st);
  }
  return L * extra->throughput;
}

}  // namespace

void gatherIteration(TransportState& state, const VisibilityShard& vis, uint64_t begin, uint64_t end, float omega) {
  const Parameterisation& param = state.param;
  TransportState::Operators& ops = *state.ops;
  const std::vector<GlossyMaterial>& glossy = ops.glossy;
  const uint32_t n = state.n;
  const std::vector<Rgb>& direct = state.direct;
  const std::vector<Rgb>& previousValues = state.previousValues;
  std::vector<Rgb>& current = state.current;
  std::vector<float>& change = state.change;
  vis.forEachSpan(begin, end, 16, [&](uint64_t g0, uint64_t g1, EntryReader& reader) {
    std::vector<Lanes4> incoming(n), twinIncoming, slowValues(n);
    std::vector<VisibilityEntry> twinDecoded;
    EntryPipeline pipeline(reader, n);
    std::optional<EntryReader> twinReader;  // rough glass: the twin record's tixels, elsewhere in the field
    std::vector<uint8_t> subCells;
    auto gathered = [&](uint64_t g) { return param.charts[param.tixelChart[g]].kind != ChartKind::Specular; };
    for (uint64_t g = g0; g < g1; ++g) {
      const Chart& c = param.charts[param.tixelChart[g]];
      if (c.kind == ChartKind::Specular) continue;
      auto slowPath = [&](VisibilityEntry e, const VisibilityExtra* extra) {
        return slowPathRadiance(state, e, extra, begin, end);
      };
      const VisibilityEntry* entries = pipeline.take(g, ops.quads.data(), ops.quads.size());
      uint64_t next = g + 1;
      while (next < g1 && !gathered(next)) ++next;
      const VisibilityEntry* ahead = next < g1 ? pipeline.ahead(next) : nullptr;
      const VisibilityExtra* extras = vis.extras(g);
      const uint64_t extraCount = vis.extraCount(g);
      const F4 sum = c.kind == ChartKind::Glossy || c.directionalIrradiance
                         ? gatherTixel<true>(entries, ahead, n, ops.quads.data(), ops.quads.size(), extras, extraCount,
                                             slowValues.data(), incoming.data(), slowPath)
                         : gatherTixel<false>(entries, ahead, n, ops.quads.data(), ops.quads.size(), extras, extraCount,
                                              slowValues.data(), nullptr, slowPath);
      const uint64_t vb = valueBase(g, c);
      auto relax = [&](const Rgb& before, const Rgb& update) { return glm::max(Rgb(0.0f), before + omega * (update - before)); };
      if (c.kind == ChartKind::Diffuse && !ops.subsurfaceChart.empty() && ops.subsurfaceChart[param.tixelChart[g]]) {
        // A subsurface tixel: its irradiance enters the object (applySubsurface, after the batches).
        ops.subsurfaceIrradiance[g] = direct[vb] + f4Rgb(sum) * (kPi / float(n));
      } else if (c.kind == ChartKind::Diffuse) {
        const Rgb before = current[vb];
        current[vb] = relax(before, direct[vb] + f4Rgb(sum) * (kPi / float(n)));
        if (c.directionalIrradiance) {
          Rgb tilted[kTiltedNormals] = {direct[vb + 1], direct[vb + 2], direct[vb + 3]};
          addTiltedGather(state, c, g, incoming.data(), subCells, tilted);
          for (uint32_t k = 0; k < kTiltedNormals; ++k) current[vb + 1 + k] = relax(current[vb + 1 + k], tilted[k]);
        }
        change[g] = exitanceChange(state, &before, &current[vb], g, c);
      } else {
        Rgb* out = current.data() + vb;
        std::copy_n(direct.data() + vb, c.valuesPerTixel(), out);
        const GlossyMaterial& gm = glossy[c.material].lobeAt(param, g);
        gm.reflect(c, param, g, incoming.data(), sum, out);
        gm.addDiffuse(c, incoming.data(), out);
        if (c.directionalIrradiance) addTiltedGather(state, c, g, incoming.data(), subCells, out + c.directionTexels() + 1);
        if (gm.glass) {
          // Rough glass: plus the transmission of what the twin record gathers now.
          const uint64_t twin = twinTixel(param, g);
          twinIncoming.resize(n);
          twinDecoded.resize(n);
          if (!twinReader) twinReader.emplace(vis);
          const F4 twinSum = gatherTixel<true>(twinReader->entries(twin, twinDecoded.data()), nullptr, n, ops.quads.data(),
                                               ops.quads.size(), vis.extras(twin), vis.extraCount(twin),
                                               slowValues.data(), twinIncoming.data(), slowPath);
          gm.transmission[c.isBack ? 1 : 0].apply(twinIncoming.data(), twinSum, out);
        }
        const Rgb* before = previousValues.data() + vb;
        for (uint32_t t = 0; t < c.valuesPerTixel(); ++t) out[t] = relax(before[t], out[t]);
        change[g] = exitanceChange(state, before, out, g, c);
      }
    }
  });
}

void recomputeChange(TransportState& state, const std::vector<Rgb>& before, uint64_t begin, uint64_t end) {
  const Parameterisation& param = state.param;
  parallelForRange(end - begin, 256, [&](uint64_t t0, uint64_t t1) {
    for (uint64_t g = begin + t0; g < begin + t1; ++g) {
      const Chart& c = param.charts[param.tixelChart[g]];
      if (c.kind == ChartKind::Specular) continue;
      const uint64_t vb = valueBase(g, c);
      state.change[g] = exitanceChange(state, before.data() + vb, state.current.data() + vb, g, c);
    }
  });
}

double transportPower(const TransportState& state, const std::vector<Rgb>& values) {
  return areaWeightedSum(state.param,
                         [&](uint64_t g, const Chart& c, uint64_t vb) { return exitance(state, values.data() + vb, g, c); });
}

double transportChange(const TransportState& state) {
  return areaWeightedSum(state.param, [&](uint64_t g, const Chart&, uint64_t) { return double(state.change[g]); });
}

void finishTransport(TransportState& state) { finishValues(state, state.current); }

void finishValues(const TransportState& state, std::vector<Rgb>& current) {
  const Scene& scene = state.scene;
  const Parameterisation& param = state.param;
  // The punctual lights' direct highlights leave the stored maps (lightfield.h "Punctual
  // highlights"): the renderers evaluate them per pixel.
  if (!state.punctualGlossy.empty())
    for (uint64_t v = 0; v < current.size(); ++v) current[v] = glm::max(Rgb(0.0f), current[v] - state.punctualGlossy[v]);
  // Glossy values carry their emission (towards the record's own side) from here on; diffuse
  // ones stay irradiance.
  for (const Chart& c : param.charts) {
    if (c.kind != ChartKind::Glossy) continue;
    if (isBlack(chartEmittedRadiance(scene.materials[c.material], c, 1.0f))) continue;
    for (uint64_t local = 0; local < c.tixelCount(); ++local) {  // the maps, not a diffuse value
      // A textured emitter's at tixel resolution: its mean over the tixel (tixelEmittedRadiance).
      const Rgb le = tixelEmittedRadiance(scene, param, c, c.firstTixel + local, 1.0f);
      for (uint64_t t = 0; t < c.directionTexels(); ++t) current[c.firstValue + local * c.valuesPerTixel() + t] += le;
    }
  }
  requireFiniteValues(scene, param, current, "when adding the glossy charts' emission");
}

PropagationResult propagate(const Scene& scene, const Accel& accel, const Parameterisation& param,
                            const VisibilityField& vis, const BakeSettings& settings) {
  return propagate(scene, accel, param, [&]() -> const VisibilityField& { return vis; }, settings);
}

PropagationResult propagate(const Scene& scene, const Accel& accel, const Parameterisation& param,
                            const std::function<const VisibilityField&()>& visibility, const BakeSettings& settings) {
  SingleProcess single;
  const ShardPlan plan = planShards(scene, param, settings, 1);
  VisibilityShard shard;
  return propagate(scene, accel, param, [&]() -> const VisibilityShard& {
    shard = VisibilityShard::whole(visibility());
    return shard;
  }, settings, single, plan);
}

namespace {

/// The exchange step of a distributed propagation: after a batch, every rank's part of its
/// values is copied to every other rank (in place: values are in tixel order, so a part is one
/// contiguous run of values). Nothing to do for one rank.
class ValueExchange {
 public:
  ValueExchange(const Parameterisation& param, const ShardPlan& plan, Communicator& comm)
      : param_(param), plan_(plan), comm_(comm), displacement_(size_t(comm.size())), count_(size_t(comm.size())) {}

  /// Exchanges every rank's part of batch b of `values`.
  void batch(std::vector<Rgb>& values, size_t b) {
    const int ranks = comm_.size();
    if (ranks == 1) return;
    const auto start = std::chrono::steady_clock::now();
    for (int r = 0; r < ranks; ++r) {
      const TixelRange part = plan_.part(b, r);
      const uint64_t v0 = firstValueOf(param_, part.begin), v1 = firstValueOf(param_, part.end);
      displacement_[size_t(r)] = v0 * sizeof(Rgb);
      count_[size_t(r)] = (v1 - v0) * sizeof(Rgb);
    }
    comm_.allgatherv(values.data(), displacement_, count_);
    seconds_ += secondsSince(start);
  }
  /// Exchanges every batch of `values`.
  void all(std::vector<Rgb>& values) {
    for (size_t b = 0; b < plan_.batches(); ++b) batch(values, b);
  }
  /// Exchanges the irradiance (tixel-indexed) that the subsurface tixels `rows` (ascending)
  /// gathered, each on the rank that owns it: every rank's rows packed into one run of a
  /// buffer, one collective per call.
  void subsurface(const std::vector<uint64_t>& rows, std::vector<Rgb>& irradiance) {
    const int ranks = comm_.size();
    if (ranks == 1 || rows.empty()) return;
    const auto start = std::chrono::steady_clock::now();
    if (packedStart_.empty()) {
      // Rank r's rows, in tixel order, are packed[packedStart_[r], packedStart_[r + 1]).
      packedStart_.push_back(0);
      for (int r = 0; r < ranks; ++r) {
        for (const TixelRange& owned : plan_.owned(r))
          for (auto it = std::lower_bound(rows.begin(), rows.end(), owned.begin); it != rows.end() && *it < owned.end; ++it)
            packedTixel_.push_back(*it);
        packedStart_.push_back(packedTixel_.size());
      }
    }
    std::vector<Rgb> packed(packedTixel_.size());
    const int rank = comm_.rank();
    for (uint64_t k = packedStart_[size_t(rank)]; k < packedStart_[size_t(rank) + 1]; ++k)
      packed[k] = irradiance[packedTixel_[k]];
    for (int r = 0; r < ranks; ++r) {
      displacement_[size_t(r)] = packedStart_[size_t(r)] * sizeof(Rgb);
      count_[size_t(r)] = (packedStart_[size_t(r) + 1] - packedStart_[size_t(r)]) * sizeof(Rgb);
    }
    comm_.allgatherv(packed.data(), displacement_, count_);
    for (uint64_t k = 0; k < packed.size(); ++k) irradiance[packedTixel_[k]] = packed[k];
    seconds_ += secondsSince(start);
  }
  /// Time spent inside the exchanges (waiting for the slowest rank included).
  double seconds() const { return seconds_; }

 private:
  const Parameterisation& param_;
  const ShardPlan& plan_;
  Communicator& comm_;
  std::vector<uint64_t> displacement_, count_;
  std::vector<uint64_t> packedTixel_, packedStart_;  ///< the subsurface rows by owning rank (subsurface())
  double seconds_ = 0.0;
};

/// sum += weight ⊙ part, elementwise (the one step of combineFirstShot's sums).
void addWeighted(std::vector<Rgb>& sum, const Rgb& weight, const std::vector<Rgb>& part) {
  parallelForRange(sum.size(), 4096, [&](uint64_t v0, uint64_t v1) {
    for (uint64_t v = v0; v < v1; ++v) sum[v] += weight * part[v];
  });
}

}  // namespace

std::vector<Rgb> combineFirstShot(const Scene& scene, const std::vector<std::vector<Rgb>>& perLight,
                                  const std::vector<Rgb>& rest) {
  uint64_t size = rest.size();
  for (const std::vector<Rgb>& part : perLight) size = std::max<uint64_t>(size, part.size());
  std::vector<Rgb> sum(size, Rgb(0.0f));
  for (size_t l = 0; l < perLight.size() && l < scene.lights.size(); ++l) {
    const Rgb emission = lightEmission(scene.lights[l]);
    if (!perLight[l].empty() && !isBlack(emission)) addWeighted(sum, emission, perLight[l]);
  }
  if (!rest.empty())
    parallelForRange(size, 4096, [&](uint64_t v0, uint64_t v1) {
      for (uint64_t v = v0; v < v1; ++v) sum[v] += rest[v];
    });
  return sum;
}

namespace {

/// The first shot of this rank's tixels: shadow rays, then (the visibility field obtained,
/// its time returned in waitSeconds) the gathered emission, then the exchange of the direct
/// values. Returns the visibility field. The shadow rays are shot by source — each scene light
/// on its own at unit emission (D_l), then the emissive surfaces — and the first shot is
/// combineFirstShot's sum of the parts, so that it is the same whether or not `bySource` keeps
/// them (one process keeps them for the .pls; bake/first_shot.h) and the same as a relight's.
const VisibilityShard& shootFirstShot(TransportState& state, const ShardPlan& plan, int rank,
                                      const std::function<const VisibilityShard&()>& visibility,
                                      ValueExchange& exchange, double& waitSeconds, FirstShotBySource* bySource) {
  const std::vector<TixelRange> own = plan.owned(rank);
  uint64_t ownTixels = 0;
  for (const TixelRange& r : own) ownTixels += r.size();
  const Scene& scene = state.scene;
  const uint64_t valueCount = state.param.valueCount;
  const bool punctual = !state.punctualGlossy.empty();
  // Σ_l E_l ⊙ D_l and its punctual part, in light order (combineFirstShot's first sum).
  std::vector<Rgb> lightSum(valueCount, Rgb(0.0f)), punctualSum(punctual ? valueCount : 0, Rgb(0.0f));
  {
    Progress progress("direct light", ownTixels * (scene.lights.size() + 1));
    for (size_t l = 0; l < scene.lights.size(); ++l) {
      std::vector<Rgb> direct(valueCount, Rgb(0.0f)), punctualPart(punctual ? valueCount : 0, Rgb(0.0f));
      std::swap(state.direct, direct);
      std::swap(state.punctualGlossy, punctualPart);
      ShadowRaySources only;
      only.lights.assign(scene.lights.size(), 0);
      only.lights[l] = 1;
      only.emitters = false;
      only.unitEmission = true;
      for (const TixelRange& r : own) shootShadowRays(state, r.begin, r.end, &progress, only);
      std::swap(state.direct, direct);
      std::swap(state.punctualGlossy, punctualPart);
      const Rgb emission = lightEmission(scene.lights[l]);
      if (!isBlack(emission)) {
        addWeighted(lightSum, emission, direct);
        if (punctual) addWeighted(punctualSum, emission, punctualPart);
      }
      if (bySource) {
        bySource->lightDirect.push_back(std::move(direct));
        if (punctual) bySource->lightPunctual.push_back(std::move(punctualPart));
      }
    }
    ShadowRaySources emitters;
    emitters.lights.assign(scene.lights.size(), 0);
    for (const TixelRange& r : own) shootShadowRays(state, r.begin, r.end, &progress, emitters);
  }
  // From here on the visibility field is needed. Time spent obtaining it (waiting for a read
  // that overlapped the shadow rays, or tracing it) is not propagation time.
  const auto waitStart = std::chrono::steady_clock::now();
  const VisibilityShard& vis = visibility();
  waitSeconds = secondsSince(waitStart);
  // The rank's own tixels and the rough-glass twins it holds (whose gathered cells its own
  // glass records transmit; their direct values are replaced by the exchange below).
  for (const TixelRange& r : vis.ranges) gatherEmission(state, vis, r.begin, r.end);
  if (state.caustics) {
    Progress progress("caustics", state.settings.causticPhotons);
    shootCaustics(state, &progress);
  }
  finishFirstShot(state);
  // state.direct is D_e now: the first shot is Σ_l E_l ⊙ D_l + D_e.
  if (bySource) bySource->emitterDirect = state.direct;
  parallelForRange(valueCount, 4096, [&](uint64_t v0, uint64_t v1) {
    for (uint64_t v = v0; v < v1; ++v) lightSum[v] += state.direct[v];
  });
  state.direct = std::move(lightSum);
  if (punctual) state.punctualGlossy = std::move(punctualSum);
  exchange.all(state.direct);
  if (!state.punctualGlossy.empty()) exchange.all(state.punctualGlossy);
  return vis;
}

// The iteration is Gauss–Seidel by batches of whole charts: batches are updated one after
// another, so a batch already sees this iteration's values of the batches before it (about
// half the iterations of Jacobi). Inside a batch, tixels are updated in parallel and read the
// previous iteration's values of their own batch, so no value is read while it is written
// and the result does not depend on thread timing.
//
// Over-relaxed (SOR): a tixel's new values are old + ω·(update − old), clamped at 0. Plain
// Gauss–Seidel (ω = 1) from the first shot only ever adds light, so it approaches the
// solution from below, each iteration closing a fixed fraction (1 − ρ) of the gap; stepping
// past the update by ω − 1 closes more of it: ω = 1.2 takes a third to a half fewer
// iterations than ω = 1 on the Cornell boxes (docs/benchmarks.md, Propagation iterations);
// SOR cannot converge for ω ≥ 2. If the L1 change grows after the second iteration, the rest
// of the iteration falls back to ω = 1, which converges for any ρ < 1.
//
// Distributed (shard.h): a rank updates its part of each batch, the parts are exchanged
// before the next batch, and the batch's transport is refreshed on every rank from the
// exchanged values, so each batch still sees this iteration's values of the batches before
// it. The stopping rule then runs on every rank over the same values in the same order.
// (kOverRelaxation, propagation.h.)

/// One iteration: every batch in order, this rank's part gathered (gatherIteration), the
/// parts exchanged, the batch's transport refreshed and the change of the other ranks'
/// tixels measured from the iteration's starting values. Adds its times to `result`.
void iterateOnce(TransportState& state, const VisibilityShard& vis, const ShardPlan& plan, int rank, float omega,
                 ValueExchange& exchange, bool keepPrevious, PropagationResult& result) {
  const std::vector<uint64_t>& batchStart = state.batchStart;
  auto repeatedStart = std::chrono::steady_clock::now();
  // The iteration's starting values are also what the change of the tixels other ranks
  // updated is measured from (recomputeChange).
  if (keepPrevious) state.previousValues = state.current;
  result.repeatedSeconds += secondsSince(repeatedStart);
  for (size_t batch = 0; batch + 1 < batchStart.size(); ++batch) {
    const uint64_t begin = batchStart[batch], end = batchStart[batch + 1];
    const TixelRange mine = plan.part(batch, rank);
    const auto gatherStart = std::chrono::steady_clock::now();
    gatherIteration(state, vis, mine.begin, mine.end, omega);
    result.gatherSeconds += secondsSince(gatherStart);
    exchange.batch(state.current, batch);
    repeatedStart = std::chrono::steady_clock::now();
    updateTransport(state, begin, end);
    for (int r = 0; r < plan.ranks; ++r) {
      const TixelRange theirs = plan.part(batch, r);
      if (r != rank) recomputeChange(state, state.previousValues, theirs.begin, theirs.end);
    }
    result.repeatedSeconds += secondsSince(repeatedStart);
  }
  // Subsurface tixels: the light that entered them this iteration (gathered by their owners,
  // exchanged) leaves through the object; every rank applies the whole operator.
  exchange.subsurface(state.ops->subsurface.rowTixel, state.ops->subsurfaceIrradiance);
  applySubsurface(state, true);
}

/// The iteration, from the first shot (or a checkpoint's iterate: resume.from) to convergence
/// (StoppingRule) or maxIterations, handing its state to resume.save after every iteration.
void iterate(TransportState& state, const VisibilityShard& vis, const ShardPlan& plan, int rank, ValueExchange& exchange,
             const PropagationOptions& resume, PropagationResult& result) {
  const Scene& scene = state.scene;
  const Parameterisation& param = state.param;
  const BakeSettings& settings = state.settings;
  beginIteration(state);
  // The previous iteration's values are needed only by lookups in glossy charts of the batch
  // being updated (diffuse lookups read the quads, which lag by a batch), and by the change of
  // the tixels other ranks updated.
  const bool keepPrevious = keepsPreviousValues(param) || plan.ranks > 1;
  StoppingRule stopping(transportPower(state, state.current), settings.tolerance);
  PropagationProgress at;
  at.shadowRays = state.shadowRays.load();
  at.causticPhotons = state.causticPhotons;
  at.causticPhotonsLanded = state.causticPhotonsLanded;
  if (resume.from) {
    // After a full iteration every transport quad is its tixel's function of current
    // (updateTransport), so the iterate alone gives the state the next iteration starts from.
    at = resume.from->progress;
    state.current = resume.from->current;
    updateTransport(state, 0, param.tixelCount);
    stopping = StoppingRule(at, settings.tolerance);
    result.iterations = at.iterations;
    result.residual = at.residual;
  }
  Progress progress("propagation", settings.maxIterations);
  progress.advance(at.iterations);
  for (uint32_t iteration = at.iterations + 1; iteration <= settings.maxIterations && !at.converged; ++iteration) {
    iterateOnce(state, vis, plan, rank, stopping.omega(), exchange, keepPrevious, result);
    const auto repeatedStart = std::chrono::steady_clock::now();
    const double power = transportPower(state, state.current);
    if (!std::isfinite(power)) {
      requireFiniteValues(scene, param, state.current, fmt::format("in iteration {}", iteration));
      fail("{}: light propagation overflowed in iteration {}: the total power is not finite; scale the emission down",
           scene.sourcePath, iteration);
    }
    const double changed = transportChange(state);
    result.repeatedSeconds += secondsSince(repeatedStart);
    progress.advance(1);
    at.converged = stopping.converged(iteration, power, changed, result);
    at.iterations = iteration;
    at.residual = result.residual;
    stopping.save(at);
    if (resume.save) resume.save(at, state);
  }
  // Converged (or resumed converged): the iterations left are not needed, so the bar completes.
  progress.advance(settings.maxIterations - std::min(settings.maxIterations, at.iterations));
  progress.finish();
}

}  // namespace

bool keepsPreviousValues(const Parameterisation& param) {
  return std::any_of(param.charts.begin(), param.charts.end(), [](const Chart& c) { return c.kind == ChartKind::Glossy; });
}

void iterateTransport(TransportState& state, const VisibilityShard& vis, float omega) {
  SingleProcess single;
  const ShardPlan plan = planShards(state.scene, state.param, state.settings, 1);
  ValueExchange exchange(state.param, plan, single);
  PropagationResult times;
  iterateOnce(state, vis, plan, 0, omega, exchange, keepsPreviousValues(state.param), times);
}

PropagationResult propagate(const Scene& scene, const Accel& accel, const Parameterisation& param,
                            const std::function<const VisibilityShard&()>& visibility, const BakeSettings& settings,
                            Communicator& comm, const ShardPlan& plan, const PropagationOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  PropagationResult result;
  const uint64_t bytesBefore = comm.bytesReceived();  // the subsurface walks' exchange included
  TransportState state(scene, accel, param, settings, &comm);
  const int rank = comm.rank(), ranks = comm.size();
  if (plan.ranks != ranks || plan.batchStart != state.batchStart)
    fail("{}: the shard plan ({} ranks, {} batches) does not fit this propagation ({} ranks, {} batches)", scene.sourcePath,
         plan.ranks, plan.batches(), ranks, state.batchStart.size() - 1);
  ValueExchange exchange(param, plan, comm);
  result.subsurfaceSeconds = state.ops->subsurface.seconds;
  result.subsurfaceTixels = state.ops->subsurface.rowTixel.size();
  result.subsurfaceWalks = state.ops->subsurface.walks;
  result.subsurfaceWalkedHere = state.ops->subsurface.walkedHere;
  result.subsurfaceRays = state.ops->subsurface.rays;
  result.subsurfaceEntries = state.ops->subsurface.entries();
  result.subsurfaceBytes = state.ops->subsurface.bytes();

  double waitSeconds = 0.0;
  const VisibilityShard* vis = nullptr;
  if (options.from) {
    // The checkpoint holds the first shot (every rank's: the direct values were exchanged).
    const auto waitStart = std::chrono::steady_clock::now();
    vis = &visibility();
    waitSeconds = secondsSince(waitStart);
    state.direct = options.from->direct;
    state.punctualGlossy = options.from->punctualGlossy;
    state.shadowRays = options.from->progress.shadowRays;
    state.causticPhotons = options.from->progress.causticPhotons;
    state.causticPhotonsLanded = options.from->progress.causticPhotonsLanded;
  } else {
    if (options.keepFirstShotBySource) result.firstShotBySource.emplace();
    vis = &shootFirstShot(state, plan, rank, visibility, exchange, waitSeconds,
                          result.firstShotBySource ? &*result.firstShotBySource : nullptr);
  }
  result.firstShotSeconds = secondsSince(start) - waitSeconds;
  iterate(state, *vis, plan, rank, exchange, options, result);
  finishTransport(state);

  result.values = std::move(state.current);
  result.direct = std::move(state.direct);
  result.shadowRays = comm.sum(state.shadowRays.load());
  result.causticPhotons = state.causticPhotons;
  result.causticPhotonsLanded = state.causticPhotonsLanded;
  result.causticSeconds = state.causticSeconds;
  result.exchangeBytes = comm.bytesReceived() - bytesBefore;
  result.exchangeSeconds = exchange.seconds();
  result.seconds = secondsSince(start) - waitSeconds;
  return result;
}

}  // namespace pl
