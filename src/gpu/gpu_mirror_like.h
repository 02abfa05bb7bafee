#pragma once
// Mirror-like glossy lobes on the GPU (specular chart records of a Blinn-Phong or GGX model,
// lookup.h isMirrorLikeRecord): the lobe's importance sampling and density in GLSL, the first
// part of following them as the CPU renderers do (followSpecular's lobe step).
//
// A mirror-like model has no diffuse part (bake/parameterisation.h isMirrorLike), so bsdf.cpp's
// sample() chooses its lobe with probability 1 and its pdf() is the lobe's density alone:
//   Blinn-Phong  h with cos θh = u.x^(1/(n+1)), φ = 2π·u.y, wi = reflect(wo, h);
//                p(wi) = (n + 1)/(2π) · cos^n θh / (4 wo·h)                (blinnLobePdf)
//   GGX          h from the visible normals (Heitz 2018, sampleGgxVisibleNormal), wi = reflect;
//                p(wi) = G1(wo) D(h) / (4 cos θo)                          (ggxLobePdf)
// and the sample's weight is f·cos θi/p with f the model's eval (finishSample). The models are
// read from the highlights' records (gpu_highlights.h HighlightModelGpu: Blinn-Phong's
// exponent and normalisation, GGX's clamped α and f0). glTF PBR models, whose sample() picks
// between their lobes, are not sampled here (gpuUnsupportedMirrorLike names them).
#include <string>

#include "lightfield/lightfield.h"

namespace pl {

/// Whether `lf` has mirror-like chart records (lookup.h isMirrorLikeRecord).
bool hasMirrorLikeCharts(const LightField& lf);

/// The first mirror-like chart's model of `lf` that kMirrorLikeGlsl does not sample (glTF PBR,
/// or one a metallic-roughness texture makes per point), as a phrase; empty if none.
std::string gpuUnsupportedMirrorLike(const LightField& lf);

/// GLSL, in the local frame of the shading normal (z up):
///   float mirrorLikeLobePdf(HighlightModel m, vec3 wo, vec3 wi) — pdf(bsdf, wo, wi);
///   bool sampleMirrorLikeLobe(HighlightModel m, vec3 wo, vec2 u, out vec3 wi, out vec3 weight,
///     out float pdf) — sample(bsdf, wo, u): false where it returns nothing.
/// Needs kSurfaceGlsl (luminanceOf) and kHighlightsGlsl (HighlightModel, evalHighlightModel,
/// ggxD, ggxLambda) before it.
extern const char* const kMirrorLikeGlsl;

}  // namespace pl
