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
//    non-delta part of the model (0 for a pure mirror).
//  * sample(b, wo, u) draws wi from a density approximately proportional to f_r·cos θi and
//    returns the *weight* f_r·cos θi / pdf (for a delta lobe: the reflectance itself), the
//    value f_r (zero for delta lobes) and the pdf. It returns nothing when the sample is
//    invalid (below the surface, zero pdf).
//  * Every model conserves energy (∫ f_r cos θi dωi ≤ 1 for every wo) and is reciprocal
//    (f_r(wo, wi) = f_r(wi, wo)); the tests check both numerically.
//
// Models form a closed set dispatched statically through std::variant.
#include "core/math.h"

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

/// Normalised Blinn-Phong as in the tri-Ace talk:
///   f = diffuse/π + specular · (n + 8)/(8π) · cos^n θh
/// where θh is the angle between the normal and the half vector. Energy is conserved when
/// diffuse + specular ≤ 1 per channel (the loader enforces it).
struct BlinnPhongBsdf {
  Rgb diffuse{0.5f};
  Rgb specular{0.04f};
  float exponent = 64.0f;  ///< n, the Phong exponent (MTL Ns)
};

/// GGX (Trowbridge–Reitz) microfacet specular with Schlick Fresnel and a Lambertian base.
/// The exact form (and how glTF metallic-roughness maps onto it) is documented in bsdf.cpp.
struct GgxBsdf {
  Rgb diffuse{0.0f};  ///< Lambertian base albedo
  Rgb f0{0.04f};      ///< Fresnel reflectance at normal incidence
  float alpha = 0.25f;  ///< GGX roughness α (= perceptual roughness²)
};

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
