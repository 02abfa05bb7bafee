#pragma once
// Cameras and exposure: how a pixel value follows from scene radiance.
//
// Pixel value = exposureScale · vignetting(θ) · (mean radiance arriving through the pixel's
// footprint and the lens aperture), where θ is the angle between the ray and the optical
// axis, vignetting(θ) = cos⁴θ when natural vignetting is on and 1 otherwise (see the tri-Ace
// talk's derivation and camera.cpp), and exposureScale is derived in exposure.h.
//
// Film coordinates: pixel (x, y) covers [x, x+1) × [y, y+1); y = 0 is the top row.
#include "core/math.h"
#include "scene/scene.h"

namespace pl {

class Camera {
 public:
  /// A camera for an image of width × height pixels. Thin lens when desc.fNumber > 0.
  Camera(const CameraDesc& desc, int width, int height, bool vignetting = false);

  struct Sample {
    Ray ray;            ///< unit direction, origin on the lens
    float weight = 1.0f;  ///< cos⁴θ with vignetting on, else 1
  };
  /// A ray through film position (x, y) in pixels, through lens position `lens` ∈ [0,1)²
  /// (ignored for a pinhole).
  Sample generateRay(Vec2 film, Vec2 lens) const;

  int width() const { return width_; }
  int height() const { return height_; }
  bool isThinLens() const { return apertureRadius_ > 0.0f; }
  const CameraDesc& desc() const { return desc_; }
  /// Projects a world point to film coordinates (pixels); false when behind the camera.
  bool project(const Vec3& world, Vec2& film) const;

 private:
  CameraDesc desc_;
  int width_, height_;
  bool vignetting_;
  Vec3 eye_, forward_, right_, up_;
  float tanHalfFovY_, aspect_;
  float apertureRadius_ = 0.0f;  ///< scene units
  float focusDistance_ = 1.0f;   ///< scene units
};

}  // namespace pl
