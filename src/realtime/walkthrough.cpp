// Rendering camera paths to files (see walkthrough.h).
#include "realtime/walkthrough.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>

#include "camera/camera.h"
#include "core/error.h"
#include "core/progress.h"
#include "core/timing.h"
#include "image/frame_output.h"

namespace pl {

WalkthroughResult renderWalkthrough(const CameraPath& path, const CameraDesc& baseCamera, const WalkthroughOptions& options,
                                    const std::function<void(const Camera&, Image&)>& renderFrame) {
  const bool video = isVideoOutput(options.output);
  if (!video && !isFramePattern(options.output))
    fail("-o {}: a camera path renders many frames: give a frame pattern like frames/%04d.png or an .mp4 file",
         options.output);
  if (!video) {
    const std::string ext = fileExtensionLower(options.output);
    if (!isHdrExtension(options.output) && ext != ".png")
      fail("-o {}: unknown image type '{}' (expected {})", options.output, ext, alternatives(kWrittenImageExtensions));
  }
  const std::filesystem::path parent = std::filesystem::path(options.output).parent_path();
  if (!parent.empty()) {
    std::error_code error;
    std::filesystem::create_directories(parent, error);
    if (error) fail("-o {}: cannot create directory '{}': {}", options.output, parent.string(), error.message());
  }
  std::unique_ptr<VideoWriter> videoWriter;
  if (video) videoWriter = std::make_unique<VideoWriter>(options.output, options.width, options.height, path.fps);

  WalkthroughResult result;
  result.frames = path.frameCount();
  std::unique_ptr<Progress> progress;
  if (options.showProgress) progress = std::make_unique<Progress>("walk-through", uint64_t(result.frames));
  Image image;
  for (int frame = 0; frame < result.frames; ++frame) {
    const CameraDesc desc = applyPose(baseCamera, path.at(path.frameTime(frame)));
    const Camera camera(desc, options.width, options.height, options.vignetting, options.metresPerUnit);
    const auto start = std::chrono::steady_clock::now();
    renderFrame(camera, image);
    result.frameMs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    if (videoWriter) {
      videoWriter->write(toneMap(exposedCopy(image, options.exposureScale), options.toneMap));
    } else {
      writeFrame(formatFramePath(options.output, frame), image, options.exposureScale, options.toneMap);
    }
    if (progress) progress->advance();
  }
  if (videoWriter) videoWriter->finish();
  result.msPerFrameMedian = median(result.frameMs);
  result.fps = result.msPerFrameMedian > 0.0 ? 1e3 / result.msPerFrameMedian : 0.0;
  return result;
}

WalkthroughResult renderWalkthrough(const CameraPath& path, const CameraDesc& baseCamera, const WalkthroughOptions& options,
                                    const FastRenderer& renderer, const RenderSettings& settings) {
  return renderWalkthrough(path, baseCamera, options,
                           [&](const Camera& camera, Image& image) { renderer.render(camera, settings, image); });
}

}  // namespace pl
