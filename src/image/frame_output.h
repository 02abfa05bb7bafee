#pragma once
// Picture output: how a frame of radiance becomes a file — the exposed copy, one image
// (writeFrame: the one way every command writes an image), an image sequence named by a
// printf-style frame pattern ("frames/%04d.png"), or an MP4 video encoded by the ffmpeg program.
//
// Frame patterns contain exactly one conversion %d or %0Nd (N = 1…9): frame k of the path
// replaces it by k (0-based). "%%" stands for a literal '%'.
//
// Video: frames (8-bit sRGB, already tone-mapped) are piped as raw RGB24 into
//   ffmpeg -f rawvideo -pix_fmt rgb24 -s W×H -r FPS -i - -c:v libx264 -pix_fmt yuv420p
//          -crf 18 -movflags +faststart -f mp4 .OUT.mp4.tmp-PID-N
// (a hidden temporary beside OUT.mp4, core/file_io.h) and the finished file is renamed to
// OUT.mp4 (never a half-written video under the final name). libx264 needs even sizes: an odd width or height is refused before rendering.
#include <cstdio>
#include <string>

#include "core/file_io.h"
#include "image/image.h"
#include "image/tonemap.h"

namespace pl {

/// radiance × exposureScale (camera/exposure.h), the exposed image tone mapping starts from.
Image exposedCopy(const Image& radiance, float exposureScale);

/// Writes a frame of radiance, the one way every command writes an image (ViewSettings::
/// writeImage in jobs/jobs.h calls this): .exr/.hdr/.pfm get radiance × exposureScale, .png
/// additionally the tone mapping and sRGB encoding. Atomic.
void writeFrame(const std::string& path, const Image& radiance, float exposureScale, const ToneMapSettings& toneMap);

/// True when `pattern` contains a frame conversion (%d or %0Nd). Throws pl::Error naming
/// the option for malformed patterns (two conversions, "%x", width out of range).
bool isFramePattern(const std::string& pattern, const std::string& option = "-o");
/// The pattern with its conversion replaced by `frame`.
std::string formatFramePath(const std::string& pattern, int frame);

/// True for an .mp4 output name (case-insensitive).
bool isVideoOutput(const std::string& path);
/// The ffmpeg executable found on PATH, or "" when it is not installed.
std::string findFfmpeg();

class VideoWriter {
 public:
  /// Starts ffmpeg. Throws pl::Error when ffmpeg is missing (saying so and suggesting an
  /// image sequence), for odd sizes, or when the process cannot start.
  VideoWriter(const std::string& path, int width, int height, double fps);
  ~VideoWriter();  ///< without finish(): stops ffmpeg and removes the partial file
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  void write(const Image8& frame);
  /// Closes the pipe, checks ffmpeg's exit status and renames the file into place.
  void finish();

 private:
  PendingFile file_;  ///< the target and the temporary ffmpeg writes to
  int width_, height_;
  FILE* pipe_ = nullptr;
};

}  // namespace pl
