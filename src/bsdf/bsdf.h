#pragma once
// Reflection models (BRDFs). The contract, written once:
//
//  * All directions are unit vectors in the *local shading frame*: the normal is +z, and both
//    wo (towards the viewer / where light goes) and wi (towards where light comes from) point
//    away from the surface. cos θ of a local direction is its z.
//  * eval(b, wo, wi) returns f_r(wo, wi) in sr⁻¹ per RGB channel, WITHOUT the cos θi factor.
//    It is zero when wo or wi lies below the surface (z <= 0), and zero for delta (ideal
//    specular) components, which only sample() can produce.
//  * pdf(b, wo, wi) is the solid-angle density of sample() choosing wi given wo, for the
//    non-delta part of the model (0 for a pure mirror). It integrates over the hemisphere to
//    1 minus the probability that sample() returns nothing (a lobe sample that left the
//    hemisphere), so pdf() is exactly the density of the directions sample() returns.
//  * sample(b, wo, u) draws wi from a density approximately proportional to f_r·cos θi and
//    returns the *weight* f_r·cos θi / pdf (for a delta lobe: the reflectance itself), the
//    value f_r (zero for delta lobes) and the pdf. It returns nothing when the sample is
//    invalid (below the surface, zero pdf).
//  * Every model conserves energy (∫ f_r cos θi dωi ≤ 1 for every wo) and is reciprocal
//    (f_r(wo, wi) = f_r(wi, wo)); the tests check both numerically.
//
// Models form a closed set dispatched statically through std::variant.
#include "core/math.h"

#include <algorithm>
#include <optional>
#include <variant>

namespace pl {

/// Ideal diffuse: f = albedo / π.
struct LambertBsdf {
  Rgb albedo{0.8f};
};

/// Ideal specular reflection. With fresnel = false the reflectance is `reflectance`; with
/// fresnel = true it is Schlick's approximation with F0 = reflectance.
struct MirrorBsdf {
  Rgb reflectance{1.0f};
  bool fresnel = false;
};

/// Normalised Blinn-Phong (tri-Ace, Gotanda 2010):
///   f = diffuse/π + specular · N(n) · cos^n θh
/// where θh is the angle between the normal and the half vector h = normalize(wo + wi).
/// N(n) is the *exact* normal-incidence normalisation (blinnPhongNormalization below), of
/// which the talk's (n + 8)/(8π) is an approximation: (n + 8)/(8π) is up to 7.5 % too large
/// (at n = 8), so with it a white specular lobe would reflect more than it receives. With
/// N(n), ∫ f cos θi dωi = diffuse + specular at normal incidence and less elsewhere, so
/// energy is conserved when diffuse + specular ≤ 1 per channel (the loader enforces it).
/// f is symmetric in (wo, wi) because h is.
struct BlinnPhongBsdf {
  Rgb diffuse{0.5f};
  Rgb specular{0.04f};
  float exponent = 64.0f;  ///< n, the Phong exponent (MTL Ns)
};

/// GGX (Trowbridge–Reitz) microfacet specular with Schlick Fresnel over a Lambertian base:
///   f = F(wo·h) D(h) G2(wo, wi) / (4 cos θo cos θi)
///     + diffuse/π · (1 − E(θo)) (1 − E(θi)) / (1 − Ē)
/// with D the GGX distribution, G2 Smith's height-correlated masking-shadowing, E(θ) the
/// specular lobe's directional albedo and Ē = 2∫E(μ)μ dμ its cosine-weighted mean (Kelemen &
/// Szirmay-Kalos 2001). Both terms are symmetric in (wo, wi), and ∫ f cos θi = E(θo) +
/// diffuse·(1 − E(θo)) ≤ 1 for diffuse ≤ 1 (derivation and tables in bsdf.cpp).
/// α is clamped to [kGgxMinAlpha, 1].
struct GgxBsdf {
  Rgb diffuse{0.0f};  ///< Lambertian base albedo
  Rgb f0{0.04f};      ///< Fresnel reflectance at normal incidence
  float alpha = 0.25f;  ///< GGX roughness α (= perceptual roughness²)
};
inline constexpr float kGgxMinAlpha = 1e-3f;

/// The glTF 2.0 metallic-roughness material as a GgxBsdf (the mapping of the glTF spec's
/// appendix B): f0 = mix(0.04, baseColor, metallic), diffuse = baseColor·(1 − metallic),
/// α = roughness².
GgxBsdf ggxFromMetallicRoughness(const Rgb& baseColor, float metallic, float roughness);

/// Exact normalisation of the Blinn-Phong lobe cos^n θh so that ∫ N cos^n θh cos θi dωi = 1
/// at normal incidence: N(n) = (n + 2)(n + 4) / (8π (2^(−n/2) + n)) (F. Giesen, "The
/// Blinn-Phong normalization zoo", 2009). n = 0 gives 1/π (Lambert).
float blinnPhongNormalization(float exponent);
/// The tri-Ace talk's approximation of it, (n + 8)/(8π) (kept for the tests and docs).
inline float triAceBlinnPhongNormalization(float exponent) { return (exponent + 8.0f) / (8.0f * kPi); }
/// Schlick's Fresnel approximation F0 + (1 − F0)(1 − cos θ)^5.
inline Rgb fresnelSchlick(const Rgb& f0, float cosTheta) {
  const float m = std::clamp(1.0f - cosTheta, 0.0f, 1.0f);
  const float m2 = m * m;
  return f0 + (Rgb(1.0f) - f0) * (m2 * m2 * m);
}

using Bsdf = std::variant<LambertBsdf, MirrorBsdf, BlinnPhongBsdf, GgxBsdf>;

struct BsdfSample {
  Vec3 wi{0.0f};      ///< sampled incident direction (local frame)
  Rgb weight{0.0f};   ///< f·cos θi / pdf (for delta lobes: the reflectance)
  Rgb f{0.0f};        ///< f_r(wo, wi) (zero for delta lobes)
  float pdf = 0.0f;   ///< solid-angle density (0 for delta lobes)
  bool delta = false; ///< true when wi came from an ideal specular (Dirac) lobe
};

Rgb eval(const Bsdf& bsdf, const Vec3& wo, const Vec3& wi);
float pdf(const Bsdf& bsdf, const Vec3& wo, const Vec3& wi);
std::optional<BsdfSample> sample(const Bsdf& bsdf, const Vec3& wo, Vec2 u);

/// True when the whole model is a Dirac delta (ideal mirror): no eval, only sample.
bool isDelta(const Bsdf& bsdf);
/// True when f is constant (Lambertian): one value per tixel suffices in the light field.
bool isDiffuse(const Bsdf& bsdf);
/// Hemispherical-directional reflectance ∫ f cos θi dωi for outgoing wo (numerically
/// integrated for models without a closed form). Used by tests and by the bake's energy
/// bookkeeping.
Rgb albedo(const Bsdf& bsdf, const Vec3& wo);
/// The model with its diffuse albedo replaced (texture lookups at a hit point). Models with
/// no diffuse part are returned unchanged.
Bsdf withDiffuseAlbedo(const Bsdf& bsdf, const Rgb& albedo);
/// A short name for messages and `info`: "lambert", "mirror", "blinn-phong", "ggx".
const char* modelName(const Bsdf& bsdf);

}  // namespace pl
