// Mirror-like glossy lobes on the GPU (gpu_mirror_like.h).
#include "gpu/gpu_mirror_like.h"

#include <variant>

#include "bsdf/bsdf.h"
#include "lightfield/lookup.h"

namespace pl {

bool hasMirrorLikeCharts(const LightField& lf) {
  for (const Chart& c : lf.charts)
    if (isMirrorLikeRecord(c, lf.scene.materials[c.material].bsdf)) return true;
  return false;
}

std::string gpuUnsupportedMirrorLike(const LightField& lf) {
  for (const Chart& c : lf.charts) {
    const Material& material = lf.scene.materials[c.material];
    const Bsdf& model = material.bsdf;
    if (!isMirrorLikeRecord(c, model)) continue;
    if (!std::holds_alternative<BlinnPhongBsdf>(model) && !std::holds_alternative<GgxBsdf>(model))
      return "mirror-like glTF PBR lobes";
    // The lobe is sampled from the material's model record, not each point's (materialModelAt).
    if (material.metallicRoughness.texture >= 0) return "mirror-like lobes with a metallic-roughness texture";
  }
  return {};
}

// sample() and pdf() of bsdf.cpp for Blinn-Phong and GGX without a diffuse part —
// sampleBlinnPhongDirection, sampleGgxDirection with sampleGgxVisibleNormal, reflectAbout,
// finishSample, pdfBlinnPhong with blinnLobePdf, pdfGgx with ggxLobePdf — statement for
// statement, the lobe chosen with probability 1 (chooseFirst(1, u.x) keeps u.x).
const char* const kMirrorLikeGlsl = R"glsl(
GgxLobe mirrorLikeGgx(HighlightModel m) {
  return GgxLobe(m.diffuse.rgb, m.lobe.w, m.lobe.rgb, m.extra.x, m.diffuseF0.rgb, m.extra.y);
}
float mirrorLikeLobePdf(HighlightModel m, vec3 wo, vec3 wi) {
  if (!(wo.z > 0.0 && wi.z > 0.0)) return 0.0;
  vec3 h = normalize(wo + wi);
  float woh = dot(wo, h);
  if (floatBitsToUint(m.diffuse.w) == kHighlightBlinnPhong) {
    float n = m.lobe.w;
    if (woh <= 0.0 || h.z <= 0.0) return 0.0;
    return (n + 1.0) / (2.0 * 3.14159265358979) * pow(h.z, n) / (4.0 * woh);
  }
  float alpha = m.lobe.w;
  if (woh <= 0.0) return 0.0;
  return ggxD(alpha, h) / ((1.0 + ggxLambda(alpha, wo)) * 4.0 * wo.z);
}
vec3 sampleGgxVisibleNormal(float alpha, vec3 wo, vec2 u) {
  vec3 vh = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
  float lensq = vh.x * vh.x + vh.y * vh.y;
  vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) / sqrt(lensq) : vec3(1.0, 0.0, 0.0);
  vec3 t2 = cross(vh, t1);
  float r = sqrt(u.x);
  float phi = 2.0 * 3.14159265358979 * u.y;
  float p1 = r * cos(phi);
  float p2 = r * sin(phi);
  float s = 0.5 * (1.0 + vh.z);
  p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
  vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
  return normalize(vec3(alpha * nh.x, alpha * nh.y, max(1e-6, nh.z)));
}
bool sampleMirrorLikeLobe(HighlightModel m, vec3 wo, vec2 u, out vec3 wi, out vec3 weight, out float pdf) {
  wi = vec3(0.0);
  weight = vec3(0.0);
  pdf = 0.0;
  uint kind = floatBitsToUint(m.diffuse.w);
  if (!(wo.z > 0.0) || (kind != kHighlightBlinnPhong && kind != kHighlightGgx)) return false;
  vec3 h;
  if (kind == kHighlightBlinnPhong) {
    // sampleBlinnPhongDirection: nothing to sample without a specular part either.
    if (!(luminanceOf(m.lobe.rgb) > 0.0)) return false;
    float n = m.lobe.w;
    float cosH = pow(u.x, 1.0 / (n + 1.0));
    float sinH = sqrt(max(0.0, 1.0 - cosH * cosH));
    float phi = 2.0 * 3.14159265358979 * u.y;
    h = vec3(sinH * cos(phi), sinH * sin(phi), cosH);
  } else {
    h = sampleGgxVisibleNormal(m.lobe.w, wo, u);
  }
  vec3 w = 2.0 * dot(wo, h) * h - wo;
  // finishSample
  if (w.z <= 0.0 || any(isinf(w)) || any(isnan(w))) return false;
  wi = normalize(w);
  pdf = mirrorLikeLobePdf(m, wo, wi);
  if (!(pdf > 0.0)) return false;
  // No clear coat or sheen: mirror-like glTF PBR lobes are refused.
  const PbrLayers noLayers = PbrLayers(0.0, 0.0, vec3(0.0), 0.0, vec3(0.0));
  weight = evalHighlightModel(m, mirrorLikeGgx(m), noLayers, false, wo, wi) * (wi.z / pdf);
  return true;
}
)glsl";

}  // namespace pl
