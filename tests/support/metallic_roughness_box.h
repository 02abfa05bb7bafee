#pragma once
// Test support (header-only; include as "support/metallic_roughness_box.h"): the built-in
// Cornell box with its white material a glTF-style GGX whose metallicRoughnessTexture is a
// ramp along x (scene.h MetallicRoughnessMap), for the path tracer's, the light field's and the
// GPU renderer's tests of per-point metalness and roughness.
#include <variant>

#include "bsdf/bsdf.h"
#include "scene/scene.h"

namespace pl::test_support {

constexpr int kRampTexels = 8;
constexpr float kBoxWidth = 556.0f;  // the Cornell box spans x ∈ [0, 556] mm

/// Texel x of the ramp: raw (ImageDecode::Data) G = roughness 0.3 … 1, B = metalness 0 … 0.5.
inline Rgb rampTexel(int x) { return Rgb(0.0f, 0.3f + 0.1f * float(x), 0.5f * float(x) / float(kRampTexels - 1)); }
/// A metalness ramp alone: roughness 0.5, metalness 0 … 1.
inline Rgb metalRampTexel(int x) { return Rgb(0.0f, 0.5f, float(x) / float(kRampTexels - 1)); }
/// A roughness ramp alone on a metal: roughness 0.45 … 1, metalness 1.
inline Rgb roughnessRampTexel(int x) { return Rgb(0.0f, 0.45f + 0.55f * float(x) / float(kRampTexels - 1), 1.0f); }

/// The box with `white` a glTF material of base colour `base`: with the ramp texture of
/// `texelOf` (nearest filter, u = x / 556 on every mesh) when `texel` < 0, else uniform at that
/// texel's values.
inline Scene rampBox(int texel, Rgb (*texelOf)(int) = rampTexel, Rgb base = Rgb(0.8f)) {
  Scene scene = makeCornellBox();
  for (Mesh& mesh : scene.meshes) {
    mesh.uvs.clear();
    for (const Vec3& p : mesh.positions) mesh.uvs.push_back(Vec2(p.x / kBoxWidth, 0.5f));
  }
  Texture ramp;
  ramp.path = "ramp";
  ramp.decode = ImageDecode::Data;
  ramp.image = Image(kRampTexels, 1);
  for (int x = 0; x < kRampTexels; ++x) ramp.image.at(x, 0) = texelOf(x);
  ramp.sampling.nearest = true;
  ramp.sampling.wrapU = TextureWrap::ClampToEdge;
  scene.textures.push_back(ramp);
  for (Material& m : scene.materials) {
    if (m.name != "white") continue;
    if (texel >= 0) {
      m.bsdf = gltfMetallicRoughnessModel(base, texelOf(texel).b, texelOf(texel).g);
      continue;
    }
    m.metallicRoughness = {int(scene.textures.size()) - 1, TextureMapping{}, base, 1.0f, 1.0f};
    // The texture's mean lobe, as the glTF loader sets it: the model of the mean metalness
    // with the mean α.
    float metalness = 0.0f, alpha = 0.0f;
    for (int x = 0; x < kRampTexels; ++x) {
      metalness += texelOf(x).b / float(kRampTexels);
      alpha += ggxAlphaFromRoughness(texelOf(x).g) / float(kRampTexels);
    }
    m.bsdf = gltfMetallicRoughnessModel(base, metalness, 1.0f);  // GgxBsdf at metalness 0 or 1
    std::visit([&](auto& b) {
      if constexpr (requires { b.alpha; }) b.alpha = alpha;
    }, m.bsdf);
  }
  scene.finalize();
  return scene;
}

}  // namespace pl::test_support
