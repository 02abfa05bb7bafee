#pragma once
// What the GPU renderer (src/gpu) needs to evaluate a GGX-like model as bsdf.cpp does: the
// model's lobe parameters and the GGX lobe-albedo tables its diffuse part's k(μ) comes from.
// Defined in bsdf.cpp beside the tables; the shaders read them as they are (one definition).
#include <optional>
#include <vector>

#include "bsdf/bsdf.h"

namespace pl {

/// The GGX lobe behind a GGX-like model's highlights and its diffuse part's k(μ), for models
/// without a clear coat or sheen (GgxBsdf; GltfPbrBsdf without those layers): the diffuse albedo ρ,
/// the lobe's α (clamped to [kGgxMinAlpha, 1], as eval clamps it) and its Fresnel ends f0,
/// f90, and the Fresnel ends of the lobe whose directional albedo E(μ) the diffuse part gives
/// up, k(μ) = (1 − E(μ)) / √(1 − Ē) — GgxBsdf's own lobe (f90 = 1), a glTF model's dielectric
/// member. Then eval = ggx lobe + ρ/π · k(μo) · k(μi) exactly as bsdf.cpp evaluates it, with E
/// from ggxAlbedoTables. nullopt for other models and for glTF models with a clear coat or sheen. The GPU
/// renderer's copy of k and of the highlights (src/gpu) reads these.
struct GgxLobeParameters {
  Rgb diffuse{0.0f};
  float alpha = 0.25f;
  Rgb f0{0.04f};
  float f90 = 1.0f;
  Rgb diffuseF0{0.04f};
  float diffuseF90 = 1.0f;
};
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

}  // namespace pl
