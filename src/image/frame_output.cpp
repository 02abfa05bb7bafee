// Image sequences and MP4 output (see frame_output.h).
#include "image/frame_output.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>

#include "core/error.h"
#include "image/tonemap.h"

namespace pl {
namespace {

struct Conversion {
  size_t begin = std::string::npos, end = 0;  ///< [begin, end) of "%0Nd" in the pattern
  int width = 0;
  bool zeroPad = false;
};

Conversion findConversion(const std::string& pattern, const std::string& option) {
  Conversion found;
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') continue;
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      ++i;
      continue;
    }
    size_t j = i + 1;
    Conversion c;
    c.begin = i;
    if (j < pattern.size() && pattern[j] == '0') {
      c.zeroPad = true;
      ++j;
    }
    while (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9') c.width = c.width * 10 + (pattern[j++] - '0');
    if (j >= pattern.size() || pattern[j] != 'd' || c.width > 9)
      fail("{} {}: bad frame pattern at '{}' (use %d or %0Nd with N ≤ 9, and %% for a literal %)", option, pattern,
           pattern.substr(i, std::min<size_t>(4, pattern.size() - i)));
    c.end = j + 1;
    if (found.begin != std::string::npos) fail("{} {}: more than one frame number (%d) in the pattern", option, pattern);
    found = c;
    i = j;
  }
  return found;
}

}  // namespace

Image exposedCopy(const Image& radiance, float exposureScale) {
  Image exposed = radiance;
  if (exposureScale != 1.0f)
    for (Rgb& p : exposed.pixels) p *= exposureScale;
  return exposed;
}

void writeFrame(const std::string& path, const Image& radiance, float exposureScale, const ToneMapSettings& toneMap) {
  const bool hdr = isHdrExtension(path);
  if (!hdr && fileExtensionLower(path) != ".png")
    fail("{}: unknown output type '{}' (use {})", path, fileExtensionLower(path), alternatives(kWrittenImageExtensions));
  if (hdr && exposureScale == 1.0f) {
    writeHdrImage(path, radiance);  // radiance as it is: no exposed copy (half the memory)
  } else if (hdr) {
    writeHdrImage(path, exposedCopy(radiance, exposureScale));
  } else {
    writePng(path, pl::toneMap(exposedCopy(radiance, exposureScale), toneMap));
  }
}

bool isFramePattern(const std::string& pattern, const std::string& option) {
  return findConversion(pattern, option).begin != std::string::npos;
}

std::string formatFramePath(const std::string& pattern, int frame) {
  const Conversion c = findConversion(pattern, "-o");
  std::string number = std::to_string(frame);
  if (c.width > int(number.size())) number.insert(0, size_t(c.width) - number.size(), c.zeroPad ? '0' : ' ');
  std::string out;
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (i == c.begin) {
      out += number;
      i = c.end - 1;
    } else if (pattern[i] == '%' && i + 1 < pattern.size() && pattern[i + 1] == '%') {
      out += '%';
      ++i;
    } else {
      out += pattern[i];
    }
  }
  return out;
}

bool isVideoOutput(const std::string& path) { return fileExtensionLower(path) == ".mp4"; }

std::string findFfmpeg() {
  const char* pathVariable = std::getenv("PATH");
  if (!pathVariable) return "";
  const std::string paths = pathVariable;
  size_t start = 0;
  while (start <= paths.size()) {
    const size_t colon = paths.find(':', start);
    const std::string dir = paths.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    if (!dir.empty()) {
      const std::string candidate = dir + "/ffmpeg";
      if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    }
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  return "";
}

VideoWriter::VideoWriter(const std::string& path, int width, int height, double fps)
    : file_(path), width_(width), height_(height) {
  const std::string ffmpeg = findFfmpeg();
  if (ffmpeg.empty())
    fail("-o {}: MP4 output needs ffmpeg, which is not installed (not found on PATH); write an image sequence "
         "instead, e.g. -o frames/%04d.png",
         path);
  if (width % 2 != 0 || height % 2 != 0)
    fail("-o {}: MP4 (H.264, 4:2:0) needs an even width and height, got {}x{}", path, width, height);
  // Paths are single-quoted for the shell; a quote inside is closed, escaped and reopened.
  auto quote = [](const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
  };
  const std::string command =
      fmt::format("{} -loglevel error -y -f rawvideo -pix_fmt rgb24 -s {}x{} -r {} -i - -c:v libx264 -pix_fmt yuv420p "
                  "-crf 18 -movflags +faststart -f mp4 {}",
                  quote(ffmpeg), width, height, fps, quote(file_.temporaryPath()));
  // If ffmpeg dies, writing to its pipe must fail with EPIPE (reported below), not kill us.
  ::signal(SIGPIPE, SIG_IGN);
  pipe_ = ::popen(command.c_str(), "w");
  if (!pipe_) fail("-o {}: cannot start ffmpeg", path);
}

VideoWriter::~VideoWriter() {
  if (pipe_) ::pclose(pipe_);
  // file_ (destroyed next) removes the partial video unless finish() committed it.
}

void VideoWriter::write(const Image8& frame) {
  if (frame.width != width_ || frame.height != height_)
    fail("{}: frame of {}x{} pixels in a {}x{} video", file_.target(), frame.width, frame.height, width_, height_);
  if (std::fwrite(frame.rgb.data(), 1, frame.rgb.size(), pipe_) != frame.rgb.size())
    fail("{}: ffmpeg stopped accepting frames (see its message above)", file_.target());
}

void VideoWriter::finish() {
  const int status = ::pclose(pipe_);
  pipe_ = nullptr;
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    file_.discard();
    fail("{}: ffmpeg failed (exit status {})", file_.target(), WIFEXITED(status) ? WEXITSTATUS(status) : -1);
  }
  file_.commit();
}

}  // namespace pl
