#pragma once
// Scattering models (BRDFs, and BTDFs for dielectrics). The contract, written once:
//
//  * All directions are unit vectors in the *local shading frame*: the normal is +z, and both
//    wo (towards the viewer / where light goes) and wi (towards where light comes from) point
//    away from the surface. cos θ of a local direction is its z.
//  * Reflection-only models (everything but DielectricBsdf) live in the upper hemisphere:
//    callers flip the frame to the side wo is on (two-sided shading), and eval/pdf are zero
//    and sample returns nothing whenever wo or wi has z <= 0.
//  * Transmissive models (hasTransmission(): DielectricBsdf) are defined on both sides. +z is
//    the surface's *outside* (the front side of the geometry, the side the winding normal
//    points to), and the frame is NOT flipped: wo.z < 0 means the viewer is inside. wo and wi
//    on opposite sides (wo.z · wi.z < 0) is transmission. Radiance is not symmetric across an
//    interface: it scales by η² (η the refractive index on each side), and the models obey
//    the generalised reciprocity f(wo, wi) / η(wo)² = f(wi, wo) / η(wi)², where η(w) is the
//    index of the medium w lies in (Veach 1997, §5.2; Walter et al. 2007, eq. 21). Energy is
//    conserved in the flux form ∫ f(wo, wi) |cos θo| dωo ≤ 1 for every wi (light arriving
//    from wi is reflected or transmitted, never amplified); in the radiance form ∫ … dωi a
//    BTDF from the dense side exceeds 1 by up to η².
//  * eval(b, wo, wi) returns f(wo, wi) in sr⁻¹ per RGB channel, WITHOUT the |cos θi| factor.
//    It is zero for delta (ideal specular) components, which only sample() can produce.
//  * pdf(b, wo, wi) is the solid-angle density of sample() choosing wi given wo, for the
//    non-delta part of the model (0 for a pure mirror or smooth glass). It integrates over
//    the sphere to 1 minus the probability that sample() returns nothing (a lobe sample that
//    left its hemisphere), so pdf() is exactly the density of the directions sample() returns.
//  * sample(b, wo, u) draws wi from a density approximately proportional to f·|cos θi| and
//    returns the *weight* f·|cos θi| / pdf (for a delta lobe: the reflectance or radiance
//    transmittance of the branch taken, divided by the probability of taking it), the value f
//    (zero for delta lobes) and the pdf. It returns nothing when the sample is invalid
//    (outside its hemisphere, zero pdf).
//  * Every model conserves energy and is reciprocal in the forms above (for reflection-only
//    models: ∫ f cos θi dωi ≤ 1 and f(wo, wi) = f(wi, wo)); the tests check both numerically.
//
// Models form a closed set dispatched statically through std::variant.
#include "core/math.h"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace pl {

/// Ideal diffuse: f = albedo / π.
struct LambertBsdf {
  Rgb albedo{0.8f};

  /// The serialisation hook every model has: f(field) for each parameter, in the order of
  /// the .plf encoding (lightfield/plf_file.cpp); Self is the model, const or not.
  template <class Self, class F>
  static void parameters(Self& b, F&& f) { f(b.albedo); }
};

/// Ideal specular reflection. With fresnel = false the reflectance is `reflectance`; with
/// fresnel = true it is Schlick's approximation with F0 = reflectance.
struct MirrorBsdf {
  Rgb reflectance{1.0f};
  bool fresnel = false;

  template <class Self, class F>
  static void parameters(Self& b, F&& f) { f(b.reflectance), f(b.fresnel); }
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

  template <class Self, class F>
  static void parameters(Self& b, F&& f) { f(b.diffuse), f(b.specular), f(b.exponent); }
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

  template <class Self, class F>
  static void parameters(Self& b, F&& f) { f(b.diffuse), f(b.f0), f(b.alpha); }
};
inline constexpr float kGgxMinAlpha = 1e-3f;

// ---- Parameter conversions (the only place they are written) ----------------------------
//
// Perceptual roughness r ∈ [0, 1] (glTF, Disney/UE4 "roughness") maps to the GGX α = r²
// (Burley 2012; glTF 2.0 appendix B). A Blinn-Phong lobe cosⁿθh matches the Beckmann
// distribution of roughness α near its peak when n = 2/α² − 2 (Walter et al. 2007, §5.2), so
// α = √(2/(n + 2)) the other way; GGX of the same α has a narrower core (half width at half
// maximum tan θh = 0.64α against Beckmann's 0.83α) and longer tails.

/// α = r², unclamped (for loaders that validate the result themselves).
inline float alphaFromRoughness(float roughness) { return roughness * roughness; }
/// GGX α of perceptual roughness r (clamped to [0, 1]): r², floored at kGgxMinAlpha (α → 0
/// makes the distribution a Dirac delta, which GgxBsdf does not model).
float ggxAlphaFromRoughness(float roughness);
/// Dielectric α of perceptual roughness r (clamped to [0, 1]): r², or exactly 0 (the smooth,
/// delta form of DielectricBsdf) when r² < kGgxMinAlpha.
float dielectricAlphaFromRoughness(float roughness);
/// The Blinn-Phong exponent n = 2/α² − 2 whose lobe matches GGX α near the peak (≥ 0).
float blinnPhongExponentFromAlpha(float alpha);
/// The inverse, α = √(2/(n + 2)).
float alphaFromBlinnPhongExponent(float exponent);

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

/// A dielectric interface (glass, water) between the outside (+z, index 1) and an inside of
/// relative index η = n_inside / n_outside, in one of three forms:
///  * smooth (alpha == 0, thin == false): ideal reflection and refraction, with the exact
///    unpolarised Fresnel reflectance F (fresnelDielectric) and total internal reflection;
///    sample() takes reflection with probability F and refraction otherwise, so its weight is
///    1 for reflection and transmittance/η'² for refraction (η' the ratio of the index on wi's
///    side to that on wo's side: radiance entering a denser medium grows by η'²).
///  * rough (alpha > 0, thin == false): GGX microfacet reflection + transmission (Walter et
///    al. 2007), height-correlated Smith masking, sampled with visible normals (Heitz 2018).
///  * thin (thin == true): a sheet with two parallel interfaces and nothing between them
///    bending light: a ray passes straight through (wi = −wo) or reflects, with the
///    inter-reflections inside summed in closed form:
///      R' = R + T² t² R / (1 − R² t²),   T' = T² t / (1 − R² t²)
///    with R = F(cos θ), T = 1 − R, and t the `transmittance` of one pass through the sheet.
///    Thin sheets are smooth (alpha is ignored).
/// `transmittance` multiplies every refraction (a closed object filters by its square); it is
/// the only colour of the model (reflection is white, as Fresnel's is). `absorption` is the
/// Beer–Lambert coefficient σa (per scene unit, per channel) of the inside, applied by the
/// path tracer over the distance a path travels inside a closed mesh; the BSDF ignores it.
struct DielectricBsdf {
  float ior = 1.5f;          ///< η = n_inside / n_outside (> 0)
  Rgb transmittance{1.0f};   ///< in [0, 1]
  float alpha = 0.0f;        ///< GGX roughness α (= perceptual roughness²); 0 = smooth
  bool thin = false;
  Rgb absorption{0.0f};      ///< σa ≥ 0 per scene unit (inside a closed mesh)

  bool isSmooth() const { return thin || alpha < kGgxMinAlpha; }

  template <class Self, class F>
  static void parameters(Self& b, F&& f) { f(b.ior), f(b.transmittance), f(b.alpha), f(b.thin), f(b.absorption); }
};

/// The glTF 2.0 PBR material with the KHR_materials_specular, KHR_materials_clearcoat and
/// KHR_materials_sheen layers (glTF 2.0 appendix B and the extensions' READMEs), bottom up:
///   base   f_b = f_spec + f_d: a GGX lobe (α, Schlick Fresnel from f0 at normal incidence
///          to f90 at grazing — KHR_materials_specular's weight) over the diffuse ρ. glTF's
///          base is mix(dielectric, metal, metallic); Schlick's F is linear in (f0, f90), so
///          the two members' lobes sum to one lobe of the mixed (f0, f90), and the diffuse
///          (the dielectric's, ρ = baseColor·(1 − metallic)) gives up the share of the
///          dielectric member's lobe alone: E_d below, of (dielectricF0, dielectricF90);
///   sheen  f_s = sheenColor · D_charlie(h) / ((1 + Λ(wo) + Λ(wi)) 4 cos θo cos θi)
///          (Estevez & Kulla 2017: the "Charlie" distribution and visibility, as the
///          sheen README's reference), roughness r ∈ [kSheenMinRoughness, 1];
///   coat   f_c = clearcoat · GGX(α_c, f0 = 0.04 i.e. ior 1.5, f90 = 1).
/// Each layer scales what lies below by the sheen README's reciprocal albedo scaling,
///   T_l(wo, wi) = 1 − w_l · max(E_l(θo), E_l(θi))     (w the layer's weight, E its lobe's
/// directional albedo; w = max(sheenColor) for sheen, clearcoat for the coat), except the
/// diffuse term, whose scaling is the separable product of the same factors (Kelemen-style):
///   f = f_c + T_c (f_s + T_s f_spec) + ρ/π · g(θo) g(θi) / Ḡ,
///   g(θ) = (1 − E_d(θ)) (1 − w_s E_s(θ)) (1 − w_c E_c(θ)),   Ḡ = 2∫ g(μ) μ dμ,
/// E_d the directional albedo of the GGX lobe of α with Fresnel from dielectricF0 to
/// dielectricF90. Every term is symmetric in (wo, wi) — reciprocal exactly — and ∫ f cos θi
/// dωi ≤ 1 when, per channel, ρ ≤ 1, f0 ≤ 1 − ρ (1 − dielectricF0) and f90 ≤ 1 − ρ (1 −
/// dielectricF90) (derivation in bsdf.cpp; every glTF mapping meets it, and so does
/// dielectricF0 = f0, dielectricF90 = f90: the diffuse coupled to the whole lobe, as GgxBsdf
/// couples it). With no sheen and no coat, f90 = 1 and the dielectric Fresnel the lobe's, it is
/// GgxBsdf. gltfPbrFromInputs builds it from the glTF factors.
struct GltfPbrBsdf {
  Rgb diffuse{0.8f};          ///< ρ = baseColor · (1 − metallic)
  Rgb f0{0.04f};              ///< base lobe's Fresnel at normal incidence
  float f90 = 1.0f;           ///< base lobe's Fresnel at grazing incidence, in [0, 1]
  float alpha = 0.25f;        ///< base GGX α
  float clearcoat = 0.0f;     ///< coat weight in [0, 1] (0: no coat)
  float clearcoatAlpha = 0.0625f;  ///< coat GGX α
  Rgb sheenColor{0.0f};       ///< sheen colour in [0, 1] (black: no sheen)
  float sheenRoughness = 0.5f;  ///< Charlie roughness r (not squared), in [0, 1]
  /// The dielectric member's Fresnel (f0 at normal incidence, f90 at grazing), whose lobe the
  /// diffuse gives up (E_d above); both in [0, 1].
  Rgb dielectricF0{0.04f};
  float dielectricF90 = 1.0f;

  /// The .plf encodes the fields in this order; files of format version 5 and older end the
  /// list at sheenRoughness and mean dielectricF0 = f0, dielectricF90 = f90 (plf_file.cpp).
  template <class Self, class F>
  static void parameters(Self& b, F&& f) {
    f(b.diffuse), f(b.f0), f(b.f90), f(b.alpha), f(b.clearcoat), f(b.clearcoatAlpha), f(b.sheenColor),
        f(b.sheenRoughness), f(b.dielectricF0), f(b.dielectricF90);
  }
};
/// The Charlie distribution's roughness floor: below it the fitted visibility term and the
/// distribution (∝ sin^(1/r) θh) leave the range the fit was made for.
inline constexpr float kSheenMinRoughness = 0.07f;

/// The glTF inputs of GltfPbrBsdf: the core metallic-roughness factors, KHR_materials_ior's
/// ior, KHR_materials_specular's specularFactor and specularColorFactor, KHR_materials_
/// clearcoat's factor and roughness and KHR_materials_sheen's colour and roughness, each
/// already multiplied by its texture where it has one.
struct GltfPbrInputs {
  Rgb baseColor{1.0f};
  float metallic = 1.0f, roughness = 1.0f;
  float ior = 1.5f;
  float specular = 1.0f;
  Rgb specularColor{1.0f};
  float clearcoat = 0.0f, clearcoatRoughness = 0.0f;
  Rgb sheenColor{0.0f};
  float sheenRoughness = 0.0f;
};
/// The KHR_materials_specular mapping (its README), mixed with the metal as appendix B mixes:
///   dielectric f0 = min(((ior − 1)/(ior + 1))² · specularColor, 1) · specular,  f90 = specular
///   f0 = mix(dielectric f0, baseColor, metallic),  f90 = mix(specular, 1, metallic),
///   dielectricF0 = dielectric f0,  dielectricF90 = specular,
///   diffuse = baseColor · (1 − metallic),  α = ggxAlphaFromRoughness(roughness),
///   clearcoat α = ggxAlphaFromRoughness(clearcoatRoughness),
/// the rest copied; every factor clamped to its range ([0, 1]; ior ≥ 1).
GltfPbrBsdf gltfPbrFromInputs(const GltfPbrInputs& in);

/// Subsurface scattering: a translucent solid (marble, wax, skin, milk, jade) whose closed mesh
/// bounds a homogeneous medium — the model of Chiang, Kutz & Burley 2016 ("Practical and
/// Controllable Subsurface Scattering for Production Path Tracing"), which Blender Cycles used
/// for its random walk before 3.0 (Cycles 3.x fits the albedo differently and scales the radius;
/// bench/sss_vs_cycles_blender.py converts). Inside, light travels in straight lines between scattering
/// events, is attenuated with the extinction coefficient σt, keeps the fraction α (the single-
/// scattering albedo) at each event and leaves it in a uniformly random direction (isotropic
/// phase function). Both are per RGB channel, derived from the user's albedo A and radius d by
/// subsurfaceMedium() below. The boundary is diffuse and index-matched: a path entering the
/// surface continues in a cosine-distributed direction into the object, and light leaving it
/// leaves cosine-distributed (as from a Lambertian surface of albedo 1), with no Fresnel.
///
/// As a BSDF — eval/pdf/sample, what anything without a random walk sees — it is Lambertian of
/// albedo A, the reflectance the mapping gives a thick slab (where light leaves close to where
/// it entered); the path tracer replaces it by the walk through the medium (trace.h), and the
/// light-field bake by an operator between tixels built from the same walk (bake/subsurface.h).
struct SubsurfaceBsdf {
  Rgb albedo{0.8f};  ///< A in [0, 1): the multiple-scattering albedo of a thick slab
  Rgb radius{1.0f};  ///< d > 0 (scene units): the distance light travels inside, per channel

  template <class Self, class F>
  static void parameters(Self& b, F&& f) { f(b.albedo), f(b.radius); }
};

/// The interior medium of a SubsurfaceBsdf, per RGB channel.
struct SubsurfaceMedium {
  Rgb sigmaT{1.0f};  ///< extinction coefficient σt (per scene unit)
  Rgb alpha{0.0f};   ///< single-scattering albedo α = σs / σt, in [0, 1)
};
/// Chiang et al. 2016's mapping, per channel, from the albedo A and radius d:
///   α  = 1 − exp(−5.09406 A + 2.61188 A² − 4.31805 A³),
///   σt = 1 / (d · s),   s = 1.9 − A + 3.5 (A − 0.8)².
/// α is meant as the single-scattering albedo for which a semi-infinite slab of the medium under
/// uniform light reflects the fraction A — a fit, close for A ≤ 0.8 and short of A above (the
/// slab reflects 0.90 at A = 0.95; measured in docs/design.md) — and 1/σt = d·s the mean free
/// path, scaled so that the light's lateral spread is about d.
SubsurfaceMedium subsurfaceMedium(const SubsurfaceBsdf& b);

/// Exact unpolarised Fresnel reflectance of a dielectric interface for light arriving at
/// cos θ (> 0: from the outside, < 0: from the inside) with η = n_inside / n_outside:
///   F = (r∥² + r⊥²)/2,  r∥ = (η cos θi − cos θt)/(η cos θi + cos θt),
///                       r⊥ = (cos θi − η cos θt)/(cos θi + η cos θt)   (η relative to θi's side)
/// and 1 beyond the critical angle (total internal reflection).
float fresnelDielectric(float cosTheta, float eta);
/// 1 − fresnelDielectric, computed without cancellation near grazing incidence.
float fresnelDielectricTransmittance(float cosTheta, float eta);

/// Thin-sheet reflectance R' and transmittance T' (DielectricBsdf, thin) at |cos θ|.
void thinSheetReflectanceTransmittance(const DielectricBsdf& b, float cosTheta, Rgb& reflectance, Rgb& transmittance);

/// The closed set of models. Adding one: its struct (parameters, and a parameters() hook for
/// serialisation), an entry here (at the end: the index is the .plf model number), and its
/// per-model functions in bsdf.cpp (eval/pdf/sample) and lobe.cpp (lobe, validation) — the
/// compiler names every function a new entry still lacks. Nothing outside bsdf/ switches on it.
using Bsdf =
    std::variant<LambertBsdf, MirrorBsdf, BlinnPhongBsdf, GgxBsdf, DielectricBsdf, GltfPbrBsdf, SubsurfaceBsdf>;

/// A default-constructed model of variant index `index` (the serialised model number);
/// nullopt for an index no model has.
std::optional<Bsdf> bsdfOfIndex(size_t index);

/// The glTF 2.0 metallic-roughness material (the spec's appendix B): the BRDF
///   mix(dielectric_brdf, metal_brdf, metallic),
///   dielectric_brdf = a GGX lobe of f0 0.04 over the diffuse baseColor, which gives up that
///                     lobe's share (fresnel_mix),   metal_brdf = a GGX lobe of f0 baseColor,
/// α = ggxAlphaFromRoughness(roughness), metallic and roughness clamped to [0, 1]. Where
/// metallic is 0 or 1 the mix has one member and this is the GgxBsdf {diffuse = baseColor·
/// (1 − metallic), f0 = mix(0.04, baseColor, metallic), α}; in between it is the GltfPbrBsdf of
/// gltfPbrFromInputs, whose diffuse base gives up only the dielectric lobe's share (a GgxBsdf
/// of the mixed f0 would couple it to the brighter mixed lobe).
Bsdf gltfMetallicRoughnessModel(const Rgb& baseColor, float metallic, float roughness);

// ---- What other modules need to know about a model (the lobe descriptor) ----------------

/// How a model scatters, as the light field classifies it.
enum class LobeKind : uint8_t {
  Delta,    ///< ideal specular only (mirror, smooth or thin glass): no eval, only sample()
  Diffuse,  ///< f constant (Lambert): one value per tixel suffices
  Glossy,   ///< a directional lobe (Blinn-Phong, GGX, rough glass)
};

/// Everything the scene, the bake and the renderers ask about a model, in one place.
struct LobeDescriptor {
  LobeKind kind = LobeKind::Diffuse;
  /// Defined on both sides, frame not flipped (DielectricBsdf; the contract above); reflecting
  /// models are two-sided by flipping the frame to wo's side (scene.h scatteringFrame).
  bool transmits = false;
  /// θh: half width at half maximum of the lobe in half-vector angle (radians); the reflected
  /// lobe's full width at half maximum is ≈ 4θh. 0 for delta models, π/2 for diffuse ones.
  float halfWidth = 0.0f;
  /// The diffuse reflectance a texture multiplies (black for models without a diffuse part).
  Rgb diffuseAlbedo{0.0f};
};
LobeDescriptor describe(const Bsdf& bsdf);

/// The lobe half width θh of describe() alone (see LobeDescriptor::halfWidth):
///   Blinn-Phong cosⁿθh = ½           → θh = acos(2^(−1/n));
///   GGX D ∝ 1/(α² + tan²θh)² (the cos⁴ factor ignored) = ½ D(0) → tan θh = α·√(√2 − 1).
float lobeHalfWidth(const Bsdf& bsdf);
/// The diffuse albedo a texture multiplies (describe().diffuseAlbedo alone; per hit).
Rgb diffuseAlbedo(const Bsdf& bsdf);
/// The Beer–Lambert absorption σa (per scene unit) inside a closed dielectric; black for
/// every other model (per hit).
Rgb interiorAbsorption(const Bsdf& bsdf);
/// The medium of a SubsurfaceBsdf model; nullopt for every other model (per hit).
std::optional<SubsurfaceMedium> subsurfaceMedium(const Bsdf& bsdf);

/// The reason the model's parameters violate the contract above ("" when valid): reflectances
/// in [0, 1] (more would create energy), Blinn-Phong diffuse + specular ≤ 1 per channel and a
/// finite exponent ≥ 0, GGX α in (0, 1], a dielectric's finite positive index, transmittance in
/// [0, 1], α in [0, 1] and finite absorption ≥ 0, a subsurface albedo in [0, 1) and finite radius > 0.
/// Callers prefix file and material.
std::string bsdfProblem(const Bsdf& bsdf);

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

/// True when the whole model is a Dirac delta (ideal mirror, smooth or thin dielectric): no
/// eval, only sample.
bool isDelta(const Bsdf& bsdf);
/// True for models that transmit (DielectricBsdf): defined on both sides, frame not flipped
/// (see the contract above).
bool hasTransmission(const Bsdf& bsdf);
/// True when f is constant (Lambertian): one value per tixel suffices in the light field.
bool isDiffuse(const Bsdf& bsdf);
/// Directional albedo ∫ f |cos θi| dωi for outgoing wo (over both hemispheres for
/// transmissive models; numerically integrated for models without a closed form). Used by tests and by the bake's energy
/// bookkeeping.
Rgb albedo(const Bsdf& bsdf, const Vec3& wo);
/// The model with its diffuse albedo replaced (texture lookups at a hit point). Models with
/// no diffuse part are returned unchanged.
Bsdf withDiffuseAlbedo(const Bsdf& bsdf, const Rgb& albedo);
/// The Fresnel reflectance at normal incidence of the model's glossy lobe (GGX, glTF: f0;
/// black for other models), and the model with it replaced (others unchanged). The lobe is
/// linear in it (Schlick's F = f0 (1 − m⁵) + f90 m⁵), which the bake uses to give each tixel
/// of a metallic-roughness-textured material its own f0 (propagation.cpp GlossyMaterial).
Rgb specularF0(const Bsdf& bsdf);
Bsdf withSpecularF0(const Bsdf& bsdf, const Rgb& f0);
/// The directional factor k(μ) of the model's diffuse part: every model's diffuse term is
///   f_diffuse(wo, wi) = diffuseAlbedo(bsdf)/π · k(μo) · k(μi)        (μ = cos θ, per channel)
/// — k = 1 for Lambert and Blinn-Phong (a plain Lambertian term); for GGX
/// k(μ) = (1 − E(μ)) / √(1 − Ē), E the specular lobe's directional albedo and Ē its cosine-
/// weighted mean (the energy-conserving base above). Zero for μ ≤ 0. The light field stores a
/// glossy chart's diffuse part as one irradiance-like value per tixel, Ẽ = ∫ L k(μi) cos θi dωi,
/// and evaluates ρ(uv)/π · k(μo) · Ẽ where it is seen, so that textures modulate it
/// (lightfield.h "What is stored per chart kind").
Rgb diffuseDirectionalFactor(const Bsdf& bsdf, float cosTheta);
/// A short name for messages and `info`: "lambert", "mirror", "blinn-phong", "ggx",
/// "dielectric" (smooth), "rough-dielectric", "thin-dielectric", "gltf-pbr", "subsurface".
const char* modelName(const Bsdf& bsdf);

}  // namespace pl
