#pragma once
// Paraboloid maps of a hemisphere (seed slides 16–17): the (s, t) parameterisation declared in
// lightfield.h, and the discrete dirRes × dirRes texel grid laid over [−1, 1]².
//
// Texel (a, b) of an R × R map covers s ∈ [−1 + 2a/R, −1 + 2(a+1)/R] and likewise t with b.
// Its centre direction is paraboloidToDirection of the texel centre; for texels whose centre
// lies outside the unit disk (the corners of the square) it is the direction of the nearest
// point of the disk, pulled just above the horizon (see kHorizonRadius), so that these texels
// hold "the value of the nearest horizon direction" and bilinear interpolation near the
// horizon never reads garbage.
//
// Solid angle: the map's Jacobian is dω = 4 / (1 + s² + t²)² ds dt (radially symmetric;
// integrating it over the unit disk gives 4π·∫₀¹ du/(1+u)² = 2π). A texel's solid angle is the
// integral over the part of the texel inside the disk.
#include "core/math.h"
#include "lightfield/lightfield.h"

#include <cstdint>
#include <vector>

namespace pl {

/// Centres of texels outside the disk are projected to this radius: cos θ there is
/// (1 − r²)/(1 + r²) ≈ 5e-4, i.e. 0.03° above the horizon, where BSDFs are still defined.
inline constexpr float kHorizonRadius = 0.9995f;

/// Continuous texel coordinate of paraboloid coordinate x ∈ [−1, 1] in an R-texel map:
/// texel centres sit at integers 0 … R−1.
inline float paraboloidTexelCoordinate(float x, uint32_t resolution) {
  return (x + 1.0f) * 0.5f * float(resolution) - 0.5f;
}

/// (s, t) of the centre of texel (a, b).
Vec2 paraboloidTexelCentre(uint32_t a, uint32_t b, uint32_t resolution);

/// Local direction represented by texel (a, b) (see the header comment for corner texels).
Vec3 paraboloidTexelDirection(uint32_t a, uint32_t b, uint32_t resolution);

/// Solid angle (sr) of the part of texel (a, b) inside the unit disk, computed by integrating
/// the Jacobian in closed form along t and with composite Gauss–Legendre quadrature along s
/// (relative error < 1e-6). Sums to 2π over all texels.
double paraboloidTexelSolidAngle(uint32_t a, uint32_t b, uint32_t resolution);

/// Solid angles of all R² texels, index a + b·R (cached per resolution; thread-safe).
const std::vector<float>& paraboloidTexelSolidAngles(uint32_t resolution);

}  // namespace pl
