// Reflection models. The contract (local frame, eval without cosine, what sample returns)
// is in bsdf.h; this file holds the formulas, their derivations and the sampling routines.
#include "bsdf/bsdf.h"
#include "bsdf/ggx_lobe.h"

#include <array>
#include <cmath>
#include <memory>
#include <mutex>
#include <vector>

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

std::optional<BsdfSample> sampleLambert(const LambertBsdf& b, Vec2 u) {
  BsdfSample s;
  s.wi = sampleCosineHemisphere(u);
  if (s.wi.z <= 0.0f) return std::nullopt;
  s.pdf = cosineHemispherePdf(s.wi.z);
  s.f = b.albedo * kInvPi;
  s.weight = b.albedo;  // f cos / pdf = (ρ/π) cos / (cos/π)
  return s;
}

/// A subsurface model seen as a BSDF (bsdf.h SubsurfaceBsdf): Lambertian of its albedo.
LambertBsdf surfaceLambert(const SubsurfaceBsdf& b) { return LambertBsdf{b.albedo}; }

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
  /// The tables as they are (ggxAlbedoTables).
  GgxAlbedoTables tables() const {
    GgxAlbedoTables t;
    t.muNodes = kMuNodes;
    t.roughNodes = kRoughNodes;
    t.mu.assign(mu_.begin(), mu_.end());
    for (int r = 0; r < kRoughNodes; ++r) {
      t.e0.insert(t.e0.end(), e0_[r].begin(), e0_[r].end());
      t.e5.insert(t.e5.end(), e5_[r].begin(), e5_[r].end());
    }
    t.mean0.assign(mean0_.begin(), mean0_.end());
    t.mean5.assign(mean5_.begin(), mean5_.end());
    return t;
  }

  /// E₀, E₅ at (μ, α), and the matching cosine-weighted means Ē₀, Ē₅ at α.
  struct Lookup {
    float e0, e5, mean0, mean5;
  };
  Lookup lookup(float mu, float alpha) const {
    const Cell c = locate(mu, alpha);
    auto at = [&](const std::array<std::array<float, kMuNodes>, kRoughNodes>& t, int r) {
      return t[r][c.i0] + c.tm * (t[r][c.i0 + 1] - t[r][c.i0]);
    };
    const int r0 = c.r0;
    const float tr = c.tr;
    Lookup l;
    l.e0 = at(e0_, r0) + tr * (at(e0_, r0 + 1) - at(e0_, r0));
    l.e5 = at(e5_, r0) + tr * (at(e5_, r0 + 1) - at(e5_, r0));
    l.mean0 = mean0_[r0] + tr * (mean0_[r0 + 1] - mean0_[r0]);
    l.mean5 = mean5_[r0] + tr * (mean5_[r0 + 1] - mean5_[r0]);
    return l;
  }

  /// An upper bound of the lobe albedo E = f0 (E₀ − E₅) + f90 E₅ at (μ, α): the larger of the
  /// two roughness rows around α, each interpolated in μ. Between the first rows (α = 1e-3
  /// and 5.4e-3) E falls steeply with α near grazing, and lookup()'s linear interpolation in
  /// √α is up to 1.4 % below the true albedo there; the rows themselves are within 3e-3.
  float upperAlbedo(float mu, float alpha, float f0, float f90) const {
    const Cell c = locate(mu, alpha);
    auto row = [&](int r) {
      const float e0 = e0_[r][c.i0] + c.tm * (e0_[r][c.i0 + 1] - e0_[r][c.i0]);
      const float e5 = e5_[r][c.i0] + c.tm * (e5_[r][c.i0 + 1] - e5_[r][c.i0]);
      return f0 * (e0 - e5) + f90 * e5;
    };
    return std::max(row(c.r0), row(c.r0 + 1));
  }

 private:
  /// The table cell of (μ, α): roughness row r0 and the weight tr of r0 + 1, μ segment i0 and
  /// the weight tm of i0 + 1 (node i sits at μ = (i/(N−1))²: the segment from √μ, linear in μ).
  struct Cell {
    int r0, i0;
    float tr, tm;
  };
  Cell locate(float mu, float alpha) const {
    const float rMin = std::sqrt(kGgxMinAlpha);
    const float rPos = (std::sqrt(clampAlpha(alpha)) - rMin) / (1.0f - rMin) * (kRoughNodes - 1);
    Cell c;
    c.r0 = std::clamp(static_cast<int>(rPos), 0, kRoughNodes - 2);
    c.tr = std::clamp(rPos - static_cast<float>(c.r0), 0.0f, 1.0f);
    mu = std::clamp(mu, 0.0f, 1.0f);
    c.i0 = std::clamp(static_cast<int>(std::sqrt(mu) * (kMuNodes - 1)), 0, kMuNodes - 2);
    c.tm = std::clamp((mu - mu_[c.i0]) / (mu_[c.i0 + 1] - mu_[c.i0]), 0.0f, 1.0f);
    return c;
  }

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
        // At grazing (μ = 0) the lobe is evaluated just above the horizon: exactly at μ = 0,
        // Λ(wo) is infinite and the estimator G2/G1 is 0/0. μ = 1e-4 (θ = 89.994°) is the
        // limit's stand-in: E(μ) is continuous at 0 and its slope there is finite, so the
        // node differs from E(0) by O(1e-4), far below the table's interpolation error
        // between nodes (first node after 0 is μ = 1/(kMuNodes−1)²).
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
/// With Fresnel from f0 to f90 (F = f0 (1 − m⁵) + f90 m⁵, m = 1 − wo·h): E = f0 (E₀ − E₅) + f90 E₅.
GgxLobeAlbedo ggxLobeAlbedo(float alpha, const Rgb& f0, float f90, float mu) {
  const auto l = GgxAlbedoTable::get().lookup(mu, alpha);
  return {f0 * (l.e0 - l.e5) + Rgb(f90 * l.e5), f0 * (l.mean0 - l.mean5) + Rgb(f90 * l.mean5)};
}
GgxLobeAlbedo ggxLobeAlbedo(const GgxBsdf& b, float mu) { return ggxLobeAlbedo(b.alpha, b.f0, 1.0f, mu); }

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

/// The GGX lobe F D G2 / (4 cos θo cos θi), F Schlick's from f0 (normal) to f90 (grazing).
Rgb ggxSpecular(float alphaIn, const Rgb& f0, float f90, const Vec3& wo, const Vec3& wi) {
  const float alpha = clampAlpha(alphaIn);
  const Vec3 h = glm::normalize(wo + wi);
  const float g2 = 1.0f / (1.0f + ggxLambda(alpha, wo) + ggxLambda(alpha, wi));
  const float m = std::clamp(1.0f - glm::dot(wo, h), 0.0f, 1.0f), m2 = m * m;
  const Rgb fresnel = f0 + (Rgb(f90) - f0) * (m2 * m2 * m);  // fresnelSchlick when f90 = 1
  return fresnel * (ggxD(alpha, h) * g2 / (4.0f * wo.z * wi.z));
}
Rgb ggxSpecular(const GgxBsdf& b, const Vec3& wo, const Vec3& wi) { return ggxSpecular(b.alpha, b.f0, 1.0f, wo, wi); }

/// Mixture probability of the specular lobe from the lobe albedos at wo.
float ggxSpecularProbability(const GgxBsdf& b, const Vec3& wo) {
  const GgxLobeAlbedo e = ggxLobeAlbedo(b, wo.z);
  const float s = std::max(0.0f, luminance(e.at));
  const float d = std::max(0.0f, luminance(b.diffuse * (Rgb(1.0f) - e.at)));
  return d + s > 0.0f ? s / (d + s) : 1.0f;
}

float ggxLobePdf(float alphaIn, const Vec3& wo, const Vec3& wi) {
  // p(wi) = D_wo(h) / (4 wo·h) = G1(wo) D(h) / (4 cos θo).
  const float alpha = clampAlpha(alphaIn);
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
  return (1.0f - ps) * cosineHemispherePdf(wi.z) + ps * ggxLobePdf(b.alpha, wo, wi);
}

std::optional<Vec3> sampleGgxDirection(const GgxBsdf& b, const Vec3& wo, Vec2 u) {
  const float ps = ggxSpecularProbability(b, wo);
  if (!chooseFirst(ps, u.x)) return sampleCosineHemisphere(u);
  return reflectAbout(wo, sampleGgxVisibleNormal(clampAlpha(b.alpha), wo, u));
}

// ---------------------------------------------------------------------------------------
// glTF PBR with the specular, sheen and clearcoat layers (GltfPbrBsdf).
//
// Lobes (bsdf.h): the base GGX f_spec (Fresnel f0 → f90), the Charlie sheen f_s, the GGX
// coat f_c (f0 = 0.04, f90 = 1) and the diffuse base. E_spec(μ), E_s(μ) and E_c(μ) are the
// lobes' directional albedos ∫ f_lobe cos θi dωi at cos θo = μ (E_spec per channel; E_s for a
// white sheen colour; E_c for weight 1); E_d(μ) is the albedo of the base's GGX lobe with the
// dielectric member's Fresnel (dielectricF0 → dielectricF90), the share the diffuse gives up. The KHR_materials_sheen README scales the layers
// below a lobe by min(1 − w E(μo), 1 − w E(μi)) = T(wo, wi); we use the same reciprocal form
// for the coat (its README's 1 − clearcoat·F(N·V) is one-sided: its flux-form albedo from a
// grazing direction reaches 1 + clearcoat·(E_c(0) − Ē_c) ≈ 1.9 for a smooth coat over white),
// with the lobe's tabulated E in place of the README's Schlick F(N·V) (which is below E for a
// rough coat near normal incidence, where it would let the sum exceed 1).
//   f = w_c f_c + T_c (f_s + T_s f_spec) + ρ/π g(μo) g(μi) / Ḡ,
//   g(μ) = (1 − E_d(μ)) (1 − w_s E_s(μ)) (1 − w_c E_c(μ)),  Ḡ = 2∫ g μ dμ,
// w_s = max(sheenColor) ≥ each channel. Energy, per channel, for fixed wo (μo):
//   ∫ w_c f_c cos                ≤ w_c E_c(μo)
//   ∫ T_c f_s cos                ≤ (1 − w_c E_c(μo)) w_s E_s(μo)          (T_c ≤ 1 − w_c E_c(μo))
//   ∫ T_c T_s f_spec cos         ≤ (1 − w_c E_c(μo)) (1 − w_s E_s(μo)) E_spec(μo)
//   ∫ ρ/π g(μo) g(μi)/Ḡ cos dωi  = ρ g(μo)
// and their sum is ≤ 1 when E_spec + ρ (1 − E_d) ≤ 1 (it telescopes). E is linear in the
// Fresnel's ends: E = f0 A(μ) + f90 B(μ) with A = E₀ − E₅ ≥ 0, B = E₅ ≥ 0, A + B = E₀ ≤ 1
// (the GGX tables below), so E_spec + ρ (1 − E_d) = ρ + (f0 − ρ dielectricF0) A + (f90 −
// ρ dielectricF90) B, a linear function on the triangle of (A, B), at most 1 iff it is at its
// corners: ρ ≤ 1, f0 ≤ 1 − ρ (1 − dielectricF0), f90 ≤ 1 − ρ (1 − dielectricF90) (bsdf.h;
// lobe.cpp checks them). glTF's mix (f0 = mix(f0_d, c, m), f90 = mix(f90_d, 1, m),
// ρ = c (1 − m)) leaves 1 − ρ(1 − f0_d) − f0 = (1 − c)(1 − (1 − m) f0_d) ≥ 0 and
// (1 − m)(1 − f90_d)(1 − c) ≥ 0. With a white base and a white sheen and coat it is
// 1 − (loss of the T's max) − m (1 − E_metal): the loss is what the reciprocal max takes where
// a layer reflects more at θi than at θo, the second term the metal lobe's own. Each
// term is symmetric in (wo, wi), so f is reciprocal exactly. The diffuse term's separable
// product keeps it one irradiance-like value per tixel in the light field (diffuseDirectional-
// Factor = g/√Ḡ); Ḡ is the GGX table's exact mean without layers, else a 64-point midpoint
// rule in μ² of the interpolated tables.
//
// The Charlie sheen (Estevez & Kulla 2017): D(h) = (2 + 1/r) sin^(1/r) θh / (2π) and the
// visibility 1/((1 + Λ(wo) + Λ(wi)) 4 cos θo cos θi) with their fitted Λ (the README's l()).
// Its E_s(μ, r) comes from a table (below) filled once by quadrature; where the fit makes
// E_s exceed 1 (it is not an exact shadowing function) the lobe is scaled by 1/max_μ E_s for
// that roughness so that it conserves energy alone.
//
// Sampling: a mixture of the coat's and the base's visible-normal samplers, a uniform
// hemisphere for the sheen (its lobe is broad, peaking at grazing) and the cosine hemisphere
// for the diffuse, chosen with probabilities ∝ the terms' albedo estimates at wo above; pdf()
// is the full mixture. The coat's f0 is kClearcoatF0 (ggx_lobe.h: ior 1.5).

inline float sheenRoughness(float r) { return std::clamp(r, kSheenMinRoughness, 1.0f); }

inline float charlieD(float r, float cosH) {
  const float invR = 1.0f / r;
  const float sin2 = std::max(0.0f, 1.0f - cosH * cosH);
  return (2.0f + invR) * std::pow(sin2, 0.5f * invR) * (0.5f * kInvPi);
}

/// Estevez & Kulla's fit l(x, r) of ln Λ (the sheen README's l()).
inline float charlieL(float x, float r) {
  const float t = (1.0f - r) * (1.0f - r);
  const float a = glm::mix(21.5473f, 25.3245f, t), b = glm::mix(3.82987f, 3.32435f, t);
  const float c = glm::mix(0.19823f, 0.16801f, t), d = glm::mix(-1.97760f, -1.27393f, t);
  const float e = glm::mix(-4.32054f, -4.85967f, t);
  return a / (1.0f + b * std::pow(x, c)) + d * x + e;
}

inline float charlieLambda(float cosTheta, float r) {
  return cosTheta < 0.5f ? std::exp(charlieL(cosTheta, r))
                         : std::exp(2.0f * charlieL(0.5f, r) - charlieL(1.0f - cosTheta, r));
}

/// The unscaled Charlie lobe D G / (4 cos θo cos θi) for both directions up, r clamped.
float charlieLobe(float r, const Vec3& wo, const Vec3& wi) {
  const Vec3 h = glm::normalize(wo + wi);
  return charlieD(r, h.z) / ((1.0f + charlieLambda(wo.z, r) + charlieLambda(wi.z, r)) * 4.0f * wo.z * wi.z);
}

/// E_s(μ, r) of the Charlie lobe, on nodes μ_i = (i/(N−1))² × r uniform on
/// [kSheenMinRoughness, 1], and the scale 1/max(1, max_μ E_s) per roughness node; lookup()
/// returns both interpolated, E_s already scaled.
class SheenAlbedoTable {
 public:
  static constexpr int kMuNodes = 32;
  static constexpr int kRoughNodes = 16;
  static constexpr int kQuadratureMu = 96;   ///< midpoint nodes in v, μi = v² (dense at grazing)
  static constexpr int kQuadraturePhi = 48;  ///< midpoint nodes in φ ∈ [0, π] (the lobe is even in φ)

  static const SheenAlbedoTable& get() {
    static const SheenAlbedoTable table;
    return table;
  }

  struct Lookup {
    float albedo, scale;
  };
  Lookup lookup(float mu, float r) const {
    const float rPos = (sheenRoughness(r) - kSheenMinRoughness) / (1.0f - kSheenMinRoughness) * (kRoughNodes - 1);
    const int r0 = std::clamp(static_cast<int>(rPos), 0, kRoughNodes - 2);
    const float tr = std::clamp(rPos - static_cast<float>(r0), 0.0f, 1.0f);
    mu = std::clamp(mu, 0.0f, 1.0f);
    const int i0 = std::clamp(static_cast<int>(std::sqrt(mu) * (kMuNodes - 1)), 0, kMuNodes - 2);
    const float tm = std::clamp((mu - mu_[i0]) / (mu_[i0 + 1] - mu_[i0]), 0.0f, 1.0f);
    auto at = [&](int row) { return e_[row][i0] + tm * (e_[row][i0 + 1] - e_[row][i0]); };
    return {at(r0) + tr * (at(r0 + 1) - at(r0)), scale_[r0] + tr * (scale_[r0 + 1] - scale_[r0])};
  }
  /// The table as the GPU renderer uploads it (ggx_lobe.h sheenAlbedoTables).
  SheenAlbedoTables tables() const {
    SheenAlbedoTables t;
    t.muNodes = kMuNodes;
    t.roughNodes = kRoughNodes;
    t.mu.assign(mu_.begin(), mu_.end());
    for (const auto& row : e_) t.e.insert(t.e.end(), row.begin(), row.end());
    t.scale.assign(scale_.begin(), scale_.end());
    return t;
  }

 private:
  SheenAlbedoTable() {
    for (int i = 0; i < kMuNodes; ++i) {
      const float x = static_cast<float>(i) / (kMuNodes - 1);
      mu_[i] = x * x;
    }
    for (int k = 0; k < kRoughNodes; ++k) {
      const float r = kSheenMinRoughness + (1.0f - kSheenMinRoughness) * static_cast<float>(k) / (kRoughNodes - 1);
      float peak = 0.0f;
      for (int i = 0; i < kMuNodes; ++i) {
        const float mu = std::max(mu_[i], 1e-4f);  // just above the horizon (see GgxAlbedoTable)
        const Vec3 wo(std::sqrt(1.0f - mu * mu), 0.0f, mu);
        // ∫ f μi dωi with dωi = dμi dφ, μi = v²: dμi = 2v dv; φ over [0, π] counted twice.
        double sum = 0.0;
        for (int a = 0; a < kQuadratureMu; ++a) {
          const float v = (a + 0.5f) / kQuadratureMu, mi = v * v, si = std::sqrt(std::max(0.0f, 1.0f - mi * mi));
          for (int b = 0; b < kQuadraturePhi; ++b) {
            const float phi = kPi * (b + 0.5f) / kQuadraturePhi;
            const Vec3 wi(si * std::cos(phi), si * std::sin(phi), mi);
            sum += double(charlieLobe(r, wo, wi)) * mi * 2.0 * v;
          }
        }
        e_[k][i] = static_cast<float>(sum * 2.0 * kPi / (double(kQuadratureMu) * kQuadraturePhi));
        peak = std::max(peak, e_[k][i]);
      }
      scale_[k] = 1.0f / std::max(1.0f, peak);
      for (float& e : e_[k]) e *= scale_[k];
    }
  }

  std::array<float, kMuNodes> mu_{};
  std::array<std::array<float, kMuNodes>, kRoughNodes> e_{};
  std::array<float, kRoughNodes> scale_{};
};

inline float sheenWeight(const GltfPbrBsdf& b) { return std::max(0.0f, maxComponent(b.sheenColor)); }

/// The lobes' directional albedos at μ: E_c (weight 1; the table's upper bound, so that the
/// coat never takes less from the layers below than it reflects), E_s (white, scaled), E_spec.
struct PbrAlbedos {
  float coat = 0.0f, sheen = 0.0f;
  Rgb base{0.0f};
  Rgb dielectric{0.0f};  ///< E_d: the base lobe's albedo with the dielectric member's Fresnel
};
PbrAlbedos pbrAlbedos(const GltfPbrBsdf& b, float mu) {
  PbrAlbedos a;
  if (b.clearcoat > 0.0f) a.coat = GgxAlbedoTable::get().upperAlbedo(mu, b.clearcoatAlpha, kClearcoatF0, 1.0f);
  if (sheenWeight(b) > 0.0f) a.sheen = SheenAlbedoTable::get().lookup(mu, b.sheenRoughness).albedo;
  a.base = ggxLobeAlbedo(b.alpha, b.f0, b.f90, mu).at;
  a.dielectric = b.dielectricF0 == b.f0 && b.dielectricF90 == b.f90
                     ? a.base
                     : ggxLobeAlbedo(b.alpha, b.dielectricF0, b.dielectricF90, mu).at;
  return a;
}

/// g(μ) = (1 − E_d)(1 − w_s E_s)(1 − w_c E_c), per channel, ≥ 0.
Rgb pbrDiffuseShape(const GltfPbrBsdf& b, const PbrAlbedos& a) {
  const float layers = std::max(0.0f, 1.0f - sheenWeight(b) * a.sheen) * std::max(0.0f, 1.0f - b.clearcoat * a.coat);
  return glm::max(Rgb(1.0f) - a.dielectric, Rgb(0.0f)) * layers;
}

/// Ḡ = 2∫ g(μ) μ dμ. Without a coat and a sheen g = 1 − E_d, and Ḡ = 1 − Ē_d exactly for the
/// interpolated table (GgxBsdf's Ē: the model is then GgxBsdf when the dielectric Fresnel is
/// the lobe's); with layers ∫₀¹ g(√v) dv by the midpoint rule in v.
Rgb pbrDiffuseMean(const GltfPbrBsdf& b) {
  if (!(b.clearcoat > 0.0f) && !(sheenWeight(b) > 0.0f))
    return glm::max(Rgb(1.0f) - ggxLobeAlbedo(b.alpha, b.dielectricF0, b.dielectricF90, 1.0f).mean, Rgb(0.0f));
  constexpr int kSteps = 64;
  Rgb sum(0.0f);
  for (int k = 0; k < kSteps; ++k) sum += pbrDiffuseShape(b, pbrAlbedos(b, std::sqrt((k + 0.5f) / kSteps)));
  return sum / float(kSteps);
}

/// 1/√Ḡ per channel (0 where Ḡ ≈ 0: the layers leave the diffuse nothing). Ḡ does not
/// depend on ρ; the last model's value is kept per thread (a path's vertices on one material
/// ask for it with the same parameters many times).
Rgb pbrDiffuseNorm(const GltfPbrBsdf& b) {
  struct Cached {
    GltfPbrBsdf key;
    Rgb norm{0.0f};
    bool valid = false;
  };
  thread_local Cached cache;
  const auto& k = cache.key;
  if (cache.valid && k.f0 == b.f0 && k.f90 == b.f90 && k.alpha == b.alpha && k.clearcoat == b.clearcoat &&
      k.clearcoatAlpha == b.clearcoatAlpha && k.sheenColor == b.sheenColor && k.sheenRoughness == b.sheenRoughness &&
      k.dielectricF0 == b.dielectricF0 && k.dielectricF90 == b.dielectricF90)
    return cache.norm;
  const Rgb mean = pbrDiffuseMean(b);
  Rgb n;
  for (int c = 0; c < 3; ++c) n[c] = mean[c] > 1e-6f ? 1.0f / std::sqrt(mean[c]) : 0.0f;
  cache = {b, n, true};
  return n;
}

Rgb evalGltfPbr(const GltfPbrBsdf& b, const Vec3& wo, const Vec3& wi) {
  if (!sameHemisphereUp(wo, wi)) return Rgb(0.0f);
  const PbrAlbedos o = pbrAlbedos(b, wo.z), i = pbrAlbedos(b, wi.z);
  const float ws = sheenWeight(b);
  Rgb f = ggxSpecular(b.alpha, b.f0, b.f90, wo, wi) * (1.0f - ws * std::max(o.sheen, i.sheen));
  if (ws > 0.0f) {
    const float r = sheenRoughness(b.sheenRoughness);
    f += b.sheenColor * (SheenAlbedoTable::get().lookup(0.0f, r).scale * charlieLobe(r, wo, wi));
  }
  if (b.clearcoat > 0.0f) {
    f *= 1.0f - b.clearcoat * std::max(o.coat, i.coat);
    f += b.clearcoat * ggxSpecular(b.clearcoatAlpha, Rgb(kClearcoatF0), 1.0f, wo, wi);
  }
  if (!isBlack(b.diffuse)) {
    const Rgb norm = pbrDiffuseNorm(b);
    f += b.diffuse * kInvPi * (pbrDiffuseShape(b, o) * norm) * (pbrDiffuseShape(b, i) * norm);
  }
  return f;
}

/// Mixture probabilities at wo of the coat, sheen, base specular and diffuse samplers: the
/// terms' albedo estimates (luminance), normalised; all 0 when nothing reflects.
std::array<float, 4> pbrLobeProbabilities(const GltfPbrBsdf& b, const Vec3& wo) {
  const PbrAlbedos o = pbrAlbedos(b, wo.z);
  const float coat = b.clearcoat * o.coat, belowCoat = std::max(0.0f, 1.0f - coat);
  const float sheen = belowCoat * std::max(0.0f, luminance(b.sheenColor)) * o.sheen;
  const float belowSheen = belowCoat * std::max(0.0f, 1.0f - sheenWeight(b) * o.sheen);
  std::array<float, 4> p = {coat, sheen, belowSheen * std::max(0.0f, luminance(o.base)),
                            std::max(0.0f, luminance(b.diffuse * pbrDiffuseShape(b, o)))};
  const float total = p[0] + p[1] + p[2] + p[3];
  for (float& x : p) x = total > 0.0f ? x / total : 0.0f;
  return p;
}

float pdfGltfPbr(const GltfPbrBsdf& b, const Vec3& wo, const Vec3& wi) {
  if (!sameHemisphereUp(wo, wi)) return 0.0f;
  const std::array<float, 4> p = pbrLobeProbabilities(b, wo);
  float density = p[1] * kUniformHemispherePdf + p[3] * cosineHemispherePdf(wi.z);
  if (p[0] > 0.0f) density += p[0] * ggxLobePdf(b.clearcoatAlpha, wo, wi);
  if (p[2] > 0.0f) density += p[2] * ggxLobePdf(b.alpha, wo, wi);
  return density;
}

std::optional<Vec3> sampleGltfPbrDirection(const GltfPbrBsdf& b, const Vec3& wo, Vec2 u) {
  const std::array<float, 4> p = pbrLobeProbabilities(b, wo);
  // The lobe k whose interval [Σ_{j<k} p_j, Σ_{j≤k} p_j) holds u.x (the last one with p > 0
  // when rounding leaves u.x past the sum), and u.x stretched over it.
  int last = -1;
  for (int k = 0; k < 4; ++k)
    if (p[k] > 0.0f) last = k;
  int lobe = -1;
  float start = 0.0f;
  for (int k = 0; k <= last && lobe < 0; ++k) {
    if (!(p[k] > 0.0f)) continue;
    if (u.x < start + p[k] || k == last) {
      lobe = k;
      u.x = std::clamp((u.x - start) / p[k], 0.0f, 0x1.fffffep-1f);
    }
    start += p[k];
  }
  switch (lobe) {
    case 0: return reflectAbout(wo, sampleGgxVisibleNormal(clampAlpha(b.clearcoatAlpha), wo, u));
    case 1: return sampleUniformHemisphere(u);
    case 2: return reflectAbout(wo, sampleGgxVisibleNormal(clampAlpha(b.alpha), wo, u));
    case 3: return sampleCosineHemisphere(u);
    default: return std::nullopt;
  }
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
// Sampling: a visible normal wm with density D_wo(wm) = G1(wo) |wo·wm| D(wm)/|cos θo|
// (Heitz 2018, for wo turned to +z), then reflection with the microfacet's Fresnel
// P_R = F(wo·wm) (so the weight is G2/G1 on either branch, times t/η'² for refraction; no
// fireflies under total internal reflection of the macro-surface), wi = reflect(wo, wm) or
// refract(wo, wm). Solid-angle densities:
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

Rgb evalRoughDielectricSingle(const DielectricBsdf& b, const Vec3& wo, const Vec3& wi) {
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

float pdfRoughDielectricSingle(const DielectricBsdf& b, const Vec3& wo, const Vec3& wi) {
  Vec3 wm;
  float etap;
  if (!dielectricHalfVector(b, wo, wi, wm, etap)) return 0.0f;
  const float alpha = clampAlpha(b.alpha);
  const float woDotM = std::abs(glm::dot(wo, wm));
  const float visibleNormal = ggxD(alpha, wm) * woDotM / ((1.0f + ggxLambda(alpha, wo)) * std::abs(wo.z));
  const float pR = fresnelDielectric(glm::dot(wo, wm), b.ior);  // the microfacet's Fresnel
  if (wo.z * wi.z > 0.0f) return pR * visibleNormal / (4.0f * woDotM);
  return (1.0f - pR) * visibleNormal * std::abs(glm::dot(wi, wm)) / sqr(glm::dot(wi, wm) + glm::dot(wo, wm) / etap);
}

// Multiple-scattering compensation of the rough dielectric (Kulla & Conty 2017, "Revisiting
// Physically Based Shading at Imageworks", the dielectric extension of their Kelemen-style
// lobe). The single-scattering model above loses the light that scatters more than once
// among the microfacets: its flux-form directional albedo
//   E_s(μ) = ∫ f_ss(wo, w) |cos θo| dωo          (light arriving from w on side s, |cos θ| = μ)
// is below 1 (most at grazing angles and from the inside, where total internal reflection
// sends light back into the micro-surface). A separable lobe adds it back:
//   f_ms(wo, wi) = t_ab c_ab (1 − E_a(|cos θo|)) (1 − E_b(|cos θi|)),   wo on side a, wi on b,
// with t_ab = `transmittance` when a ≠ b (1 otherwise). Its flux-form albedo for light from
// wi on side b is (1 − E_b(μi)) Σ_a t_ab c_ab K_a with K_a = ∫ (1 − E_a) |cos| dω = π(1 − Ē_a)
// (Ē_a = 2∫ E_a(μ) μ dμ), so with t = 1 the total albedo is exactly 1 when
//   outside (b = o):  c_oo K_o + c_io K_i = 1,     inside (b = i):  c_oi K_o + c_ii K_i = 1.
// The generalised reciprocity f(wo, wi)/η(wo)² = f(wi, wo)/η(wi)² holds when
// c_ab/η_a² = c_ba/η_b², i.e. c_io = η² c_oi (η_o = 1, η_i = η). One freedom is left: the
// share x = c_io K_i of the compensated light from the outside that is transmitted. We take
// the macro-surface's hemispherical Fresnel transmittance from the outside, x = 1 − F̄_o,
// capped at η² K_i / K_o so that c_ii ≥ 0:
//   c_io = x/K_i,  c_oo = (1 − x)/K_o,  c_oi = x/(η² K_i),  c_ii = (1 − c_oi K_o)/K_i.
// E_s(μ, α) comes from a table per index of refraction, built on first use (below), for
// each side: from the inside the interface is an outside one of index 1/η.
// Sampling: the compensation lobe is chosen with probability P_ms(wo) (its share of the
// radiance-form albedo, estimated from the tables, at most 1/2), then the side b with
// probability ∝ t_ab c_ab K_b, then μ with the table's piecewise-constant density of
// (1 − E_b(μ)) μ and φ uniform; pdf() is the full mixture.

/// Flux-form directional albedo E(μ, α) of the single-scattering rough dielectric for light
/// arriving from the side of relative index `eta` (the far side's index over the near
/// side's), on nodes μ_i = (i/(N−1))² × r_j = √α uniform, with its cosine-weighted means Ē
/// and the hemispherical Fresnel transmittance 1 − F̄. One table per index (both sides).
class DielectricAlbedoTable {
 public:
  static constexpr int kMuNodes = 32;
  static constexpr int kRoughNodes = 16;
  static constexpr int kQuadrature = 64;  ///< midpoint rule per axis over the visible-normal square

  /// The table for index `ior` (built on first use, thread-safe; cached per thread).
  static const DielectricAlbedoTable& get(float ior);

  /// E at (μ, α) and Ē at α for the outside (inside == false) or the inside.
  void lookup(bool inside, float mu, float alpha, float& e, float& mean) const {
    const int s = inside ? 1 : 0;
    int r0, i0;
    float tr;
    locate(mu, alpha, r0, tr, i0);
    mu = std::clamp(mu, 0.0f, 1.0f);
    const float tm = std::clamp((mu - mu_[i0]) / (mu_[i0 + 1] - mu_[i0]), 0.0f, 1.0f);
    auto at = [&](int r) { return e_[s][r][i0] + tm * (e_[s][r][i0 + 1] - e_[s][r][i0]); };
    e = at(r0) + tr * (at(r0 + 1) - at(r0));
    mean = mean_[s][r0] + tr * (mean_[s][r0 + 1] - mean_[s][r0]);
  }
  float ior() const { return ior_; }

  /// Density over μ ∈ [0, 1] of sampleMissingMu: (1 − E(μ)) μ averaged per segment, mixed
  /// between the two roughness nodes as lookup interpolates E.
  float missingMuPdf(bool inside, float mu, float alpha) const {
    int r0, i0;
    float tr;
    locate(mu, alpha, r0, tr, i0);
    const int s = inside ? 1 : 0;
    const double total = (1.0f - tr) * segments_[s][r0].total() + tr * segments_[s][r0 + 1].total();
    if (!(total > 0.0)) return 0.0f;
    const double w = (1.0f - tr) * segmentWeight_[s][r0][i0] + tr * segmentWeight_[s][r0 + 1][i0];
    return static_cast<float>(w / (total * (mu_[i0 + 1] - mu_[i0])));
  }
  /// μ with density missingMuPdf: a roughness node, a segment, uniform within it.
  float sampleMissingMu(bool inside, float alpha, float u) const {
    int r0, i0;
    float tr;
    locate(0.5f, alpha, r0, tr, i0);
    const int s = inside ? 1 : 0;
    const double w0 = (1.0f - tr) * segments_[s][r0].total(), w1 = tr * segments_[s][r0 + 1].total();
    const int r = chooseFirst(static_cast<float>(w0 / (w0 + w1)), u) ? r0 : r0 + 1;
    float within = 0.0f;
    const size_t i = segments_[s][r].sample(u, &within);
    return mu_[i] + within * (mu_[i + 1] - mu_[i]);
  }
  /// 1 − F̄_o = 2∫ (1 − F(μ)) μ dμ from the outside.
  float meanTransmittanceOutside() const { return meanTransmittanceOutside_; }

  explicit DielectricAlbedoTable(float ior) : ior_(ior) {
    const float rMin = std::sqrt(kGgxMinAlpha);
    for (int i = 0; i < kMuNodes; ++i) {
      const float x = static_cast<float>(i) / (kMuNodes - 1);
      mu_[i] = x * x;
    }
    for (int s = 0; s < 2; ++s) {
      const float eta = s == 0 ? ior : 1.0f / ior;
      for (int r = 0; r < kRoughNodes; ++r) {
        const float rough = rMin + (1.0f - rMin) * static_cast<float>(r) / (kRoughNodes - 1);
        const float alpha = rough * rough;
        for (int i = 0; i < kMuNodes; ++i) {
          // Just above the horizon at μ = 0, where Λ is infinite (see GgxAlbedoTable).
          const float mu = std::max(mu_[i], 1e-4f);
          const Vec3 w(std::sqrt(1.0f - mu * mu), 0.0f, mu);
          const float lambdaW = ggxLambda(alpha, w);
          double sum = 0.0;
          for (int a = 0; a < kQuadrature; ++a)
            for (int b = 0; b < kQuadrature; ++b) {
              // Visible normal m of w; both the reflected and the refracted direction, each
              // with its Fresnel share: flux-form estimator F G2/G1 and (1 − F) G2/G1.
              const Vec3 m = sampleGgxVisibleNormal(alpha, w, Vec2((a + 0.5f) / kQuadrature, (b + 0.5f) / kQuadrature));
              const float cosM = glm::dot(w, m);
              if (!(cosM > 0.0f)) continue;
              const float F = fresnelDielectric(cosM, eta);
              const Vec3 wr = reflectAbout(w, m);
              if (wr.z > 0.0f) sum += F * (1.0f + lambdaW) / (1.0f + lambdaW + ggxLambda(alpha, wr));
              Vec3 wt;
              if (F < 1.0f && refractDirection(w, m, eta, wt) && wt.z < 0.0f)
                sum += (1.0f - F) * (1.0f + lambdaW) / (1.0f + lambdaW + ggxLambda(alpha, wt));
            }
          e_[s][r][i] = static_cast<float>(std::min(1.0, sum / (kQuadrature * kQuadrature)));
        }
        // Exact 2∫ E μ dμ of the piecewise-linear table (as GgxAlbedoTable), and per segment
        // [μ_i, μ_i+1] the integral w_i = ∫ (1 − E) μ dμ of the compensation lobe's shape,
        // which its sampler picks segments by (Σ w_i = (1 − Ē)/2).
        double m = 0.0;
        std::array<float, kMuNodes - 1> w{};
        for (int i = 0; i + 1 < kMuNodes; ++i) {
          const double a = mu_[i], b = mu_[i + 1];
          m += (b - a) * (e_[s][r][i] * (2 * a + b) + e_[s][r][i + 1] * (a + 2 * b)) / 6.0;
          w[i] = static_cast<float>((b - a) * ((1.0 - e_[s][r][i]) * (2 * a + b) + (1.0 - e_[s][r][i + 1]) * (a + 2 * b)) / 6.0);
        }
        mean_[s][r] = static_cast<float>(2.0 * m);
        segmentWeight_[s][r] = w;
        segments_[s][r] = Distribution1D(w);
      }
    }
    // 2∫ (1 − F(μ)) μ dμ by the midpoint rule in μ² (= ∫ (1 − F(√v)) dv).
    constexpr int kSteps = 4096;
    double t = 0.0;
    for (int k = 0; k < kSteps; ++k) t += fresnelDielectricTransmittance(std::sqrt((k + 0.5f) / kSteps), ior);
    meanTransmittanceOutside_ = static_cast<float>(t / kSteps);
  }

 private:
  /// The roughness node r0 below α (and the weight tr of r0 + 1) and the μ segment i0.
  void locate(float mu, float alpha, int& r0, float& tr, int& i0) const {
    const float rMin = std::sqrt(kGgxMinAlpha);
    const float rPos = (std::sqrt(clampAlpha(alpha)) - rMin) / (1.0f - rMin) * (kRoughNodes - 1);
    r0 = std::clamp(static_cast<int>(rPos), 0, kRoughNodes - 2);
    tr = std::clamp(rPos - static_cast<float>(r0), 0.0f, 1.0f);
    const float iPos = std::sqrt(std::clamp(mu, 0.0f, 1.0f)) * (kMuNodes - 1);
    i0 = std::clamp(static_cast<int>(iPos), 0, kMuNodes - 2);
  }

  float ior_;
  float meanTransmittanceOutside_ = 0.0f;
  std::array<float, kMuNodes> mu_{};
  std::array<std::array<std::array<float, kMuNodes>, kRoughNodes>, 2> e_{};
  std::array<std::array<float, kRoughNodes>, 2> mean_{};
  std::array<std::array<std::array<float, kMuNodes - 1>, kRoughNodes>, 2> segmentWeight_{};
  std::array<std::array<Distribution1D, kRoughNodes>, 2> segments_{};
};

const DielectricAlbedoTable& DielectricAlbedoTable::get(float ior) {
  thread_local const DielectricAlbedoTable* last = nullptr;
  if (last && last->ior() == ior) return *last;
  static std::mutex mutex;
  static std::vector<std::unique_ptr<const DielectricAlbedoTable>> tables;  // never freed: pointers stay valid
  const std::lock_guard<std::mutex> lock(mutex);
  for (const auto& t : tables)
    if (t->ior() == ior) return *(last = t.get());
  tables.push_back(std::make_unique<const DielectricAlbedoTable>(ior));
  return *(last = tables.back().get());
}

/// The compensation lobe's constants at (α, η) and the per-direction factors 1 − E.
struct DielectricCompensation {
  float c[2][2] = {{0.0f, 0.0f}, {0.0f, 0.0f}};  ///< c[a][b]: wo on side a, wi on side b (0 = outside)
  float k[2] = {0.0f, 0.0f};                     ///< K_s = π (1 − Ē_s)
  const DielectricAlbedoTable* table = nullptr;
  float alpha = 0.0f;

  /// 1 − E_s(μ), ≥ 0.
  float missing(int side, float mu) const {
    float e, mean;
    table->lookup(side == 1, mu, alpha, e, mean);
    return std::max(0.0f, 1.0f - e);
  }
};

DielectricCompensation dielectricCompensation(const DielectricBsdf& b) {
  DielectricCompensation comp;
  comp.table = &DielectricAlbedoTable::get(b.ior);
  comp.alpha = b.alpha;
  float e, meanO, meanI;
  comp.table->lookup(false, 1.0f, b.alpha, e, meanO);
  comp.table->lookup(true, 1.0f, b.alpha, e, meanI);
  const float kO = kPi * std::max(0.0f, 1.0f - meanO), kI = kPi * std::max(0.0f, 1.0f - meanI);
  constexpr float kTiny = 1e-6f;  // below this the lobe carries no energy worth adding
  if (!(kO > kTiny) || !(kI > kTiny)) return comp;
  const float eta2 = b.ior * b.ior;
  const float x = std::clamp(comp.table->meanTransmittanceOutside(), 0.0f, std::min(1.0f, eta2 * kI / kO));
  comp.k[0] = kO;
  comp.k[1] = kI;
  comp.c[1][0] = x / kI;
  comp.c[0][0] = (1.0f - x) / kO;
  comp.c[0][1] = x / (eta2 * kI);
  comp.c[1][1] = std::max(0.0f, 1.0f - comp.c[0][1] * kO) / kI;
  return comp;
}

inline int dielectricSide(const Vec3& w) { return w.z > 0.0f ? 0 : 1; }

Rgb evalDielectricCompensation(const DielectricBsdf& b, const DielectricCompensation& comp, const Vec3& wo,
                               const Vec3& wi) {
  const int a = dielectricSide(wo), s = dielectricSide(wi);
  const float value = comp.c[a][s] * comp.missing(a, std::abs(wo.z)) * comp.missing(s, std::abs(wi.z));
  return a == s ? Rgb(value) : b.transmittance * value;
}

/// The compensation lobe's radiance-form albedo at wo towards each side: t_ab c_ab (1 − E_a) K_b.
void dielectricCompensationShares(const DielectricBsdf& b, const DielectricCompensation& comp, const Vec3& wo,
                                  float share[2]) {
  const int a = dielectricSide(wo);
  const float missing = comp.missing(a, std::abs(wo.z));
  for (int s = 0; s < 2; ++s) {
    const float t = s == a ? 1.0f : std::max(0.0f, luminance(b.transmittance));
    share[s] = t * comp.c[a][s] * missing * comp.k[s];
  }
}

/// Probability that sample() takes the compensation lobe at wo: its share of the albedo,
/// against the single-scattering albedo (flux form, E_a(μo): close enough for a mixture
/// weight), and 0 when it carries nothing.
float dielectricCompensationProbability(const float share[2], const DielectricCompensation& comp, const Vec3& wo) {
  const float ms = share[0] + share[1];
  if (!(ms > 0.0f)) return 0.0f;
  const int a = dielectricSide(wo);
  const float ss = std::max(0.0f, 1.0f - comp.missing(a, std::abs(wo.z)));
  return std::clamp(ms / (ms + ss), 0.0f, 0.5f);
}

/// Solid-angle density of the compensation lobe's sampler: side b ∝ share, then μ with the
/// table's density of (1 − E_b(μ)) μ and φ uniform.
float pdfDielectricCompensation(const DielectricCompensation& comp, const float share[2], const Vec3& wi) {
  const float total = share[0] + share[1];
  if (!(total > 0.0f)) return 0.0f;
  const int b = dielectricSide(wi);
  return share[b] / total * comp.table->missingMuPdf(b == 1, std::abs(wi.z), comp.alpha) * (0.5f * kInvPi);
}

Rgb evalRoughDielectric(const DielectricBsdf& b, const Vec3& wo, const Vec3& wi) {
  return evalRoughDielectricSingle(b, wo, wi) + evalDielectricCompensation(b, dielectricCompensation(b), wo, wi);
}

float pdfRoughDielectric(const DielectricBsdf& b, const Vec3& wo, const Vec3& wi) {
  const DielectricCompensation comp = dielectricCompensation(b);
  float share[2];
  dielectricCompensationShares(b, comp, wo, share);
  const float pMs = dielectricCompensationProbability(share, comp, wo);
  return (1.0f - pMs) * pdfRoughDielectricSingle(b, wo, wi) + pMs * pdfDielectricCompensation(comp, share, wi);
}

std::optional<BsdfSample> sampleRoughDielectric(const DielectricBsdf& b, const Vec3& wo, Vec2 u) {
  const DielectricCompensation comp = dielectricCompensation(b);
  float share[2];
  dielectricCompensationShares(b, comp, wo, share);
  const float pMs = dielectricCompensationProbability(share, comp, wo);
  Vec3 wi;
  if (pMs > 0.0f && chooseFirst(pMs, u.x)) {
    // The compensation lobe: a side ∝ its share, then μ ∝ (1 − E(μ)) μ, φ uniform.
    const int a = dielectricSide(wo);
    const bool sameSide = chooseFirst(share[a] / (share[0] + share[1]), u.x);
    const int side = sameSide ? a : 1 - a;
    const float mu = comp.table->sampleMissingMu(side == 1, comp.alpha, u.x);
    if (!(mu > 0.0f)) return std::nullopt;
    const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - mu * mu)), phi = kTwoPi * u.y;
    wi = Vec3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), side == 0 ? mu : -mu);
  } else {
    // A visible normal, then reflection with the microfacet's Fresnel F(wo·wm), drawn with
    // the low-order bits of u.x (fract(4096 u.x): independent of u.x to within 1/4096).
    const Vec3 woUp = wo.z < 0.0f ? -wo : wo;
    const Vec3 wm = sampleGgxVisibleNormal(clampAlpha(b.alpha), woUp, u);
    const float scaled = u.x * 4096.0f;
    const bool reflectLobe = scaled - std::floor(scaled) < fresnelDielectric(glm::dot(wo, wm), b.ior);
    if (reflectLobe) {
      wi = reflectAbout(wo, wm);
      if (!(wi.z * wo.z > 0.0f)) return std::nullopt;
    } else {
      // wo·wm has the sign of cos θo (wm is a visible normal of woUp).
      const bool outside = glm::dot(wo, wm) > 0.0f;
      if (!refractDirection(wo, outside ? wm : -wm, outside ? b.ior : 1.0f / b.ior, wi)) return std::nullopt;
      if (!(wi.z * wo.z < 0.0f)) return std::nullopt;
    }
  }
  if (!isFinite(wi)) return std::nullopt;
  BsdfSample s;
  s.wi = glm::normalize(wi);
  s.pdf = (1.0f - pMs) * pdfRoughDielectricSingle(b, wo, s.wi) + pMs * pdfDielectricCompensation(comp, share, s.wi);
  if (!(s.pdf > 0.0f)) return std::nullopt;
  s.f = evalRoughDielectricSingle(b, wo, s.wi) + evalDielectricCompensation(b, comp, wo, s.wi);
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

Rgb eval(const Bsdf& bsdf, const Vec3& wo, const Vec3& wi) {
  return std::visit(Overloaded{
                        [&](const LambertBsdf& b) { return evalLambert(b, wo, wi); },
                        [&](const MirrorBsdf&) { return Rgb(0.0f); },
                        [&](const BlinnPhongBsdf& b) { return evalBlinnPhong(b, wo, wi); },
                        [&](const GgxBsdf& b) { return evalGgx(b, wo, wi); },
                        [&](const DielectricBsdf& b) {
                          return b.isSmooth() ? Rgb(0.0f) : evalRoughDielectric(b, wo, wi);
                        },
                        [&](const GltfPbrBsdf& b) { return evalGltfPbr(b, wo, wi); },
                        [&](const SubsurfaceBsdf& b) { return evalLambert(surfaceLambert(b), wo, wi); },
                    },
                    bsdf);
}

float pdf(const Bsdf& bsdf, const Vec3& wo, const Vec3& wi) {
  const auto lambertPdf = [&] { return sameHemisphereUp(wo, wi) ? cosineHemispherePdf(wi.z) : 0.0f; };
  return std::visit(Overloaded{
                        [&](const LambertBsdf&) { return lambertPdf(); },
                        [&](const SubsurfaceBsdf&) { return lambertPdf(); },
                        [&](const MirrorBsdf&) { return 0.0f; },
                        [&](const BlinnPhongBsdf& b) { return pdfBlinnPhong(b, wo, wi); },
                        [&](const GgxBsdf& b) { return pdfGgx(b, wo, wi); },
                        [&](const DielectricBsdf& b) {
                          return b.isSmooth() ? 0.0f : pdfRoughDielectric(b, wo, wi);
                        },
                        [&](const GltfPbrBsdf& b) { return pdfGltfPbr(b, wo, wi); },
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
                        [&](const LambertBsdf& b) { return sampleLambert(b, u); },
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
                        [&](const GltfPbrBsdf& b) { return finishSample(bsdf, wo, sampleGltfPbrDirection(b, wo, u)); },
                        [&](const SubsurfaceBsdf& b) { return sampleLambert(surfaceLambert(b), u); },
                    },
                    bsdf);
}

Rgb albedo(const Bsdf& bsdf, const Vec3& wo) {
  const auto* dielectric = std::get_if<DielectricBsdf>(&bsdf);
  if (!(wo.z > 0.0f) && !(dielectric && wo.z < 0.0f)) return Rgb(0.0f);
  if (dielectric && dielectric->isSmooth()) return dielectricAlbedo(*dielectric, wo);
  if (const auto* l = std::get_if<LambertBsdf>(&bsdf)) return l->albedo;
  if (const auto* l = std::get_if<SubsurfaceBsdf>(&bsdf)) return l->albedo;
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
                        [&](GltfPbrBsdf b) -> Bsdf {
                          b.diffuse = albedo;
                          return b;
                        },
                        [&](SubsurfaceBsdf b) -> Bsdf {
                          b.albedo = albedo;
                          return b;
                        },
                    },
                    bsdf);
}

Rgb specularF0(const Bsdf& bsdf) {
  if (const auto* ggx = std::get_if<GgxBsdf>(&bsdf)) return ggx->f0;
  if (const auto* pbr = std::get_if<GltfPbrBsdf>(&bsdf)) return pbr->f0;
  return Rgb(0.0f);
}

Bsdf withSpecularF0(const Bsdf& bsdf, const Rgb& f0) {
  Bsdf b = bsdf;
  if (auto* ggx = std::get_if<GgxBsdf>(&b)) ggx->f0 = f0;
  if (auto* pbr = std::get_if<GltfPbrBsdf>(&b)) pbr->f0 = f0;
  return b;
}

Rgb diffuseDirectionalFactor(const Bsdf& bsdf, float cosTheta) {
  if (!(cosTheta > 0.0f)) return Rgb(0.0f);
  const float mu = std::min(cosTheta, 1.0f);
  if (const auto* ggx = std::get_if<GgxBsdf>(&bsdf)) return ggxDiffuseFactor(*ggx, mu);
  if (const auto* pbr = std::get_if<GltfPbrBsdf>(&bsdf)) return pbrDiffuseShape(*pbr, pbrAlbedos(*pbr, mu)) * pbrDiffuseNorm(*pbr);
  return Rgb(1.0f);
}

std::optional<GgxLobeParameters> ggxLobeParameters(const Bsdf& bsdf) {
  if (const auto* ggx = std::get_if<GgxBsdf>(&bsdf))
    return GgxLobeParameters{ggx->diffuse, clampAlpha(ggx->alpha), ggx->f0, 1.0f, ggx->f0, 1.0f};
  const auto* pbr = std::get_if<GltfPbrBsdf>(&bsdf);
  if (pbr == nullptr) return std::nullopt;
  GgxLobeParameters p{pbr->diffuse, clampAlpha(pbr->alpha), pbr->f0, pbr->f90, pbr->dielectricF0, pbr->dielectricF90};
  if (pbr->clearcoat > 0.0f || sheenWeight(*pbr) > 0.0f) {
    p.clearcoat = pbr->clearcoat;
    p.clearcoatAlpha = clampAlpha(pbr->clearcoatAlpha);
    p.sheenColor = pbr->sheenColor;
    p.sheenRoughness = sheenRoughness(pbr->sheenRoughness);
    p.diffuseNorm = pbrDiffuseNorm(*pbr);
  }
  return p;
}

const SheenAlbedoTables& sheenAlbedoTables() {
  static const SheenAlbedoTables tables = SheenAlbedoTable::get().tables();
  return tables;
}

const GgxAlbedoTables& ggxAlbedoTables() {
  static const GgxAlbedoTables tables = GgxAlbedoTable::get().tables();
  return tables;
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
                        [](const GltfPbrBsdf&) { return "gltf-pbr"; },
                        [](const SubsurfaceBsdf&) { return "subsurface"; },
                    },
                    bsdf);
}

}  // namespace pl
