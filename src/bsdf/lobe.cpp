// What other modules need to know about a scattering model — its lobe descriptor, validation
// and the parameter conversions (bsdf.h). The per-model answers are overloads below: a model
// added to the Bsdf variant without them does not compile.
#include <fmt/format.h>

#include <cmath>
#include <utility>

#include "bsdf/bsdf.h"

namespace pl {
namespace {

// ---- Lobe kind ----------------------------------------------------------------------------

LobeKind kindOf(const LambertBsdf&) { return LobeKind::Diffuse; }
LobeKind kindOf(const MirrorBsdf&) { return LobeKind::Delta; }
LobeKind kindOf(const BlinnPhongBsdf&) { return LobeKind::Glossy; }
LobeKind kindOf(const GgxBsdf&) { return LobeKind::Glossy; }
LobeKind kindOf(const DielectricBsdf& b) { return b.isSmooth() ? LobeKind::Delta : LobeKind::Glossy; }
LobeKind kindOf(const GltfPbrBsdf&) { return LobeKind::Glossy; }
LobeKind kindOf(const SubsurfaceBsdf&) { return LobeKind::Diffuse; }

bool transmitsOf(const DielectricBsdf&) { return true; }
template <class Model>
bool transmitsOf(const Model&) { return false; }

// ---- Lobe width ---------------------------------------------------------------------------

/// θh at half maximum of GGX D ∝ 1/(α² + tan²θh)² (cos⁴θh ignored): (α² + tan²)² = 2α⁴
/// ⇒ tan θh = α·√(√2 − 1).
float ggxHalfWidth(float alpha) { return std::atan(alpha * std::sqrt(std::sqrt(2.0f) - 1.0f)); }

float halfWidthOf(const LambertBsdf&) { return 0.5f * kPi; }
float halfWidthOf(const SubsurfaceBsdf&) { return 0.5f * kPi; }
float halfWidthOf(const MirrorBsdf&) { return 0.0f; }
/// cosⁿθh = ½ ⇒ θh = acos(2^(−1/n)); n floored at 1e-3 (n = 0 is Lambert-wide: θh → π/2).
float halfWidthOf(const BlinnPhongBsdf& b) { return std::acos(std::pow(0.5f, 1.0f / std::max(b.exponent, 1e-3f))); }
float halfWidthOf(const GgxBsdf& b) { return ggxHalfWidth(b.alpha); }
float halfWidthOf(const DielectricBsdf& b) { return b.isSmooth() ? 0.0f : ggxHalfWidth(b.alpha); }
/// The narrowest of the lobes present: the base's or the coat's (the sheen is wider than both).
float halfWidthOf(const GltfPbrBsdf& b) {
  const float base = ggxHalfWidth(b.alpha);
  return b.clearcoat > 0.0f ? std::min(base, ggxHalfWidth(b.clearcoatAlpha)) : base;
}

// ---- Diffuse part and interior ------------------------------------------------------------

Rgb diffuseOf(const LambertBsdf& b) { return b.albedo; }
Rgb diffuseOf(const BlinnPhongBsdf& b) { return b.diffuse; }
Rgb diffuseOf(const GgxBsdf& b) { return b.diffuse; }
Rgb diffuseOf(const GltfPbrBsdf& b) { return b.diffuse; }
Rgb diffuseOf(const SubsurfaceBsdf& b) { return b.albedo; }
Rgb diffuseOf(const MirrorBsdf&) { return Rgb(0.0f); }
Rgb diffuseOf(const DielectricBsdf&) { return Rgb(0.0f); }

// ---- Validation ---------------------------------------------------------------------------

std::string str(const Rgb& v) { return fmt::format("({}, {}, {})", v.x, v.y, v.z); }
bool inUnitRange(const Rgb& c) {
  return isFinite(c) && glm::all(glm::greaterThanEqual(c, Rgb(0.0f))) && maxComponent(c) <= 1.0f;
}
/// Slack for decimal inputs such as 0.7 + 0.3 that round to a hair above 1 in float.
constexpr float kSumSlack = 1e-6f;

std::string problemOf(const LambertBsdf& b) {
  if (!inUnitRange(b.albedo)) return fmt::format("Lambert albedo {} outside [0, 1]", str(b.albedo));
  return {};
}
std::string problemOf(const MirrorBsdf& b) {
  if (!inUnitRange(b.reflectance)) return fmt::format("mirror reflectance {} outside [0, 1]", str(b.reflectance));
  return {};
}
std::string problemOf(const BlinnPhongBsdf& b) {
  if (!inUnitRange(b.diffuse) || !inUnitRange(b.specular) || maxComponent(b.diffuse + b.specular) > 1.0f + kSumSlack)
    return fmt::format("Blinn-Phong needs diffuse, specular >= 0 and diffuse + specular <= 1 (diffuse {}, specular {})",
                       str(b.diffuse), str(b.specular));
  if (!(b.exponent >= 0.0f && std::isfinite(b.exponent)))
    return fmt::format("Blinn-Phong exponent {} must be finite and >= 0", b.exponent);
  return {};
}
std::string problemOf(const GgxBsdf& b) {
  if (!inUnitRange(b.diffuse) || !inUnitRange(b.f0))
    return fmt::format("GGX diffuse {} and f0 {} must lie in [0, 1]", str(b.diffuse), str(b.f0));
  if (!(b.alpha > 0.0f && b.alpha <= 1.0f)) return fmt::format("GGX alpha {} must lie in (0, 1]", b.alpha);
  return {};
}
std::string problemOf(const DielectricBsdf& b) {
  if (!(b.ior > 0.0f && std::isfinite(b.ior)))
    return fmt::format("dielectric index of refraction {} must be finite and > 0", b.ior);
  if (!inUnitRange(b.transmittance))
    return fmt::format("dielectric transmittance {} outside [0, 1]", str(b.transmittance));
  if (!(b.alpha >= 0.0f && b.alpha <= 1.0f))
    return fmt::format("dielectric roughness alpha {} must lie in [0, 1]", b.alpha);
  if (!isFinite(b.absorption) || glm::any(glm::lessThan(b.absorption, Rgb(0.0f))))
    return fmt::format("dielectric absorption {} must be finite and >= 0", str(b.absorption));
  return {};
}

std::string problemOf(const GltfPbrBsdf& b) {
  if (!inUnitRange(b.diffuse) || !inUnitRange(b.f0) || !inUnitRange(b.sheenColor))
    return fmt::format("glTF PBR diffuse {}, f0 {} and sheen colour {} must lie in [0, 1]", str(b.diffuse), str(b.f0),
                       str(b.sheenColor));
  if (!(b.f90 >= 0.0f && b.f90 <= 1.0f) || !(b.clearcoat >= 0.0f && b.clearcoat <= 1.0f) ||
      !(b.sheenRoughness >= 0.0f && b.sheenRoughness <= 1.0f))
    return fmt::format("glTF PBR f90 {}, clearcoat {} and sheen roughness {} must lie in [0, 1]", b.f90, b.clearcoat,
                       b.sheenRoughness);
  if (!(b.alpha > 0.0f && b.alpha <= 1.0f) || !(b.clearcoatAlpha > 0.0f && b.clearcoatAlpha <= 1.0f))
    return fmt::format("glTF PBR alpha {} and clearcoat alpha {} must lie in (0, 1]", b.alpha, b.clearcoatAlpha);
  if (!inUnitRange(b.dielectricF0) || !(b.dielectricF90 >= 0.0f && b.dielectricF90 <= 1.0f))
    return fmt::format("glTF PBR dielectric f0 {} and f90 {} must lie in [0, 1]", str(b.dielectricF0), b.dielectricF90);
  // The energy bound of the diffuse's coupling (bsdf.cpp): f0 ≤ 1 − ρ (1 − dielectric f0),
  // f90 ≤ 1 − ρ (1 − dielectric f90) per channel.
  for (int c = 0; c < 3; ++c)
    if (b.f0[c] > 1.0f - b.diffuse[c] * (1.0f - b.dielectricF0[c]) + kSumSlack ||
        b.f90 > 1.0f - b.diffuse[c] * (1.0f - b.dielectricF90) + kSumSlack)
      return fmt::format("glTF PBR f0 {} and f90 {} exceed what the diffuse {} under the dielectric f0 {} and f90 {} "
                         "leaves (f0 <= 1 - diffuse (1 - dielectric f0), likewise f90)",
                         str(b.f0), b.f90, str(b.diffuse), str(b.dielectricF0), b.dielectricF90);
  return {};
}

std::string problemOf(const SubsurfaceBsdf& b) {
  // A = 1 would make α = 1 − e^−6.8 and is not the white limit the user means; the fit is for
  // A < 1 (Chiang et al. 2016), and A ≥ 1 would ask a slab to reflect all it receives.
  if (!(inUnitRange(b.albedo) && maxComponent(b.albedo) < 1.0f))
    return fmt::format("subsurface albedo {} outside [0, 1)", str(b.albedo));
  if (!isFinite(b.radius) || !glm::all(glm::greaterThan(b.radius, Rgb(0.0f))))
    return fmt::format("subsurface radius {} must be finite and > 0 in every channel", str(b.radius));
  return {};
}

template <size_t... I>
std::optional<Bsdf> bsdfOfIndexImpl(size_t index, std::index_sequence<I...>) {
  std::optional<Bsdf> result;
  ((index == I ? (result.emplace(std::in_place_index<I>), true) : false) || ...);
  return result;
}

}  // namespace

std::optional<Bsdf> bsdfOfIndex(size_t index) {
  return bsdfOfIndexImpl(index, std::make_index_sequence<std::variant_size_v<Bsdf>>{});
}

LobeDescriptor describe(const Bsdf& bsdf) {
  return std::visit(
      [](const auto& b) {
        return LobeDescriptor{kindOf(b), transmitsOf(b), halfWidthOf(b), diffuseOf(b)};
      },
      bsdf);
}

float lobeHalfWidth(const Bsdf& bsdf) {
  return std::visit([](const auto& b) { return halfWidthOf(b); }, bsdf);
}

Rgb diffuseAlbedo(const Bsdf& bsdf) {
  return std::visit([](const auto& b) { return diffuseOf(b); }, bsdf);
}

Rgb interiorAbsorption(const Bsdf& bsdf) {
  const auto* glass = std::get_if<DielectricBsdf>(&bsdf);
  return glass ? glass->absorption : Rgb(0.0f);
}

SubsurfaceMedium subsurfaceMedium(const SubsurfaceBsdf& b) {
  SubsurfaceMedium m;
  for (int c = 0; c < 3; ++c) {
    const float a = b.albedo[c];
    m.alpha[c] = 1.0f - std::exp(a * (-5.09406f + a * (2.61188f - a * 4.31805f)));
    const float s = 1.9f - a + 3.5f * (a - 0.8f) * (a - 0.8f);
    m.sigmaT[c] = 1.0f / (b.radius[c] * s);
  }
  return m;
}

std::optional<SubsurfaceMedium> subsurfaceMedium(const Bsdf& bsdf) {
  const auto* sss = std::get_if<SubsurfaceBsdf>(&bsdf);
  return sss ? std::optional<SubsurfaceMedium>(subsurfaceMedium(*sss)) : std::nullopt;
}

std::string bsdfProblem(const Bsdf& bsdf) {
  return std::visit([](const auto& b) { return problemOf(b); }, bsdf);
}

bool isDelta(const Bsdf& bsdf) {
  return std::visit([](const auto& b) { return kindOf(b) == LobeKind::Delta; }, bsdf);
}

bool hasTransmission(const Bsdf& bsdf) {
  return std::visit([](const auto& b) { return transmitsOf(b); }, bsdf);
}

bool isDiffuse(const Bsdf& bsdf) {
  return std::visit([](const auto& b) { return kindOf(b) == LobeKind::Diffuse; }, bsdf);
}

// ---- Parameter conversions ----------------------------------------------------------------

float ggxAlphaFromRoughness(float roughness) {
  return std::max(alphaFromRoughness(std::clamp(roughness, 0.0f, 1.0f)), kGgxMinAlpha);
}

float dielectricAlphaFromRoughness(float roughness) {
  const float alpha = alphaFromRoughness(std::clamp(roughness, 0.0f, 1.0f));
  return alpha < kGgxMinAlpha ? 0.0f : alpha;
}

float blinnPhongExponentFromAlpha(float alpha) { return std::max(0.0f, 2.0f / (alpha * alpha) - 2.0f); }

float alphaFromBlinnPhongExponent(float exponent) { return std::sqrt(2.0f / (std::max(exponent, 0.0f) + 2.0f)); }

Bsdf gltfMetallicRoughnessModel(const Rgb& baseColor, float metallic, float roughness) {
  metallic = std::clamp(metallic, 0.0f, 1.0f);
  if (metallic > 0.0f && metallic < 1.0f)
    return gltfPbrFromInputs({.baseColor = baseColor, .metallic = metallic, .roughness = roughness});
  GgxBsdf b;
  b.f0 = glm::mix(Rgb(0.04f), baseColor, metallic);
  b.diffuse = baseColor * (1.0f - metallic);
  b.alpha = ggxAlphaFromRoughness(roughness);
  return b;
}

GltfPbrBsdf gltfPbrFromInputs(const GltfPbrInputs& in) {
  const float metallic = std::clamp(in.metallic, 0.0f, 1.0f), specular = std::clamp(in.specular, 0.0f, 1.0f);
  const Rgb base = glm::clamp(in.baseColor, 0.0f, 1.0f);
  const float ior = std::isfinite(in.ior) ? std::max(in.ior, 1.0f) : 1.5f;
  const float r = (ior - 1.0f) / (ior + 1.0f);
  const Rgb dielectricF0 = glm::min(Rgb(r * r) * glm::max(in.specularColor, Rgb(0.0f)), Rgb(1.0f)) * specular;
  GltfPbrBsdf b;
  b.f0 = glm::mix(dielectricF0, base, metallic);
  b.f90 = specular + (1.0f - specular) * metallic;
  b.dielectricF0 = dielectricF0;
  b.dielectricF90 = specular;
  b.diffuse = base * (1.0f - metallic);
  b.alpha = ggxAlphaFromRoughness(in.roughness);
  b.clearcoat = std::clamp(in.clearcoat, 0.0f, 1.0f);
  b.clearcoatAlpha = ggxAlphaFromRoughness(in.clearcoatRoughness);
  b.sheenColor = glm::clamp(in.sheenColor, 0.0f, 1.0f);
  b.sheenRoughness = std::clamp(in.sheenRoughness, 0.0f, 1.0f);
  return b;
}

}  // namespace pl
