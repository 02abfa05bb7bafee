#pragma once
// Environment maps: radiance arriving from infinitely far away, stored as a lat-long
// (equirectangular) image or a cubemap, and the per-ray environment light built on them.
//
// Units: every texel holds radiance L (W·sr⁻¹·m⁻², linear Rec.709 RGB). Solid angles are in
// steradians and are EXACT (not the usual cos³ approximation); they sum to 4π.
//
// ─── World directions ────────────────────────────────────────────────────────────────────
// Right-handed world, +y up (core/math.h). A direction is a unit vector pointing from the
// scene towards the environment (the way one looks to see that radiance).
//
// ─── Lat-long (equirectangular) layout, W × H with W = 2H ────────────────────────────────
//   u = (x + ½)/W, v = (y + ½)/H  (row 0 at the top, image.h)
//   θ = π·v  (polar angle from +y: top row looks up, bottom row looks down)
//   φ = 2π·(u − ½)  (azimuth, φ = atan2(z, x))
//   dir = (sin θ cos φ, cos θ, sin θ sin φ)
// So the image centre looks along +x and the image's right half covers +z: seen from inside
// the sphere the image is not mirrored. This is also three.js's equirectangular convention,
// so lat-long maps and the cube faces below agree with what three.js shows.
//
//     u=0        u=¼        u=½        u=¾        u=1
//     ┌──────────┬──────────┬──────────┬──────────┐ v=0   (+y, zenith)
//     │   −x     │   −z     │   +x     │   +z     │ v=½   (horizon)
//     └──────────┴──────────┴──────────┴──────────┘ v=1   (−y, nadir)
//
// Texel solid angle (exact): ΔΩ = Δφ·(cos θ0 − cos θ1) with Δφ = 2π/W, θ0 = π·y/H,
// θ1 = π·(y+1)/H.
//
// ─── Cubemap layout: six N × N faces, OpenGL cube-map convention ───────────────────────────
// Faces are stored and named exactly as OpenGL's GL_TEXTURE_CUBE_MAP_{POSITIVE,NEGATIVE}_{X,Y,Z}
// faces with the image's top row uploaded first (t = 0), i.e. as three.js's CubeTextureLoader
// uploads px, nx, py, ny, pz, nz; DirectX uses the same face images. For a *cube* direction
// c, the face is the major axis of c and (sc, tc) ∈ [−1,1]² with s rightwards, t downwards
// in the face image (OpenGL 4.6 table 8.19):
//
//     face  file  major   sc     tc         face  file  major   sc     tc
//     +X    px    +cx     −cz    −cy        −X    nx    −cx     +cz    −cy
//     +Y    py    +cy     +cx    +cz        −Y    ny    −cy     +cx    −cz
//     +Z    pz    +cz     +cx    −cy        −Z    nz    −cz     −cx    −cy
//
// The OpenGL table describes a left-handed cube (seen from outside). Our world is
// right-handed, so world direction d looks up cube direction c = (−d.x, d.y, d.z) — the same
// x flip three.js applies to every cube texture (its `flipEnvMap = −1`). Consequence: files
// named for three.js or OpenGL load unmodified and show the same picture as in three.js,
// unmirrored from inside; the face *files* px/nx hold the world −x/+x directions.
//
// Cross layouts (faces unmodified, as seen from outside the unfolded cube):
//
//   horizontal cross, 4N × 3N            vertical cross, 3N × 4N
//        +----+                                +----+
//        | +Y |                                | +Y |
//   +----+----+----+----+                 +----+----+----+
//   | -X | +Z | +X | -Z |                 | -X | +Z | +X |
//   +----+----+----+----+                 +----+----+----+
//        | -Y |                                | -Y |
//        +----+                                +----+
//                                              | -Z |  (rotated 180°)
//                                              +----+
// Unused cross cells are written black and ignored on reading.
//
// Cube texel solid angle (exact): a texel [x0,x1]×[y0,y1] of a face at distance 1 projects
// to a spherical quadrilateral of area A(x1,y1) − A(x0,y1) − A(x1,y0) + A(x0,y0) with
// A(x,y) = atan2(x·y, √(x²+y²+1)) (the integral of (1+x²+y²)^(−3/2) dx dy; "AreaElement").
//
// ─── Files ───────────────────────────────────────────────────────────────────────────────
// loadEnvironment(IN) accepts
//   * an image file (.hdr, .exr, .pfm, .png) whose aspect ratio says its layout:
//     2:1 lat-long, 4:3 horizontal cross, 3:4 vertical cross (anything else is refused);
//   * a directory holding px, nx, py, ny, pz, nz with one of the image extensions;
//   * a pattern containing "{face}", e.g. "sky/{face}.exr", replaced by px … nz.
// saveEnvironment(OUT, map, layout) writes lat-long or cross layouts to the file OUT, and
// the cube layout to the six files of the pattern OUT (if it contains "{face}") or to
// OUT/{face}.hdr when OUT is a directory name (created if needed).
#include "core/math.h"
#include "core/sampling.h"
#include "image/image.h"

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace pl {

// ─── Lat-long ──────────────────────────────────────────────────────────────────────────────

struct LatLongMap {
  Image image;  ///< W × H, W = 2H

  int width() const { return image.width; }
  int height() const { return image.height; }
  /// Bilinear radiance lookup (wraps in φ, clamps in θ).
  Rgb lookup(const Vec3& dir) const;
  /// Direction at image coordinates (u, v) ∈ [0,1]².
  static Vec3 direction(double u, double v);
  static DVec3 directionD(double u, double v);
  /// (u, v) ∈ [0,1)×[0,1] of a unit direction.
  static Vec2 uv(const Vec3& dir);
  /// Exact solid angle of any texel of row y (all texels of a row are equal).
  double texelSolidAngle(int y) const;
};

// ─── Cubemap ───────────────────────────────────────────────────────────────────────────────

enum class CubeFace : int { PosX = 0, NegX = 1, PosY = 2, NegY = 3, PosZ = 4, NegZ = 5 };
/// "px", "nx", "py", "ny", "pz", "nz" (file names of the faces, index = CubeFace).
inline constexpr std::array<const char*, 6> kCubeFaceNames = {"px", "nx", "py", "ny", "pz", "nz"};

/// Face coordinates of a world direction: face index, s and t in [0,1] (s right, t down).
struct CubeCoords {
  int face = 0;
  double s = 0.5, t = 0.5;
};

struct CubeMap {
  int size = 0;                ///< N, the edge length of every face in texels
  std::array<Image, 6> faces;  ///< indexed by CubeFace

  explicit CubeMap(int n = 0);
  /// Bilinear radiance lookup; texels past a face edge are fetched from the adjacent face,
  /// so filtering is seamless.
  Rgb lookup(const Vec3& dir) const;
  /// Radiance of texel (x, y) of `face`; x or y may lie up to one texel outside the face,
  /// in which case the texel of the neighbouring face in that direction is returned.
  Rgb fetch(int face, int x, int y) const;
  /// Unit world direction through (sc, tc) ∈ [−1,1]² of a face (table above).
  static DVec3 direction(int face, double sc, double tc);
  static CubeCoords coords(const DVec3& worldDir);
  /// Exact solid angle of texel (x, y) of an N × N face (the same on every face).
  static double texelSolidAngle(int n, int x, int y);
  double texelSolidAngle(int x, int y) const { return texelSolidAngle(size, x, y); }
};

/// Either layout. Everything in env/ accepts both.
using EnvImage = std::variant<LatLongMap, CubeMap>;

/// Bilinear radiance lookup in either layout.
Rgb lookup(const EnvImage& env, const Vec3& dir);
/// Short description, e.g. "lat-long 1024×512" or "cube 6×256²".
std::string describe(const EnvImage& env);

/// Number of texels and, for each texel, its centre direction, radiance and exact solid
/// angle: the discretisation every integral over the sphere in env/ uses.
struct SphereTexels {
  std::vector<DVec3> direction;
  std::vector<Rgb> radiance;
  std::vector<double> solidAngle;
  size_t size() const { return direction.size(); }
};
SphereTexels sphereTexels(const EnvImage& env);

// ─── Layout conversion ─────────────────────────────────────────────────────────────────────

/// Resamples to a lat-long map of the given height (width = 2·height). Each target texel is
/// the solid-angle-weighted mean of k×k bilinear lookups, k chosen from the ratio of source
/// to target angular resolution (so downsampling averages instead of aliasing).
LatLongMap toLatLong(const EnvImage& env, int height);
/// Resamples to a cubemap with faces of `faceSize` texels (same filtering as toLatLong).
CubeMap toCube(const EnvImage& env, int faceSize);
/// Lat-long downsampled by an integer factor with exact solid-angle weights (radiant
/// power is preserved exactly). Height must be divisible by factor.
LatLongMap downsampleLatLong(const LatLongMap& map, int factor);
/// A natural size for converting between layouts: lat-long height H ↔ face size H/2 (the
/// same angular resolution at the face centres).
int equivalentLatLongHeight(const EnvImage& env);
int equivalentFaceSize(const EnvImage& env);

/// Fills a map of the given layout and size (lat-long height or face size) with fn(dir)
/// evaluated at every texel centre (unit world direction), in parallel.
EnvImage makeEnvImage(bool cube, int size, const std::function<Rgb(const Vec3&)>& fn);

// ─── Files ─────────────────────────────────────────────────────────────────────────────────

enum class EnvLayout { LatLong, Cube, HorizontalCross, VerticalCross };
/// "latlong", "cube", "cross" (horizontal), "vcross"; throws pl::Error otherwise.
EnvLayout parseEnvLayout(const std::string& name);

EnvImage loadEnvironment(const std::string& path);
void saveEnvironment(const std::string& path, const EnvImage& env, EnvLayout layout);
/// Cross layouts to and from images (exposed for tests).
Image cubeToCross(const CubeMap& cube, bool vertical);
CubeMap crossToCube(const Image& image, const std::string& nameForErrors);

// ─── Environment light (per ray) ───────────────────────────────────────────────────────────

/// A direction sampled from the environment: radiance (already scaled) and the solid-angle
/// density of having chosen it. pdf == 0 means the sample is invalid (skip it).
struct EnvironmentSample {
  Vec3 direction{0.0f, 1.0f, 0.0f};
  Rgb radiance{0.0f};
  float pdf = 0.0f;
};

/// The environment as a light: a lat-long radiance map (any input is converted to it),
/// multiplied by `scale` and rotated by `rotationDegrees` about +y (positive = counter-
/// clockwise seen from above: the map's +x turns towards −z). Immutable and thread-safe;
/// radiance(), sample() and pdf() do no allocation.
///
/// Importance sampling: a piecewise-constant density over the lat-long texels, texel weight
/// = (solid-angle-weighted mean of the bilinearly reconstructed luminance over the texel)
/// × (texel solid angle), i.e. the texel's share of luminous power. Because the weight is the
/// mean of the *bilinear* reconstruction (separable 1/8, 3/4, 1/8 filter), every direction
/// where radiance() is non-zero has pdf() > 0, so estimators stay unbiased. In (u, v) the
/// density is constant per texel; per solid angle it is p(u,v) / (2π² sin θ).
class EnvironmentMap {
 public:
  explicit EnvironmentMap(LatLongMap map, float scale = 1.0f, float rotationDegrees = 0.0f);

  /// Radiance arriving from unit world direction `dir` (bilinear, scaled, rotated).
  Rgb radiance(const Vec3& dir) const;
  /// Samples a direction for u ∈ [0,1)²: pdf(result.direction) == result.pdf.
  EnvironmentSample sample(Vec2 u) const;
  /// Solid-angle density of sample() returning unit world direction `dir`.
  float pdf(const Vec3& dir) const;

  const LatLongMap& map() const { return map_; }
  float scale() const { return scale_; }
  float rotationDegrees() const { return rotationDegrees_; }
  /// Total luminous "power" ∫ Y(L) dΩ of the scaled map (W·m⁻² of luminance), for choosing
  /// between lights.
  double integratedLuminance() const { return integratedLuminance_; }

  /// World ↔ map direction (the rotation only).
  Vec3 toMap(const Vec3& worldDir) const;
  Vec3 toWorld(const Vec3& mapDir) const;

 private:
  LatLongMap map_;
  float scale_ = 1.0f;
  float rotationDegrees_ = 0.0f;
  float cosRot_ = 1.0f, sinRot_ = 0.0f;
  Distribution1D rows_;                  ///< marginal over rows (v)
  std::vector<Distribution1D> columns_;  ///< per row, conditional over columns (u)
  double integratedLuminance_ = 0.0;
};

// The environment as one light (constant + map, sampled as a mixture) is light/emitters.h
// EnvironmentLight.

/// Loads any environment file (see loadEnvironment) as a light. A cube input is converted
/// to lat-long at the equivalent resolution.
std::shared_ptr<const EnvironmentMap> loadEnvironmentMap(const std::string& path, float scale = 1.0f,
                                                         float rotationDegrees = 0.0f);

}  // namespace pl
