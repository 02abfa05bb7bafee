#pragma once
// Four float lanes (r, g, b and an unused fourth) for RGB arithmetic: SSE where the target has
// it (every x86-64), else a plain array. Both do the same IEEE single-precision operations in
// the same order per lane — and the same as glm's per-component Rgb arithmetic written in the
// same order — so results agree to the bit whichever is used (no fused multiply-add: the
// operations are separate intrinsics or separate expressions).
#include "core/math.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace pl {

#if defined(__SSE2__)
using F4 = __m128;
inline F4 f4Zero() { return _mm_setzero_ps(); }
inline F4 f4Splat(float s) { return _mm_set1_ps(s); }
inline F4 f4Load(const float* aligned) { return _mm_load_ps(aligned); }
inline F4 f4Add(F4 a, F4 b) { return _mm_add_ps(a, b); }
inline F4 f4Mul(F4 a, F4 b) { return _mm_mul_ps(a, b); }
inline F4 f4Sub(F4 a, F4 b) { return _mm_sub_ps(a, b); }
/// glm::max(a, b) lane-wise: (a < b) ? b : a (so a NaN in a is kept, as glm does).
inline F4 f4Max(F4 a, F4 b) { return _mm_max_ps(b, a); }
inline F4 f4FromRgb(const Rgb& c) { return _mm_setr_ps(c.r, c.g, c.b, 0.0f); }
inline Rgb f4Rgb(F4 a) {
  alignas(16) float v[4];
  _mm_store_ps(v, a);
  return {v[0], v[1], v[2]};
}
#else
struct F4 {
  float v[4];
};
inline F4 f4Zero() { return {{0.0f, 0.0f, 0.0f, 0.0f}}; }
inline F4 f4Splat(float s) { return {{s, s, s, s}}; }
inline F4 f4Load(const float* aligned) { return {{aligned[0], aligned[1], aligned[2], aligned[3]}}; }
inline F4 f4Add(F4 a, F4 b) { return {{a.v[0] + b.v[0], a.v[1] + b.v[1], a.v[2] + b.v[2], a.v[3] + b.v[3]}}; }
inline F4 f4Mul(F4 a, F4 b) { return {{a.v[0] * b.v[0], a.v[1] * b.v[1], a.v[2] * b.v[2], a.v[3] * b.v[3]}}; }
inline F4 f4Sub(F4 a, F4 b) { return {{a.v[0] - b.v[0], a.v[1] - b.v[1], a.v[2] - b.v[2], a.v[3] - b.v[3]}}; }
inline F4 f4Max(F4 a, F4 b) {
  F4 m;
  for (int k = 0; k < 4; ++k) m.v[k] = a.v[k] < b.v[k] ? b.v[k] : a.v[k];
  return m;
}
inline F4 f4FromRgb(const Rgb& c) { return {{c.r, c.g, c.b, 0.0f}}; }
inline Rgb f4Rgb(F4 a) { return {a.v[0], a.v[1], a.v[2]}; }
#endif

/// Stores lanes r, g, b of a into *destination (12 bytes; the fourth lane is not written).
inline void f4StoreRgb(Rgb* destination, F4 a) {
#if defined(__SSE2__)
  static_assert(sizeof(Rgb) == 12);
  _mm_storel_pi(reinterpret_cast<__m64*>(&destination->r), a);
  _mm_store_ss(&destination->b, _mm_movehl_ps(a, a));
#else
  *destination = f4Rgb(a);
#endif
}

/// Storage for an F4 (lanes r, g, b, 0), aligned for f4Load: 16 bytes per RGB value.
struct alignas(16) Lanes4 {
  float v[4] = {0.0f, 0.0f, 0.0f, 0.0f};
};
inline Lanes4 lanes4(F4 a) {
  Lanes4 l;
#if defined(__SSE2__)
  _mm_store_ps(l.v, a);
#else
  l = Lanes4{{a.v[0], a.v[1], a.v[2], a.v[3]}};
#endif
  return l;
}
inline Lanes4 lanes4(const Rgb& c) { return Lanes4{{c.r, c.g, c.b, 0.0f}}; }

}  // namespace pl
