// Frame patterns and MP4 output.
#include "image/frame_output.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/error.h"
#include "support/temp_dir_test.h"

namespace pl {
namespace {

TEST(FrameOutput, FormatsFramePatterns) {
  EXPECT_TRUE(isFramePattern("frames/%04d.png"));
  EXPECT_EQ(formatFramePath("frames/%04d.png", 7), "frames/0007.png");
  EXPECT_EQ(formatFramePath("f%d.exr", 123), "f123.exr");
  EXPECT_EQ(formatFramePath("f%3d.exr", 5), "f  5.exr");
  EXPECT_EQ(formatFramePath("100%%_%02d.png", 3), "100%_03.png");
  EXPECT_EQ(formatFramePath("f%02d.png", 1234), "f1234.png");  // wider numbers are not cut
  EXPECT_FALSE(isFramePattern("still.png"));
  EXPECT_FALSE(isFramePattern("100%%.png"));
  EXPECT_THROW(isFramePattern("f%d_%d.png"), Error);
  EXPECT_THROW(isFramePattern("f%x.png"), Error);
  EXPECT_THROW(isFramePattern("f%010d.png"), Error);
  EXPECT_THROW(isFramePattern("f%"), Error);
}

TEST(FrameOutput, RecognisesVideo) {
  EXPECT_TRUE(isVideoOutput("walk.mp4"));
  EXPECT_TRUE(isVideoOutput("WALK.MP4"));
  EXPECT_FALSE(isVideoOutput("walk.png"));
}

/// Restores an environment variable when it goes out of scope.
struct EnvironmentGuard {
  std::string name, value;
  bool had;
  explicit EnvironmentGuard(const char* n) : name(n), had(std::getenv(n) != nullptr) {
    if (had) value = std::getenv(n);
  }
  ~EnvironmentGuard() {
    if (had) ::setenv(name.c_str(), value.c_str(), 1);
    else ::unsetenv(name.c_str());
  }
};

TEST(FrameOutput, MissingFfmpegIsAClearError) {
  EnvironmentGuard guard("PATH");
  ::setenv("PATH", "/nonexistent-plenoptic-dir", 1);
  EXPECT_EQ(findFfmpeg(), "");
  try {
    VideoWriter writer("walk.mp4", 16, 16, 30.0);
    FAIL() << "no error without ffmpeg";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("walk.mp4: MP4 output needs ffmpeg, which is not installed"), std::string::npos)
        << e.what();
  }
}

/// Video files go into a fresh directory per test.
class VideoFiles : public test_support::TempDirTest {};

TEST_F(VideoFiles, WritesAnMp4WhenFfmpegIsInstalled) {
  if (findFfmpeg().empty()) GTEST_SKIP() << "ffmpeg is not installed";
  const std::filesystem::path path = dir_ / "walk.mp4";
  EXPECT_THROW(VideoWriter(path.string(), 15, 16, 30.0), Error);  // odd width
  {
    VideoWriter writer(path.string(), 32, 16, 30.0);
    Image8 frame{32, 16, std::vector<uint8_t>(32 * 16 * 3)};
    for (int k = 0; k < 5; ++k) {
      std::fill(frame.rgb.begin(), frame.rgb.end(), uint8_t(40 * k));
      writer.write(frame);
    }
    EXPECT_FALSE(std::filesystem::exists(path));  // only the temporary file until finish()
    writer.finish();
  }
  ASSERT_TRUE(std::filesystem::exists(path));
  EXPECT_GT(std::filesystem::file_size(path), 100u);
  EXPECT_EQ(fileCount(), 1u);  // no temporary left beside it
}

TEST_F(VideoFiles, AnUnfinishedVideoLeavesNoFile) {
  if (findFfmpeg().empty()) GTEST_SKIP() << "ffmpeg is not installed";
  const std::filesystem::path path = dir_ / "abandoned.mp4";
  {
    VideoWriter writer(path.string(), 16, 16, 30.0);
    writer.write(Image8{16, 16, std::vector<uint8_t>(16 * 16 * 3, 128)});
  }  // destroyed without finish(), as when rendering fails half-way
  EXPECT_EQ(fileCount(), 0u);  // neither the video nor its temporary (core/file_io.h)
}

}  // namespace
}  // namespace pl
