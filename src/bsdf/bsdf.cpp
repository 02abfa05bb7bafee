// Reflection models. The contract (local frame, eval without cosine, what sample returns)
// is in bsdf.h; this file holds the formulas, their derivations and the sampling routines.
#include "bsdf/bsdf.h"

#include <array>
#include <cmath>

#include "core/sampling.h"

namespace pl {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

inline float cosTheta(const Vec3& w) { return w.z; }
inline bool sameHemisphereUp(const Vec3& wo, const Vec3& wi) { return wo.z > 0.0f && wi.z > 0.0f; }
inline Vec3 mirrorLocal(const Vec3& wo) { return {-wo.x, -wo.y, wo.z}; }
inline Vec3 reflectAbout(const Vec3& wo, const Vec3& h) { return 2.0f * glm::dot(wo, h) * h - wo; }

/// Picks between two lobes with probability pFirst and stretches u back onto [0, 1).
inline bool chooseFirst(float pFirst, float& u) {
  if (u < pFirst) {
    u = std::min(u / pFirst, 0x1.fffffep-1f);
    return true;
  }
  u = std::min((u - pFirst) / (1.0f - pFirst), 0x1.fffffep-1f);
  return false;
}

// ---------------------------------------------------------------------------------------
// Lambert: f = ρ/π, sampled by the cosine-weighted hemisphere (weight = ρ exactly).

Rgb evalLambert(const LambertBsdf& b, const Vec3& wo, const Vec3& wi) {
  return sameHemisphereUp(wo, wi) ? b.albedo * kInvPi : Rgb(0.0f);
}

// ---------------------------------------------------------------------------------------
// Mirror: f = R(θo) δ(wi − mirror(wo)) / cos θi. Only sample() produces it.

Rgb mirrorReflectance(const MirrorBsdf& b, float cosO) {
  return b.fresnel ? fresnelSchlick(b.reflectance, cosO) : b.reflectance;
}

// ---------------------------------------------------------------------------------------
// Normalised Blinn-Phong.
//
// Lobe sampling draws the half vector h with density p(h) = (n+1)/(2π) cos^n θh (so
// cos θh = u^(1/(n+1))), reflects wo about it, and converts to solid angle of wi with the
// reflection Jacobian dωh/dωi = 1/(4 wo·h). A sample whose wi falls below the horizon is
// rejected (sample() returns nothing); pdf() is then still exactly its density.

float blinnLobePdf(float exponent, const Vec3& wo, const Vec3& wi) {
  const Vec3 h = glm::normalize(wo + wi);
  const float woh = glm::dot(wo, h);
  if (woh <= 0.0f || h.z <= 0.0f) return 0.0f;
  return (exponent + 1.0f) / (2.0f * kPi) * std::pow(h.z, exponent) / (4.0f * woh);
}

/// Mixture probability of the specular lobe: the lobe albedos' luminances (specular at
/// normal incidence is `specular` exactly, see blinnPhongNormalization).
float blinnSpecularProbability(const BlinnPhongBsdf& b) {
  const float d = std::max(0.0f, luminance(b.diffuse)), s = std::max(0.0f, luminance(b.specular));
  return d + s > 0.0f ? s / (d + s) : 0.0f;
}

Rgb evalBlinnPhong(const BlinnPhongBsdf& b, const Vec3& wo, const Vec3& wi) {
  if (!sameHemisphereUp(wo, wi)) return Rgb(0.0f);
  const Vec3 h = glm::normalize(wo + wi);
  const float n = std::max(0.0f, b.exponent);
  return b.diffuse * kInvPi + b.specular * (blinnPhongNormalization(n) * std::pow(std::max(0.0f, h.z), n));
}

float pdfBlinnPhong(const BlinnPhongBsdf& b, const Vec3& wo, const Vec3& wi) {
  if (!sameHemisphereUp(wo, wi)) return 0.0f;
  const float ps = blinnSpecularProbability(b);
  return (1.0f - ps) * cosineHemispherePdf(wi.z) + ps * blinnLobePdf(std::max(0.0f, b.exponent), wo, wi);
}

std::optional<Vec3> sampleBlinnPhongDirection(const BlinnPhongBsdf& b, const Vec3& wo, Vec2 u) {
  const float ps = blinnSpecularProbability(b);
  if (ps <= 0.0f && luminance(b.diffuse) <= 0.0f) return std::nullopt;
  if (!chooseFirst(ps, u.x)) return sampleCosineHemisphere(u);
  const float n = std::max(0.0f, b.exponent);
  const float cosH = std::pow(u.x, 1.0f / (n + 1.0f));
  const float sinH = std::sqrt(std::max(0.0f, 1.0f - cosH * cosH));
  const float phi = kTwoPi * u.y;
  const Vec3 h(sinH * std::cos(phi), sinH * std::sin(phi), cosH);
  return reflectAbout(wo, h);
}

// ---------------------------------------------------------------------------------------
// GGX microfacet model.
//
// Specular term (Walter et al. 2007, Heitz 2014):
//   f_s = F(wo·h) D(h) G2(wo, wi) / (4 cos θo cos θi)
//   D(h)  = α² / (π (cos²θh (α² − 1) + 1)²)
//   Λ(w)  = (√(1 + α² tan²θ) − 1) / 2,   G1(w) = 1 / (1 + Λ(w))
//   G2    = 1 / (1 + Λ(wo) + Λ(wi))      (height-correlated Smith)
// f_s is symmetric: h, wo·h = wi·h, D and G2 are. Single-scattering energy: with F ≤ 1 and
// G2 ≤ G1(wo), E(θo) = ∫ f_s cos θi dωi ≤ ∫ D_wo(h) dωh = 1 (D_wo is the visible-normal
// distribution, normalised), so the lobe alone never creates energy.
//
// Diffuse base (Kelemen & Szirmay-Kalos 2001, "A microfacet based coupled specular-matte
// BRDF model with importance sampling"):
//   f_d = ρ/π · (1 − E(θo)) (1 − E(θi)) / (1 − Ē),   Ē = 2 ∫₀¹ E(μ) μ dμ
// It is a product of a function of θo and the same function of θi, hence reciprocal, and
//   ∫ f_d cos θi dωi = ρ (1 − E(θo)) · [2 ∫ (1 − E(μ)) μ dμ] / (1 − Ē) = ρ (1 − E(θo)),
// so ∫ f cos θi = E(θo) + ρ (1 − E(θo)) ≤ 1 whenever ρ ≤ 1. (Weighting the diffuse by
// 1 − F(wo·h) instead, as many real-time engines do, is not reciprocal.)
//
// E depends on (cos θo, α, F0). With Schlick's F = F0 + (1 − F0)(1 − c)^5 it is linear in F0:
//   E = F0 (E₀ − E₅) + E₅,  E₀ = ∫ D G2/(4 cos θo) dωi,  E₅ = the same weighted by (1 − c)^5,
// so two scalar tables over (μ = cos θo, r = √α) suffice. They are filled once per process by
// quadrature over the visible-normal sampler and interpolated piecewise-linearly in μ (and
// linearly in r). Ē is computed from the *interpolated* table exactly (the cosine-weighted
// integral of a piecewise-linear function is closed-form), so the identity above holds for
// the table E exactly and the energy bound is off only by the table's error against the true
// E (< 1e-3: bsdf_test's white-furnace check measures ∫ f cos = 1 ± 6.4e-4 for ρ = 1).

inline float ggxD(float alpha, const Vec3& h) {
  const float a2 = alpha * alpha;
  const float c2 = h.z * h.z;
  const float d = c2 * (a2 - 1.0f) + 1.0f;
  return a2 / (kPi * d * d);
}

inline float ggxLambda(float alpha, const Vec3& w) {
  const float c2 = w.z * w.z;
  if (c2 <= 0.0f) return kInfinity;
  const float tan2 = std::max(0.0f, 1.0f - c2) / c2;
  return 0.5f * (std::sqrt(1.0f + alpha * alpha * tan2) - 1.0f);
}

inline float clampAlpha(float alpha) { return std::clamp(alpha, kGgxMinAlpha, 1.0f); }

/// Heitz 2018, "Sampling the GGX Distribution of Visible Normals": a microfacet normal with
/// density D_wo(h) = G1(wo) max(0, wo·h) D(h) / cos θo. wo must be in the upper hemisphere.
Vec3 sampleGgxVisibleNormal(float alpha, const Vec3& wo, Vec2 u) {
  const Vec3 vh = glm::normalize(Vec3(alpha * wo.x, alpha * wo.y, wo.z));
  const float lensq = vh.x * vh.x + vh.y * vh.y;
  const Vec3 t1 = lensq > 0.0f ? Vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : Vec3(1.0f, 0.0f, 0.0f);
  const Vec3 t2 = glm::cross(vh, t1);
  const float r = std::sqrt(u.x);
  const float phi = kTwoPi * u.y;
  const float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  const float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
  const Vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return glm::normalize(Vec3(alpha * nh.x, alpha * nh.y, std::max(1e-6f, nh.z)));
}

/// The directional-albedo tables of the GGX lobe (see the derivation above).
class GgxAlbedoTable {
 public:
  static constexpr int kMuNodes = 40;     ///< nodes in μ = cos θo, μ_i = (i/(N−1))²: dense at grazing
  static constexpr int kRoughNodes = 24;  ///< nodes in r = √α, uniform on [√kGgxMinAlpha, 1]
  static constexpr int kQuadrature = 64;  ///< midpoint rule per axis over the sampler's square

  static const GgxAlbedoTable& get() {
    static const GgxAlbedoTable table;  // thread-safe one-time initialisation
    return table;
  }

  /// E₀, E₅ at (μ, α), and the matching cosine-weighted means Ē₀, Ē₅ at α.
  struct Lookup {
    float e0, e5, mean0, mean5;
  };
  Lookup lookup(float mu, float alpha) const {
    const float rMin = std::sqrt(kGgxMinAlpha);
    const float rPos = (std::sqrt(clampAlpha(alpha)) - rMin) / (1.0f - rMin) * (kRoughNodes - 1);
    const int r0 = std::clamp(static_cast<int>(rPos), 0, kRoughNodes - 2);
    const float tr = std::clamp(rPos - static_cast<float>(r0), 0.0f, 1.0f);
    mu = std::clamp(mu, 0.0f, 1.0f);
    // Node i sits at μ = (i/(N−1))²; find the segment from √μ, interpolate linearly in μ.
    const float iPos = std::sqrt(mu) * (kMuNodes - 1);
    const int i0 = std::clamp(static_cast<int>(iPos), 0, kMuNodes - 2);
    const float tm = std::clamp((mu - mu_[i0]) / (mu_[i0 + 1] - mu_[i0]), 0.0f, 1.0f);
    auto at = [&](const std::array<std::array<float, kMuNodes>, kRoughNodes>& t, int r) {
      return t[r][i0] + tm * (t[r][i0 + 1] - t[r][i0]);
    };
    Lookup l;
    l.e0 = at(e0_, r0) + tr * (at(e0_, r0 + 1) - at(e0_, r0));
    l.e5 = at(e5_, r0) + tr * (at(e5_, r0 + 1) - at(e5_, r0));
    l.mean0 = mean0_[r0] + tr * (mean0_[r0 + 1] - mean0_[r0]);
    l.mean5 = mean5_[r0] + tr * (mean5_[r0 + 1] - mean5_[r0]);
    return l;
  }

 private:
  GgxAlbedoTable() {
    const float rMin = std::sqrt(kGgxMinAlpha);
    for (int i = 0; i < kMuNodes; ++i) {
      const float x = static_cast<float>(i) / (kMuNodes - 1);
      mu_[i] = x * x;
    }
    for (int r = 0; r < kRoughNodes; ++r) {
      const float rough = rMin + (1.0f - rMin) * static_cast<float>(r) / (kRoughNodes - 1);
      const float alpha = rough * rough;
      for (int i = 0; i < kMuNodes; ++i) {
        // At grazing (μ = 0) the lobe is evaluated just above the horizon.
        const float mu = std::max(mu_[i], 1e-4f);
        const Vec3 wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
        const float g1o = 1.0f / (1.0f + ggxLambda(alpha, wo));
        double s0 = 0.0, s5 = 0.0;
        for (int a = 0; a < kQuadrature; ++a)
          for (int b = 0; b < kQuadrature; ++b) {
            const Vec2 u((a + 0.5f) / kQuadrature, (b + 0.5f) / kQuadrature);
            const Vec3 h = sampleGgxVisibleNormal(alpha, wo, u);
            const Vec3 wi = reflectAbout(wo, h);
            if (wi.z <= 0.0f) continue;
            // Importance-sampled estimator of E: f_s cos θi / p(wi) = F G2 / G1(wo).
            const float w = (1.0f / (1.0f + ggxLambda(alpha, wo) + ggxLambda(alpha, wi))) / g1o;
            const float m = std::clamp(1.0f - glm::dot(wo, h), 0.0f, 1.0f);
            s0 += w;
            s5 += w * (m * m * m * m * m);
          }
        const double inv = 1.0 / (kQuadrature * kQuadrature);
        e0_[r][i] = static_cast<float>(std::min(1.0, s0 * inv));
        e5_[r][i] = static_cast<float>(std::min(s0, s5) * inv);
      }
      // Exact 2∫E μ dμ of the piecewise-linear table: on [a, b] with end values Ea, Eb,
      // ∫ E μ dμ = (b − a)(Ea (2a + b) + Eb (a + 2b)) / 6.
      double m0 = 0.0, m5 = 0.0;
      for (int i = 0; i + 1 < kMuNodes; ++i) {
        const double a = mu_[i], b = mu_[i + 1];
        m0 += (b - a) * (e0_[r][i] * (2 * a + b) + e0_[r][i + 1] * (a + 2 * b)) / 6.0;
        m5 += (b - a) * (e5_[r][i] * (2 * a + b) + e5_[r][i + 1] * (a + 2 * b)) / 6.0;
      }
      mean0_[r] = static_cast<float>(2.0 * m0);
      mean5_[r] = static_cast<float>(2.0 * m5);
    }
  }

  std::array<float, kMuNodes> mu_{};
  std::array<std::array<float, kMuNodes>, kRoughNodes> e0_{}, e5_{};
  std::array<float, kRoughNodes> mean0_{}, mean5_{};
};

/// The specular lobe's directional albedo E(θ) per channel and its cosine-weighted mean Ē.
struct GgxLobeAlbedo {
  Rgb at;
  Rgb mean;
};
GgxLobeAlbedo ggxLobeAlbedo(const GgxBsdf& b, float mu) {
  const auto l = GgxAlbedoTable::get().lookup(mu, b.alpha);
  return {b.f0 * (l.e0 - l.e5) + Rgb(l.e5), b.f0 * (l.mean0 - l.mean5) + Rgb(l.mean5)};
}

/// (1 − E(μ)) / √(1 − Ē) per channel, so that f_d = ρ/π · k(μo) k(μi). Zero when Ē ≈ 1 (a
/// lobe that reflects everything leaves no energy for the base).
Rgb ggxDiffuseFactor(const GgxBsdf& b, float mu) {
  const GgxLobeAlbedo e = ggxLobeAlbedo(b, mu);
  Rgb k;
  for (int c = 0; c < 3; ++c) {
    const float rest = 1.0f - e.mean[c];
    k[c] = rest > 1e-6f ? std::max(0.0f, 1.0f - e.at[c]) / std::sqrt(rest) : 0.0f;
  }
  return k;
}

Rgb ggxSpecular(const GgxBsdf& b, const Vec3& wo, const Vec3& wi) {
  const float alpha = clampAlpha(b.alpha);
  const Vec3 h = glm::normalize(wo + wi);
  const float g2 = 1.0f / (1.0f + ggxLambda(alpha, wo) + ggxLambda(alpha, wi));
  return fresnelSchlick(b.f0, glm::dot(wo, h)) * (ggxD(alpha, h) * g2 / (4.0f * wo.z * wi.z));
}

/// Mixture probability of the specular lobe from the lobe albedos at wo.
float ggxSpecularProbability(const GgxBsdf& b, const Vec3& wo) {
  const GgxLobeAlbedo e = ggxLobeAlbedo(b, wo.z);
  const float s = std::max(0.0f, luminance(e.at));
  const float d = std::max(0.0f, luminance(b.diffuse * (Rgb(1.0f) - e.at)));
  return d + s > 0.0f ? s / (d + s) : 1.0f;
}

float ggxLobePdf(const GgxBsdf& b, const Vec3& wo, const Vec3& wi) {
  // p(wi) = D_wo(h) / (4 wo·h) = G1(wo) D(h) / (4 cos θo).
  const float alpha = clampAlpha(b.alpha);
  const Vec3 h = glm::normalize(wo + wi);
  if (glm::dot(wo, h) <= 0.0f) return 0.0f;
  return ggxD(alpha, h) / ((1.0f + ggxLambda(alpha, wo)) * 4.0f * wo.z);
}

Rgb evalGgx(const GgxBsdf& b, const Vec3& wo, const Vec3& wi) {
  if (!sameHemisphereUp(wo, wi)) return Rgb(0.0f);
  Rgb f = ggxSpecular(b, wo, wi);
  if (!isBlack(b.diffuse)) f += b.diffuse * kInvPi * ggxDiffuseFactor(b, wo.z) * ggxDiffuseFactor(b, wi.z);
  return f;
}

float pdfGgx(const GgxBsdf& b, const Vec3& wo, const Vec3& wi) {
  if (!sameHemisphereUp(wo, wi)) return 0.0f;
  const float ps = ggxSpecularProbability(b, wo);
  return (1.0f - ps) * cosineHemispherePdf(wi.z) + ps * ggxLobePdf(b, wo, wi);
}

std::optional<Vec3> sampleGgxDirection(const GgxBsdf& b, const Vec3& wo, Vec2 u) {
  const float ps = ggxSpecularProbability(b, wo);
  if (!chooseFirst(ps, u.x)) return sampleCosineHemisphere(u);
  return reflectAbout(wo, sampleGgxVisibleNormal(clampAlpha(b.alpha), wo, u));
}

// ---------------------------------------------------------------------------------------
// Dielectrics. Local +z is the outside; η = n_inside / n_outside. For a pair (wo, wi) on
// opposite sides, η' = η(wi side) / η(wo side) = η when wo is outside, 1/η when inside.
//
// Smooth: f = F δ(wi − mirror(wo))/|cos θi| + t (1 − F)/η'² δ(wi − refract(wo))/|cos θi|.
// The 1/η'² is the radiance scaling across the interface (radiance per solid angle is
// compressed by η'² on entering a denser medium); it makes f obey f(wo, wi)/η(wo)² =
// f(wi, wo)/η(wi)² once the Jacobian of refraction, η(wo)² cos θo dωo = η(wi)² cos θi dωi,
// is accounted for in the deltas.
//
// Rough (Walter et al. 2007, in pbrt-v4's form): with the generalised half vector
// wm = normalize(η' wi + wo) turned to +z,
//   reflection:    f = F(wo·wm) D(wm) G2(wo, wi) / |4 cos θo cos θi|
//   transmission:  f = t (1 − F(wo·wm)) D(wm) G2(wo, wi) |wi·wm| |wo·wm|
//                      / (|cos θi cos θo| (wi·wm + wo·wm/η')² η'²)
// zero when wm is back-facing to wo or wi (wo·wm and cos θo of different signs, or wi's).
// Sampling: the lobe first, reflection with the fixed probability P_R(wo) (the macro-surface
// Fresnel F(cos θo) clamped to [0.05, 0.95], so that both lobes keep support where the
// micro-surface sees them even under total internal reflection), then a visible normal wm
// with density D_wo(wm) = G1(wo) |wo·wm| D(wm)/|cos θo| (Heitz 2018, for wo turned to +z),
// then wi = reflect(wo, wm) or refract(wo, wm). Solid-angle densities:
//   reflection:    P_R D_wo(wm) / (4 |wo·wm|)
//   transmission:  (1 − P_R) D_wo(wm) |wi·wm| / (wi·wm + wo·wm/η')²
// (the Jacobians of the reflected and refracted directions with respect to wm). A sample
// that leaves its hemisphere or meets total internal reflection at the microfacet is
// rejected, so pdf() is exactly the density of what sample() returns.

inline float sqr(float x) { return x * x; }

/// Refraction of w (pointing away from the surface) through the interface with normal n,
/// where `eta` is the index ratio of the far side to w's side and w·n > 0. False under total
/// internal reflection.
bool refractDirection(const Vec3& w, const Vec3& n, float eta, Vec3& refracted) {
  const float cosI = glm::dot(n, w);
  const float sin2T = std::max(0.0f, 1.0f - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0f) return false;
  const float cosT = std::sqrt(1.0f - sin2T);
  refracted = -w / eta + (cosI / eta - cosT) * n;
  return true;
}

/// η' for a transmission with wo on the side given by cosO.
inline float relativeEta(const DielectricBsdf& b, float cosO) { return cosO > 0.0f ? b.ior : 1.0f / b.ior; }

float roughReflectProbability(const DielectricBsdf& b, const Vec3& wo) {
  return std::clamp(fresnelDielectric(wo.z, b.ior), 0.05f, 0.95f);
}

/// The generalised half vector of (wo, wi) turned to +z, with η' (1 for reflection). False
/// when it is undefined or back-facing to wo or wi.
bool dielectricHalfVector(const DielectricBsdf& b, const Vec3& wo, const Vec3& wi, Vec3& wm, float& etap) {
  const float cosO = wo.z, cosI = wi.z;
  if (cosO == 0.0f || cosI == 0.0f) return false;
  etap = cosO * cosI > 0.0f ? 1.0f : relativeEta(b, cosO);
  wm = wi * etap + wo;
  const float len2 = glm::dot(wm, wm);
  if (!(len2 > 0.0f)) return false;
  wm /= std::sqrt(len2);
  if (wm.z < 0.0f) wm = -wm;
  return glm::dot(wm, wi) * cosI > 0.0f && glm::dot(wm, wo) * cosO > 0.0f;
}

Rgb evalRoughDielectric(const DielectricBsdf& b, const Vec3& wo, const Vec3& wi) {
  Vec3 wm;
  float etap;
  if (!dielectricHalfVector(b, wo, wi, wm, etap)) return Rgb(0.0f);
  const float alpha = clampAlpha(b.alpha);
  const float dg = ggxD(alpha, wm) / (1.0f + ggxLambda(alpha, wo) + ggxLambda(alpha, wi));
  if (wo.z * wi.z > 0.0f) return Rgb(fresnelDielectric(glm::dot(wo, wm), b.ior) * dg / std::abs(4.0f * wo.z * wi.z));
  const float denom = sqr(glm::dot(wi, wm) + glm::dot(wo, wm) / etap) * wi.z * wo.z;
  const float ft = fresnelDielectricTransmittance(glm::dot(wo, wm), b.ior) * dg * std::abs(glm::dot(wi, wm) * glm::dot(wo, wm) / denom) / (etap * etap);
  return b.transmittance * ft;
}

float pdfRoughDielectric(const DielectricBsdf& b, const Vec3& wo, const Vec3& wi) {
  Vec3 wm;
  float etap;
  if (!dielectricHalfVector(b, wo, wi, wm, etap)) return 0.0f;
  const float alpha = clampAlpha(b.alpha);
  const float woDotM = std::abs(glm::dot(wo, wm));
  const float visibleNormal = ggxD(alpha, wm) * woDotM / ((1.0f + ggxLambda(alpha, wo)) * std::abs(wo.z));
  const float pR = roughReflectProbability(b, wo);
  if (wo.z * wi.z > 0.0f) return pR * visibleNormal / (4.0f * woDotM);
  return (1.0f - pR) * visibleNormal * std::abs(glm::dot(wi, wm)) / sqr(glm::dot(wi, wm) + glm::dot(wo, wm) / etap);
}

std::optional<BsdfSample> sampleRoughDielectric(const DielectricBsdf& b, const Vec3& wo, Vec2 u) {
  const bool reflectLobe = chooseFirst(roughReflectProbability(b, wo), u.x);
  const Vec3 woUp = wo.z < 0.0f ? -wo : wo;
  const Vec3 wm = sampleGgxVisibleNormal(clampAlpha(b.alpha), woUp, u);
  Vec3 wi;
  if (reflectLobe) {
    wi = reflectAbout(wo, wm);
    if (!(wi.z * wo.z > 0.0f)) return std::nullopt;
  } else {
    // wo·wm has the sign of cos θo (wm is a visible normal of woUp).
    const bool outside = glm::dot(wo, wm) > 0.0f;
    if (!refractDirection(wo, outside ? wm : -wm, outside ? b.ior : 1.0f / b.ior, wi)) return std::nullopt;
    if (!(wi.z * wo.z < 0.0f)) return std::nullopt;
  }
  if (!isFinite(wi)) return std::nullopt;
  BsdfSample s;
  s.wi = glm::normalize(wi);
  s.pdf = pdfRoughDielectric(b, wo, s.wi);
  if (!(s.pdf > 0.0f)) return std::nullopt;
  s.f = evalRoughDielectric(b, wo, s.wi);
  s.weight = s.f * (std::abs(s.wi.z) / s.pdf);
  return s;
}

std::optional<BsdfSample> sampleSmoothDielectric(const DielectricBsdf& b, const Vec3& wo, Vec2 u) {
  BsdfSample s;
  s.delta = true;
  if (b.thin) {
    Rgb r, t;
    thinSheetReflectanceTransmittance(b, wo.z, r, t);
    const float lr = std::max(0.0f, luminance(r)), lt = std::max(0.0f, luminance(t));
    if (!(lr + lt > 0.0f)) return std::nullopt;
    const float pR = lr / (lr + lt);
    if (u.x < pR) {
      s.wi = mirrorLocal(wo);
      s.weight = r / pR;
    } else {
      s.wi = -wo;
      s.weight = t / (1.0f - pR);
    }
    return s;
  }
  const float F = fresnelDielectric(wo.z, b.ior);
  if (u.x < F) {
    s.wi = mirrorLocal(wo);
    s.weight = Rgb(1.0f);  // F / F
    return s;
  }
  const float etap = relativeEta(b, wo.z);
  const Vec3 n(0.0f, 0.0f, wo.z > 0.0f ? 1.0f : -1.0f);
  if (!refractDirection(wo, n, etap, s.wi)) return std::nullopt;  // F = 1 there: not reached
  s.weight = b.transmittance / (etap * etap);  // t (1 − F) / η'² / (1 − F)
  return s;
}

Rgb dielectricAlbedo(const DielectricBsdf& b, const Vec3& wo) {
  if (b.thin) {
    Rgb r, t;
    thinSheetReflectanceTransmittance(b, wo.z, r, t);
    return r + t;
  }
  const float F = fresnelDielectric(wo.z, b.ior), etap = relativeEta(b, wo.z);
  return Rgb(F) + b.transmittance * ((1.0f - F) / (etap * etap));
}

/// Shared tail of the non-delta samplers: reject, evaluate f and pdf, form the weight.
std::optional<BsdfSample> finishSample(const Bsdf& bsdf, const Vec3& wo, const std::optional<Vec3>& wi) {
  if (!wi || wi->z <= 0.0f || !isFinite(*wi)) return std::nullopt;
  BsdfSample s;
  s.wi = glm::normalize(*wi);
  s.pdf = pdf(bsdf, wo, s.wi);
  if (!(s.pdf > 0.0f)) return std::nullopt;
  s.f = eval(bsdf, wo, s.wi);
  s.weight = s.f * (s.wi.z / s.pdf);
  return s;
}

}  // namespace

float fresnelDielectric(float cosTheta, float eta) { return 1.0f - fresnelDielectricTransmittance(cosTheta, eta); }

float fresnelDielectricTransmittance(float cosTheta, float eta) {
  cosTheta = std::clamp(cosTheta, -1.0f, 1.0f);
  if (cosTheta < 0.0f) {  // arriving from the inside: the ratio is seen the other way round
    eta = 1.0f / eta;
    cosTheta = -cosTheta;
  }
  const float sin2T = (1.0f - cosTheta * cosTheta) / (eta * eta);
  if (sin2T >= 1.0f) return 0.0f;  // total internal reflection
  const float cosT = std::sqrt(std::max(0.0f, 1.0f - sin2T));
  // With r = (a − b)/(a + b): 1 − r² = 4ab/(a + b)², free of the cancellation 1 − r² suffers
  // near grazing (where F → 1), so that both sides of an interface agree to float precision.
  auto transmitted = [](float a, float b) { return 4.0f * a * b / ((a + b) * (a + b)); };
  return 0.5f * (transmitted(eta * cosTheta, cosT) + transmitted(cosTheta, eta * cosT));
}

void thinSheetReflectanceTransmittance(const DielectricBsdf& b, float cosTheta, Rgb& reflectance, Rgb& transmittance) {
  // Both faces have the same |cos θ| and reflectance R (the sheet does not bend light).
  // Summing the paths that bounce 2k times inside, each pass attenuated by t:
  //   R' = R + T² t² R Σ (R² t²)^k = R + T² t² R / (1 − R² t²)
  //   T' = T² t Σ (R² t²)^k       = T² t / (1 − R² t²)
  const float R = fresnelDielectric(std::abs(cosTheta), b.ior), T = fresnelDielectricTransmittance(std::abs(cosTheta), b.ior);
  if (!(T > 0.0f)) {
    reflectance = Rgb(1.0f);
    transmittance = Rgb(0.0f);
    return;
  }
  const Rgb t = b.transmittance;
  const Rgb denom = Rgb(1.0f) - R * R * t * t;
  reflectance = Rgb(R) + T * T * R * t * t / denom;
  transmittance = T * T * t / denom;
}

float blinnPhongNormalization(float exponent) {
  const float n = std::max(0.0f, exponent);
  return (n + 2.0f) * (n + 4.0f) / (8.0f * kPi * (std::exp2(-0.5f * n) + n));
}

GgxBsdf ggxFromMetallicRoughness(const Rgb& baseColor, float metallic, float roughness) {
  metallic = std::clamp(metallic, 0.0f, 1.0f);
  roughness = std::clamp(roughness, 0.0f, 1.0f);
  GgxBsdf b;
  b.f0 = glm::mix(Rgb(0.04f), baseColor, metallic);
  b.diffuse = baseColor * (1.0f - metallic);
  b.alpha = clampAlpha(roughness * roughness);
  return b;
}

Rgb eval(const Bsdf& bsdf, const Vec3& wo, const Vec3& wi) {
  return std::visit(Overloaded{
                        [&](const LambertBsdf& b) { return evalLambert(b, wo, wi); },
                        [&](const MirrorBsdf&) { return Rgb(0.0f); },
                        [&](const BlinnPhongBsdf& b) { return evalBlinnPhong(b, wo, wi); },
                        [&](const GgxBsdf& b) { return evalGgx(b, wo, wi); },
                        [&](const DielectricBsdf& b) {
                          return b.isSmooth() ? Rgb(0.0f) : evalRoughDielectric(b, wo, wi);
                        },
                    },
                    bsdf);
}

float pdf(const Bsdf& bsdf, const Vec3& wo, const Vec3& wi) {
  return std::visit(Overloaded{
                        [&](const LambertBsdf&) {
                          return sameHemisphereUp(wo, wi) ? cosineHemispherePdf(wi.z) : 0.0f;
                        },
                        [&](const MirrorBsdf&) { return 0.0f; },
                        [&](const BlinnPhongBsdf& b) { return pdfBlinnPhong(b, wo, wi); },
                        [&](const GgxBsdf& b) { return pdfGgx(b, wo, wi); },
                        [&](const DielectricBsdf& b) {
                          return b.isSmooth() ? 0.0f : pdfRoughDielectric(b, wo, wi);
                        },
                    },
                    bsdf);
}

std::optional<BsdfSample> sample(const Bsdf& bsdf, const Vec3& wo, Vec2 u) {
  if (const auto* d = std::get_if<DielectricBsdf>(&bsdf)) {
    if (!(wo.z != 0.0f) || !isFinite(wo)) return std::nullopt;
    return d->isSmooth() ? sampleSmoothDielectric(*d, wo, u) : sampleRoughDielectric(*d, wo, u);
  }
  if (!(cosTheta(wo) > 0.0f)) return std::nullopt;
  return std::visit(Overloaded{
                        [&](const LambertBsdf& b) -> std::optional<BsdfSample> {
                          BsdfSample s;
                          s.wi = sampleCosineHemisphere(u);
                          if (s.wi.z <= 0.0f) return std::nullopt;
                          s.pdf = cosineHemispherePdf(s.wi.z);
                          s.f = b.albedo * kInvPi;
                          s.weight = b.albedo;  // f cos / pdf = (ρ/π) cos / (cos/π)
                          return s;
                        },
                        [&](const MirrorBsdf& b) -> std::optional<BsdfSample> {
                          BsdfSample s;
                          s.wi = mirrorLocal(wo);
                          s.weight = mirrorReflectance(b, wo.z);
                          s.delta = true;
                          return s;
                        },
                        [&](const BlinnPhongBsdf& b) {
                          return finishSample(bsdf, wo, sampleBlinnPhongDirection(b, wo, u));
                        },
                        [&](const GgxBsdf& b) { return finishSample(bsdf, wo, sampleGgxDirection(b, wo, u)); },
                        [&](const DielectricBsdf&) -> std::optional<BsdfSample> { return std::nullopt; },  // above
                    },
                    bsdf);
}

bool isDelta(const Bsdf& bsdf) {
  if (const auto* d = std::get_if<DielectricBsdf>(&bsdf)) return d->isSmooth();
  return std::holds_alternative<MirrorBsdf>(bsdf);
}

bool hasTransmission(const Bsdf& bsdf) { return std::holds_alternative<DielectricBsdf>(bsdf); }

bool isDiffuse(const Bsdf& bsdf) { return std::holds_alternative<LambertBsdf>(bsdf); }

Rgb albedo(const Bsdf& bsdf, const Vec3& wo) {
  const auto* dielectric = std::get_if<DielectricBsdf>(&bsdf);
  if (!(wo.z > 0.0f) && !(dielectric && wo.z < 0.0f)) return Rgb(0.0f);
  if (dielectric && dielectric->isSmooth()) return dielectricAlbedo(*dielectric, wo);
  if (const auto* l = std::get_if<LambertBsdf>(&bsdf)) return l->albedo;
  if (const auto* m = std::get_if<MirrorBsdf>(&bsdf)) return mirrorReflectance(*m, wo.z);
  // Deterministic importance-sampled quadrature: the mean of sample() weights over a
  // midpoint grid of the unit square. The mixture sampler covers the whole support of f, so
  // this converges to ∫ f cos θi dωi; 128² points give ≈ 1e-3 relative accuracy.
  constexpr int kGrid = 128;
  DVec3 sum(0.0);
  for (int a = 0; a < kGrid; ++a)
    for (int b = 0; b < kGrid; ++b) {
      const auto s = sample(bsdf, wo, Vec2((a + 0.5f) / kGrid, (b + 0.5f) / kGrid));
      if (s) sum += DVec3(s->weight);
    }
  return Rgb(sum / static_cast<double>(kGrid * kGrid));
}

Bsdf withDiffuseAlbedo(const Bsdf& bsdf, const Rgb& albedo) {
  return std::visit(Overloaded{
                        [&](LambertBsdf b) -> Bsdf {
                          b.albedo = albedo;
                          return b;
                        },
                        [&](MirrorBsdf b) -> Bsdf { return b; },
                        [&](BlinnPhongBsdf b) -> Bsdf {
                          b.diffuse = albedo;
                          return b;
                        },
                        [&](GgxBsdf b) -> Bsdf {
                          b.diffuse = albedo;
                          return b;
                        },
                        [&](DielectricBsdf b) -> Bsdf { return b; },
                    },
                    bsdf);
}

const char* modelName(const Bsdf& bsdf) {
  return std::visit(Overloaded{
                        [](const LambertBsdf&) { return "lambert"; },
                        [](const MirrorBsdf&) { return "mirror"; },
                        [](const BlinnPhongBsdf&) { return "blinn-phong"; },
                        [](const GgxBsdf&) { return "ggx"; },
                        [](const DielectricBsdf& b) {
                          return b.thin ? "thin-dielectric" : b.isSmooth() ? "dielectric" : "rough-dielectric";
                        },
                    },
                    bsdf);
}

}  // namespace pl
