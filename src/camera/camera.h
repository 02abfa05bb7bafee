#pragma once
// Cameras and exposure: how a pixel value follows from scene radiance.
//
// Pixel value = exposureScale · vignetting(θ) · (mean radiance arriving through the pixel's
// footprint and the lens aperture), where θ is the angle between the ray and the optical
// axis, vignetting(θ) = cos⁴θ when natural vignetting is on and 1 otherwise (see the tri-Ace
// talk's derivation and camera.cpp), and exposureScale is derived in exposure.h.
//
// Film coordinates: pixel (x, y) covers [x, x+1) × [y, y+1); y = 0 is the top row.
//
// Geometry. The camera looks from eye to target; `up` fixes the roll. The vertical field of
// view fovY spans the image height; pixels are square, so the horizontal extent follows from
// width/height (CameraDesc::aspectRatio is informational only). Film point (x, y) maps to the
// camera-space direction (sx, sy, 1) with
//     sx = (2x/width − 1) · tan(fovY/2) · width/height,   sy = (1 − 2y/height) · tan(fovY/2).
//
// Thin lens (CameraDesc::fNumber = N > 0). The lens sits at the eye, perpendicular to the
// optical axis, focused at distance d_f (CameraDesc::focusDistance, or |target − eye| when
// 0). The field of view is the one *at this focus*: the plane in focus at distance d_f
// spans 2·d_f·tan(fovY/2) vertically (a real lens "breathes": we keep the framing, not the
// sensor-to-lens distance). A film point's chief ray (through the lens centre) is the
// pinhole ray; every lens point sends its ray towards where the chief ray meets the focus
// plane, so points at d_f are sharp and others blur (the thin-lens law).
//
// Aperture in scene units. The physical lens is a 35 mm-format lens (sensor 36 × 24 mm,
// height 24 mm): its focal length is f_mm = CameraDesc::focalLengthMm when given, otherwise
// the one that gives fovY on that sensor, f_mm = 12 mm / tan(fovY/2). The aperture diameter
// is A = f/N. To put the lens into the scene we need the scene's length unit, so Camera takes
// metresPerUnit (metres per scene unit: 1 for glTF/metre scenes, 0.001 for the Cornell box in
// millimetres): f = f_mm · 0.001 / metresPerUnit scene units, aperture radius = f/(2N).
// Depth of field then matches a real 35 mm camera of that focal length and f-number at the
// same distances: a point at depth d blurs into a circle of diameter (on the film, as a
// fraction of the image height)
//     c / h = A·|d − d_f| / (d · 2·d_f·tan(fovY/2))
// which equals the thin-lens formula c = A·|d − d_f|/d · f/(d_f − f) divided by the sensor
// height h = 2·v·tan(fovY/2) with v = f·d_f/(d_f − f) the lens-to-sensor distance.
#include "core/math.h"
#include "scene/scene.h"

namespace pl {

/// Height of the 35 mm full-frame sensor that focal lengths refer to (millimetres).
inline constexpr float kFullFrameSensorHeightMm = 24.0f;
/// f_mm = 12 mm / tan(fovY/2): the focal length giving this vertical fov on a 24 mm sensor.
float focalLengthMmForFov(float fovYDegrees);
/// Inverse: fovY = 2·atan(12 mm / f_mm), degrees.
float fovForFocalLengthMm(float focalLengthMm);

class Camera {
 public:
  /// A camera for an image of width × height pixels. Thin lens when desc.fNumber > 0.
  /// metresPerUnit: the scene's length unit in metres (sizes the lens; see above).
  /// Throws pl::Error naming the camera for impossible settings (eye = target, up parallel
  /// to the view direction, fov outside (0°, 180°), focus distance ≤ focal length, ...).
  Camera(const CameraDesc& desc, int width, int height, bool vignetting = false, float metresPerUnit = 1.0f);

  struct Sample {
    Ray ray;            ///< unit direction, origin on the lens
    float weight = 1.0f;  ///< cos⁴θ with vignetting on, else 1
  };
  /// A ray through film position (x, y) in pixels, through lens position `lens` ∈ [0,1)²
  /// (ignored for a pinhole). The lens sample is mapped to the aperture disk by the
  /// concentric map (uniform in area). θ is the chief ray's angle to the optical axis.
  Sample generateRay(Vec2 film, Vec2 lens) const;

  int width() const { return width_; }
  int height() const { return height_; }
  bool isThinLens() const { return apertureRadius_ > 0.0f; }
  const CameraDesc& desc() const { return desc_; }
  /// Projects a world point to film coordinates (pixels) through the lens centre (for a
  /// thin lens: the centre of the point's blur circle); false when not in front of the camera.
  bool project(const Vec3& world, Vec2& film) const;

  Vec3 eye() const { return eye_; }
  Vec3 forward() const { return forward_; }  ///< optical axis, unit
  Vec3 right() const { return right_; }      ///< film +x in world space, unit
  Vec3 up() const { return up_; }            ///< film −y (up on the image) in world space, unit
  float tanHalfFovY() const { return tanHalfFovY_; }
  float aspect() const { return aspect_; }   ///< width / height
  float focalLengthMm() const { return focalLengthMm_; }   ///< physical (35 mm format)
  float apertureRadius() const { return apertureRadius_; }  ///< scene units (0 = pinhole)
  float focusDistance() const { return focusDistance_; }    ///< scene units
  bool vignetting() const { return vignetting_; }
  /// The height of one pixel on the image plane at unit distance from the eye, 2·tan(fovY/2)
  /// / height: the width of a pixel's ray cone per unit distance (render_settings.h
  /// textureConeSpread).
  float pixelSpread() const { return 2.0f * tanHalfFovY_ / float(height_); }

 private:
  CameraDesc desc_;
  int width_, height_;
  bool vignetting_;
  Vec3 eye_, forward_, right_, up_;
  float tanHalfFovY_, aspect_;
  float focalLengthMm_ = 0.0f;
  float apertureRadius_ = 0.0f;  ///< scene units
  float focusDistance_ = 1.0f;   ///< scene units
};

}  // namespace pl
