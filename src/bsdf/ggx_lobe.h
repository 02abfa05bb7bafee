#pragma once
// What the GPU renderer (src/gpu) needs to evaluate a GGX-like model as bsdf.cpp does: the
// model's lobe parameters and the GGX and sheen lobe-albedo tables its diffuse part's k(μ)
// comes from.
// Defined in bsdf.cpp beside the tables; the shaders read them as they are (one definition).
#include <optional>
#include <vector>

#include "bsdf/bsdf.h"

namespace pl {

/// The GGX lobe behind a GGX-like model's highlights and its diffuse part's k(μ) (GgxBsdf,
/// GltfPbrBsdf): the diffuse albedo ρ, the lobe's α (clamped to [kGgxMinAlpha, 1], as eval
/// clamps it) and its Fresnel ends f0, f90, and the Fresnel ends of the lobe whose directional
/// albedo E(μ) the diffuse part gives up — GgxBsdf's own lobe (f90 = 1), a glTF model's
/// dielectric member. Without a clear coat or sheen, k(μ) = (1 − E(μ)) / √(1 − Ē) and eval =
/// ggx lobe + ρ/π · k(μo) · k(μi) exactly as bsdf.cpp evaluates it, with E from
/// ggxAlbedoTables. A glTF model's layers above: the coat's weight and α (clamped; its lobe GGX with
/// f0 = kClearcoatF0, f90 = 1; its albedo E_c the larger of the GGX table's two roughness rows
/// around α, GgxAlbedoTable::upperAlbedo), the sheen's colour and Charlie roughness r (clamped
/// to [kSheenMinRoughness, 1]; its albedo E_s and scale from sheenAlbedoTables); with either,
/// k(μ) = g(μ) · diffuseNorm, g(μ) = max(0, 1 − E(μ)) · max(0, 1 − max(sheen) E_s(μ)) ·
/// max(0, 1 − coat E_c(μ)) and diffuseNorm = 1/√Ḡ (Ḡ = 2∫ g μ dμ, bsdf.cpp pbrDiffuseNorm).
/// nullopt for other models. The GPU renderer's copy of k and of the highlights (src/gpu)
/// reads these.
struct GgxLobeParameters {
  Rgb diffuse{0.0f};
  float alpha = 0.25f;
  Rgb f0{0.04f};
  float f90 = 1.0f;
  Rgb diffuseF0{0.04f};
  float diffuseF90 = 1.0f;
  float clearcoat = 0.0f, clearcoatAlpha = 0.0625f;
  Rgb sheenColor{0.0f};
  float sheenRoughness = 1.0f;
  Rgb diffuseNorm{0.0f};  ///< with a coat or sheen; 0 elsewhere (k from the table's Ē)
  bool layered() const { return clearcoat > 0.0f || maxComponent(sheenColor) > 0.0f; }
};
/// The clear coat's Fresnel reflectance at normal incidence (ior 1.5).
inline constexpr float kClearcoatF0 = 0.04f;
std::optional<GgxLobeParameters> ggxLobeParameters(const Bsdf& bsdf);
/// The GGX lobe-albedo tables that E(μ) and Ē are interpolated from (bsdf.cpp GgxAlbedoTable):
/// E = f0 (E₀ − E₅) + f90 E₅ at μ nodes μ_i = (i/(muNodes − 1))² and roughness nodes r = √α
/// uniform on [√kGgxMinAlpha, 1], piecewise linear in μ and linear in r; Ē likewise per
/// roughness node. e0 and e5 are row-major, one row of muNodes per roughness node.
struct GgxAlbedoTables {
  int muNodes = 0, roughNodes = 0;
  std::vector<float> mu, e0, e5, mean0, mean5;
};
const GgxAlbedoTables& ggxAlbedoTables();
/// The sheen's Charlie-lobe albedo table (bsdf.cpp SheenAlbedoTable): E_s at μ nodes μ_i =
/// (i/(muNodes − 1))² and roughness nodes r uniform on [kSheenMinRoughness, 1], already
/// multiplied by its roughness node's scale 1/max(1, max_μ E_s); `e` row-major, one row of
/// muNodes per roughness node, `scale` one per roughness node. Piecewise linear in μ, linear in r.
struct SheenAlbedoTables {
  int muNodes = 0, roughNodes = 0;
  std::vector<float> mu, e, scale;
};
const SheenAlbedoTables& sheenAlbedoTables();

}  // namespace pl
