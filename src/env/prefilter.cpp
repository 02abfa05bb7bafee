// Prefiltered specular maps, the split-sum (DFG) table and the split-sum error analysis
// (ibl.h). Every BRDF value comes from bsdf.h, so the analysis measures the models the
// renderers use.
#include "core/error.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/rng.h"
#include "env/ibl.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>

namespace pl {

namespace {

/// Van der Corput radical inverse in base 2 (the second Hammersley coordinate).
float radicalInverse2(uint32_t bits) {
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return float(bits) * 0x1p-32f;
}
Vec2 hammersley(int i, int n) { return {(float(i) + 0.5f) / float(n), radicalInverse2(uint32_t(i))}; }

float channelMean(const Rgb& c) { return (c.r + c.g + c.b) / 3.0f; }

}  // namespace

SpecularModel parseSpecularModel(const std::string& name) {
  if (name == "ggx") return SpecularModel::Ggx;
  if (name == "blinn-phong") return SpecularModel::BlinnPhong;
  fail("unknown specular model '{}' (expected ggx or blinn-phong)", name);
}

const char* specularModelName(SpecularModel model) { return model == SpecularModel::Ggx ? "ggx" : "blinn-phong"; }

Bsdf specularBsdf(SpecularModel model, float roughness, float f0) {
  const float alpha = ggxAlphaFromRoughness(roughness);
  if (model == SpecularModel::Ggx) return GgxBsdf{Rgb(0.0f), Rgb(f0), alpha};
  return BlinnPhongBsdf{Rgb(0.0f), Rgb(f0), blinnPhongExponentFromAlpha(alpha)};
}

// ─── Pyramid ───────────────────────────────────────────────────────────────────────────────

LatLongPyramid::LatLongPyramid(LatLongMap base) {
  levels.push_back(std::move(base));
  while (levels.back().height() % 2 == 0 && levels.back().height() >= 4)
    levels.push_back(downsampleLatLong(levels.back(), 2));
}

Rgb LatLongPyramid::lookup(const Vec3& dir, double solidAngle) const {
  // Mean texel solid angle of level 0 is 4π/(W·H); each level has 4× larger texels, so the
  // level whose texels match `solidAngle` is ½·log2(solidAngle / Ω0). We read one level
  // sharper than that (texels of about a quarter of the footprint): with the footprint
  // itself the pre-averaging blurs wide lobes measurably (3–6 % on the smooth test lobe of
  // env_test, EnvPrefilter.MatchesQuadratureOfItsDefinition), one level sharper leaves < 1 % with 1024
  // samples. Blend the two neighbouring levels linearly (trilinear filtering).
  const double omega0 = 4.0 * kPiD / (double(levels[0].width()) * levels[0].height());
  const double lod = std::clamp(0.5 * std::log2(std::max(solidAngle, 1e-30) / omega0) - 1.0, 0.0,
                                double(levels.size() - 1));
  const size_t lo = size_t(lod);
  const size_t hi = std::min(lo + 1, levels.size() - 1);
  const float t = float(lod - double(lo));
  const Rgb a = levels[lo].lookup(dir);
  return t > 0.0f ? (1.0f - t) * a + t * levels[hi].lookup(dir) : a;
}

// ─── Prefiltering ──────────────────────────────────────────────────────────────────────────

std::vector<PrefilteredLevel> prefilter(const EnvImage& env, const PrefilterOptions& options) {
  if (options.levels < 1 || options.levels > 32) fail("--levels must be in 1..32 (got {})", options.levels);
  if (options.height < 4) fail("prefiltered map height must be at least 4 (got {})", options.height);
  if (options.samples < 1) fail("prefilter samples must be at least 1 (got {})", options.samples);
  // The pyramid starts at the source resolution (lat-long equivalent), so sharp levels read
  // full-resolution texels and rough ones read pre-averaged ones.
  const LatLongPyramid pyramid(std::holds_alternative<LatLongMap>(env) ? std::get<LatLongMap>(env)
                                                                       : toLatLong(env, equivalentLatLongHeight(env)));
  std::vector<PrefilteredLevel> out;
  uint64_t work = 0;
  for (int k = 0; k < options.levels; ++k) {
    const int h = std::max(16, options.height >> k);
    work += uint64_t(h);
  }
  Progress progress(fmt::format("prefilter ({})", specularModelName(options.model)), work);
  for (int k = 0; k < options.levels; ++k) {
    const float roughness = options.levels == 1 ? 0.0f : float(k) / float(options.levels - 1);
    const int h = std::max(16, options.height >> k);
    PrefilteredLevel level{roughness, LatLongMap{Image(2 * h, h)}};
    if (k == 0 && roughness == 0.0f) {
      // A mirror: P(R) = L(R); only resampling to the level's size.
      level.map = toLatLong(env, h);
      progress.advance(uint64_t(h));
      out.push_back(std::move(level));
      continue;
    }
    const Bsdf bsdf = specularBsdf(options.model, roughness, 1.0f);
    const Vec3 wo(0.0f, 0.0f, 1.0f);  // N = V = R
    // The sample set is the same for every texel (deterministic Hammersley points), so the
    // remaining error is smooth bias rather than per-texel noise. Precompute it in the local
    // frame of R with each sample's weight f·cos/pdf and footprint 1/(N·pdf).
    struct LocalSample {
      Vec3 wi;
      float weight;
      double footprint;
    };
    std::vector<LocalSample> samples;
    for (int i = 0; i < options.samples; ++i) {
      const auto s = sample(bsdf, wo, hammersley(i, options.samples));
      if (!s || s->delta || !(s->pdf > 0.0f)) continue;
      samples.push_back({s->wi, channelMean(s->weight), 1.0 / (double(options.samples) * s->pdf)});
    }
    if (samples.empty()) fail("prefilter: the {} model produced no samples at roughness {}", specularModelName(options.model), roughness);
    parallelFor(uint64_t(h), [&](uint64_t y) {
      for (int x = 0; x < 2 * h; ++x) {
        const Vec3 r = LatLongMap::direction((x + 0.5) / (2.0 * h), (double(y) + 0.5) / h);
        const Frame frame = Frame::fromNormal(r);
        DVec3 sum(0.0);
        double weightSum = 0.0;
        for (const LocalSample& s : samples) {
          sum += double(s.weight) * DVec3(pyramid.lookup(frame.toWorld(s.wi), s.footprint));
          weightSum += s.weight;
        }
        level.map.image.at(x, int(y)) = Rgb(sum / weightSum);
      }
      progress.advance();
    });
    out.push_back(std::move(level));
  }
  progress.finish();
  return out;
}

// ─── DFG ───────────────────────────────────────────────────────────────────────────────────

DfgTerm dfgTerm(SpecularModel model, float roughness, float cosView, int samples) {
  const float c = std::clamp(cosView, 1e-4f, 1.0f);
  const Vec3 wo(std::sqrt(1.0f - c * c), 0.0f, c);
  const Bsdf one = specularBsdf(model, roughness, 1.0f), zero = specularBsdf(model, roughness, 0.0f);
  double e1 = 0.0, e0 = 0.0;
  for (int i = 0; i < samples; ++i) {
    const auto s = sample(one, wo, hammersley(i, samples));
    if (!s || s->delta || !(s->pdf > 0.0f)) continue;  // rejected samples contribute 0
    e1 += channelMean(s->weight);
    e0 += double(channelMean(eval(zero, wo, s->wi))) * s->wi.z / s->pdf;
  }
  e1 /= samples;
  e0 /= samples;
  return {e1 - e0, e0};
}

Image dfgTable(SpecularModel model, int size, int samples) {
  if (size < 2) fail("DFG table size must be at least 2 (got {})", size);
  Image table(size, size);
  Progress progress("split-sum table", uint64_t(size));
  parallelFor(uint64_t(size), [&](uint64_t j) {
    const float roughness = (float(j) + 0.5f) / float(size);
    for (int i = 0; i < size; ++i) {
      const DfgTerm t = dfgTerm(model, roughness, (float(i) + 0.5f) / float(size), samples);
      table.at(i, int(j)) = Rgb(float(t.scale), float(t.bias), 0.0f);
    }
    progress.advance();
  });
  progress.finish();
  return table;
}

// ─── Split-sum error ───────────────────────────────────────────────────────────────────────

namespace {

struct Estimate {
  DVec3 value{0.0};
  double relativeStdError = 0.0;  ///< of the luminance
};

// ∫ f(v, ω) L(ω) cos θ dω over the hemisphere of n by MIS: one BSDF and one environment sample
// per iteration, power heuristic. The per-iteration sums are i.i.d., so their sample variance
// gives the standard error.
Estimate exactIntegral(const EnvironmentMap& env, const Bsdf& bsdf, const Frame& frame, const Vec3& vLocal,
                       int samples, Pcg32& rng) {
  DVec3 sum(0.0);
  double sumY = 0.0, sumY2 = 0.0;
  for (int i = 0; i < samples; ++i) {
    DVec3 x(0.0);
    if (const auto s = sample(bsdf, vLocal, {rng.uniform(), rng.uniform()}); s && !s->delta && s->pdf > 0.0f) {
      const Vec3 world = frame.toWorld(s->wi);
      const float pe = env.pdf(world);
      x += DVec3(s->weight * env.radiance(world)) * double(powerHeuristic(s->pdf, pe));
    }
    const EnvironmentSample es = env.sample({rng.uniform(), rng.uniform()});
    if (es.pdf > 0.0f) {
      const Vec3 wi = frame.toLocal(es.direction);
      if (wi.z > 0.0f) {
        const float pb = pdf(bsdf, vLocal, wi);
        const Rgb f = eval(bsdf, vLocal, wi);
        x += DVec3(f * es.radiance) * double(wi.z / es.pdf * powerHeuristic(es.pdf, pb));
      }
    }
    sum += x;
    const double y = luminance(Rgb(x));
    sumY += y;
    sumY2 += y * y;
  }
  Estimate e;
  e.value = sum / double(samples);
  const double mean = sumY / samples;
  const double variance = std::max(0.0, sumY2 / samples - mean * mean) / (samples - 1.0);
  e.relativeStdError = mean > 0.0 ? std::sqrt(variance) / mean : 0.0;
  return e;
}

}  // namespace

SplitSumReport splitSumError(const EnvironmentMap& env, const SplitSumOptions& o) {
  if (o.roughness.empty() || o.viewDegrees.empty()) fail("split-sum analysis needs roughness and view angles");
  if (o.normals < 1 || o.samples < 2) fail("split-sum analysis needs ≥ 1 normal and ≥ 2 samples");
  for (float v : o.viewDegrees)
    if (!(v >= 0.0f && v < 90.0f)) fail("view angle {}° out of range [0, 90)", v);
  for (float r : o.roughness)
    if (!(r > 0.0f && r <= 1.0f)) fail("roughness {} out of range (0, 1]", r);

  const int rows = int(o.roughness.size()), cols = int(o.viewDegrees.size());
  // Normals on a Fibonacci spiral (nearly uniform over the sphere).
  std::vector<Vec3> normals;
  const double golden = kPiD * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < o.normals; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / o.normals, r = std::sqrt(1.0 - y * y);
    normals.push_back(Vec3(float(r * std::cos(golden * i)), float(y), float(r * std::sin(golden * i))));
  }
  // DFG terms per cell and the albedo at normal incidence per roughness (f0 = 1), by
  // stratified quadrature with many samples (its error, < 1e-4, is far below the MC error).
  constexpr int kDfgSamples = 1 << 16;
  std::vector<DfgTerm> dfg(size_t(rows) * cols);
  std::vector<double> albedoNormal(static_cast<size_t>(rows));
  parallelFor(uint64_t(rows) * uint64_t(cols + 1), [&](uint64_t task) {
    const int r = int(task / uint64_t(cols + 1)), c = int(task % uint64_t(cols + 1));
    if (c == cols) {
      const DfgTerm t = dfgTerm(o.model, o.roughness[size_t(r)], 1.0f, kDfgSamples);
      albedoNormal[size_t(r)] = t.scale + t.bias;
    } else {
      const float cosV = float(std::cos(double(o.viewDegrees[size_t(c)]) * kPiD / 180.0));
      dfg[size_t(r) * cols + c] = dfgTerm(o.model, o.roughness[size_t(r)], cosV, kDfgSamples);
    }
  });

  struct PerNormal {
    double relative = 0.0, mcRelative = 0.0;
  };
  std::vector<PerNormal> results(size_t(rows) * cols * o.normals);
  Progress progress("split-sum error", results.size());
  parallelFor(results.size(), [&](uint64_t task) {
    const int cell = int(task / uint64_t(o.normals)), ni = int(task % uint64_t(o.normals));
    const int r = cell / cols, c = cell % cols;
    const float roughness = o.roughness[size_t(r)];
    const double thetaV = double(o.viewDegrees[size_t(c)]) * kPiD / 180.0;
    const Vec3 n = normals[size_t(ni)];
    const Frame frame = Frame::fromNormal(n);
    const Vec3 vLocal(float(std::sin(thetaV)), 0.0f, float(std::cos(thetaV)));
    const Vec3 v = frame.toWorld(vLocal);
    Pcg32 rng = Pcg32::forKey(task, 1, o.seed);

    const Estimate exact = exactIntegral(env, specularBsdf(o.model, roughness, o.f0), frame, vLocal, o.samples, rng);
    // P(R): the BRDF-weighted mean radiance around R, i.e. the integral with n = v = R and
    // f0 = 1, divided by the albedo at normal incidence.
    const Vec3 reflected = glm::normalize(reflect(v, n));
    const Frame frameR = Frame::fromNormal(reflected);
    const Estimate around = exactIntegral(env, specularBsdf(o.model, roughness, 1.0f), frameR, Vec3(0, 0, 1),
                                          o.samples, rng);
    const DfgTerm t = dfg[size_t(cell)];
    const DVec3 approx = around.value / albedoNormal[size_t(r)] * (double(o.f0) * t.scale + t.bias);
    const double yExact = luminance(Rgb(exact.value)), yApprox = luminance(Rgb(approx));
    PerNormal& out = results[task];
    out.relative = yExact > 0.0 ? (yApprox - yExact) / yExact : 0.0;
    out.mcRelative = std::hypot(exact.relativeStdError, around.relativeStdError);
    progress.advance();
  });
  progress.finish();

  SplitSumReport report;
  report.rows = rows;
  report.columns = cols;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      SplitSumCell cell;
      cell.roughness = o.roughness[size_t(r)];
      cell.viewDegrees = o.viewDegrees[size_t(c)];
      for (int ni = 0; ni < o.normals; ++ni) {
        const PerNormal& p = results[(size_t(r) * cols + c) * o.normals + ni];
        cell.meanAbsRelative += std::abs(p.relative) / o.normals;
        cell.meanSignedRelative += p.relative / o.normals;
        cell.maxAbsRelative = std::max(cell.maxAbsRelative, std::abs(p.relative));
        cell.monteCarloRelative = std::max(cell.monteCarloRelative, p.mcRelative);
      }
      report.maxMonteCarloRelative = std::max(report.maxMonteCarloRelative, cell.monteCarloRelative);
      report.cells.push_back(cell);
    }
  return report;
}

std::string splitSumToJson(const SplitSumReport& report, const SplitSumOptions& o, const std::string& source) {
  nlohmann::ordered_json j;
  j["source"] = source;
  j["model"] = specularModelName(o.model);
  j["f0"] = o.f0;
  j["normals"] = o.normals;
  j["samples_per_strategy"] = o.samples;
  j["error"] = "relative error of luminance, (split-sum - exact) / exact";
  j["max_monte_carlo_relative_std_error"] = report.maxMonteCarloRelative;
  auto& cells = j["cells"] = nlohmann::json::array();
  for (const SplitSumCell& c : report.cells)
    cells.push_back({{"roughness", c.roughness},
                     {"view_degrees", c.viewDegrees},
                     {"mean_abs_relative", c.meanAbsRelative},
                     {"max_abs_relative", c.maxAbsRelative},
                     {"mean_signed_relative", c.meanSignedRelative},
                     {"monte_carlo_relative", c.monteCarloRelative}});
  return j.dump(2);
}

std::string splitSumTable(const SplitSumReport& report) {
  std::string s = "mean |relative error| over normals, in % (worst normal in parentheses)\n";
  s += fmt::format("{:>9} |", "r \\ θv");
  for (int c = 0; c < report.columns; ++c) s += fmt::format(" {:>15}", fmt::format("{:g}°", report.cells[size_t(c)].viewDegrees));
  s += "\n";
  s += std::string(11 + 16 * size_t(report.columns), '-') + "\n";
  for (int r = 0; r < report.rows; ++r) {
    s += fmt::format("{:>9.2f} |", report.cells[size_t(r) * report.columns].roughness);
    for (int c = 0; c < report.columns; ++c) {
      const SplitSumCell& cell = report.cells[size_t(r) * report.columns + c];
      s += fmt::format(" {:>15}", fmt::format("{:.2f} ({:.1f})", 100.0 * cell.meanAbsRelative, 100.0 * cell.maxAbsRelative));
    }
    s += "\n";
  }
  s += fmt::format("largest Monte Carlo relative standard error of any single estimate: {:.3f} %\n",
                   100.0 * report.maxMonteCarloRelative);
  return s;
}

Image8 splitSumHeatMap(const SplitSumReport& report, double maxValue) {
  constexpr int kCell = 32, kGap = 8, kBar = 16;
  const int w = report.columns * kCell + kGap + kBar, h = report.rows * kCell;
  Image8 img;
  img.width = w;
  img.height = h;
  img.rgb.assign(size_t(w) * h * 3, 255);
  // Colour scale black → blue → red → yellow → white, linear in the value.
  auto colour = [](double t) {
    static const std::array<Vec3, 5> stops = {Vec3(0, 0, 0), Vec3(0.1f, 0.1f, 0.8f), Vec3(0.9f, 0.1f, 0.1f),
                                              Vec3(1.0f, 0.9f, 0.1f), Vec3(1, 1, 1)};
    t = std::clamp(t, 0.0, 1.0) * (stops.size() - 1);
    const size_t i = std::min(size_t(t), stops.size() - 2);
    const Vec3 c = glm::mix(stops[i], stops[i + 1], float(t - double(i)));
    return std::array<uint8_t, 3>{uint8_t(c.r * 255.0f + 0.5f), uint8_t(c.g * 255.0f + 0.5f), uint8_t(c.b * 255.0f + 0.5f)};
  };
  auto put = [&](int x, int y, const std::array<uint8_t, 3>& c) {
    for (int k = 0; k < 3; ++k) img.rgb[(size_t(y) * w + x) * 3 + k] = c[size_t(k)];
  };
  const double scale = maxValue > 0.0 ? 1.0 / maxValue : 0.0;
  for (int r = 0; r < report.rows; ++r)
    for (int c = 0; c < report.columns; ++c) {
      const auto col = colour(report.cells[size_t(r) * report.columns + c].meanAbsRelative * scale);
      for (int y = 1; y < kCell; ++y)  // 1-pixel white grid lines between cells
        for (int x = 1; x < kCell; ++x) put(c * kCell + x, r * kCell + y, col);
    }
  for (int y = 0; y < h; ++y)  // colour bar: maxValue at the top, 0 at the bottom
    for (int x = 0; x < kBar; ++x) put(report.columns * kCell + kGap + x, y, colour(1.0 - (y + 0.5) / h));
  return img;
}

}  // namespace pl
