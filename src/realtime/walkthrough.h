#pragma once
// Rendering a camera path to files: the loop behind `plenoptic render --path` and the
// non-interactive `make demo`. Frame k shows the path's pose at t₀ + k/fps on the base camera
// (which keeps its lens and, when the path has no fov, its fov); each frame is written as
// `plenoptic render` writes a single image (image/frame_output.h writeFrame), or piped into an
// MP4 (VideoWriter, the same file).
#include <functional>
#include <string>
#include <vector>

#include "camera/camera_path.h"
#include "image/image.h"
#include "image/tonemap.h"
#include "lightfield/render_settings.h"
#include "realtime/realtime.h"

namespace pl {

class Camera;

struct WalkthroughOptions {
  std::string output;  ///< frame pattern ("frames/%04d.png", .png/.exr/.hdr/.pfm) or an .mp4 file
  int width = 640, height = 480;
  bool vignetting = false;
  float metresPerUnit = 1.0f;         ///< sizes a thin lens (camera.h)
  float exposureScale = 1.0f;         ///< radiance → pixel value (exposure.h)
  ToneMapSettings toneMap;            ///< for PNG and MP4 frames
  bool showProgress = true;
};

struct WalkthroughResult {
  int frames = 0;
  std::vector<double> frameMs;        ///< render time of each frame (files excluded)
  double msPerFrameMedian = 0.0;
  double fps = 0.0;                   ///< 1000 / msPerFrameMedian
};

/// Renders every frame of `path` with `renderFrame` (which fills the image for a camera) and
/// writes it. Frame-pattern directories are created. Throws pl::Error for a bad output name,
/// a missing ffmpeg (MP4) or any write failure.
WalkthroughResult renderWalkthrough(const CameraPath& path, const CameraDesc& baseCamera, const WalkthroughOptions& options,
                                    const std::function<void(const Camera&, Image&)>& renderFrame);
/// The same with the fast renderer and `settings`.
WalkthroughResult renderWalkthrough(const CameraPath& path, const CameraDesc& baseCamera, const WalkthroughOptions& options,
                                    const FastRenderer& renderer, const RenderSettings& settings);

}  // namespace pl
