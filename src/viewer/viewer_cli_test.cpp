// `plenoptic view` headless (SDL_VIDEODRIVER=dummy, and an X window under Xvfb): the
// screenshot after N frames is the image `plenoptic render` writes for the same view and
// renderer (CPU and GPU), with and without a scripted camera path; the fallback to the CPU
// renderer; the walk-through output of `render --path`; and the error paths.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "accel/accel.h"
#include "bake/parameterisation.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/rng.h"
#include "gpu/gpu.h"
#include "image/frame_output.h"
#include "image/image.h"
#include "plf/plf_file.h"
#include "support/cli_test_support.h"
#include "support/random_light_field.h"
#include "support/sky_map.h"
#include "viewer/viewer.h"

namespace pl {
namespace {

namespace fs = std::filesystem;

/// The built-in Cornell box with the default preset's charts and smooth pseudo-random
/// values (fast to make: no bake; the renderers do not care how the values were computed).
LightField cornellLightField() {
  LightField lf;
  Scene scene = makeCornellBox();
  Parameterisation param = buildParameterisation(scene, lf.settings);
  lf.charts = std::move(param.charts);
  lf.triangleChart = std::move(param.triangleChart);
  lf.values.resize(param.valueCount);
  Pcg32 rng(11, 3);
  for (Rgb& v : lf.values) v = Rgb(0.5f + rng.uniform(), 0.5f + rng.uniform(), 0.5f + rng.uniform());
  lf.scene = std::move(scene);
  return lf;
}

class ViewerCliTest : public cli_test::CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    // Headless: SDL's dummy video driver, inherited by every run() (ctest sets it too).
    ::setenv("SDL_VIDEODRIVER", "dummy", 1);
    writeLightField(path("cornell.plf"), cornellLightField());
  }

  /// walk.json: from the box's default view to the eye (350, 250, −300) looking at (250, 150,
  /// 300), the field of view 39° → 55°, in 0.5 s at 4 fps (3 frames).
  void writeWalkToTheSide() const {
    std::ofstream json(path("walk.json"));
    json << R"({"fps": 4, "keyframes": [
      {"time": 0, "eye": [278, 273, -800], "target": [278, 273, 0], "fov": 39},
      {"time": 0.5, "eye": [350, 250, -300], "target": [250, 150, 300], "fov": 55}]})";
  }
  static bool xvfbInstalled() { return std::system("command -v xvfb-run > /dev/null 2>&1") == 0; }
  /// The environment of a run in an X11 window: xvfb-run starts a virtual X server (-a: on a
  /// free display number) and runs the viewer on it.
  static constexpr const char* kInXvfb = "SDL_VIDEODRIVER=x11 xvfb-run -a -s '-screen 0 320x240x24'";

  /// Number of pixels whose 8-bit values differ between two PNGs (read back as linear).
  static int differingPixels(const std::string& a, const std::string& b) {
    const Image ia = readImage(a), ib = readImage(b);
    EXPECT_EQ(ia.width, ib.width);
    EXPECT_EQ(ia.height, ib.height);
    if (ia.width != ib.width || ia.height != ib.height) return -1;
    int differ = 0;
    for (size_t i = 0; i < ia.pixels.size(); ++i) differ += ia.pixels[i] != ib.pixels[i];
    return differ;
  }
};

TEST_F(ViewerCliTest, ScreenshotAfterFramesEqualsRender) {
  const std::string size = " --width 160 --height 120";
  ASSERT_EQ(run("render " + path("cornell.plf") + " -o " + path("render.png") + size), 0);
  std::string errors;
  ASSERT_EQ(run("view " + path("cornell.plf") + " --renderer cpu --frames 3 --screenshot " + path("view.png") + size,
                nullptr, &errors),
            0)
      << errors;
  // Same fast renderer, same camera, same exposure and tone-mapping code: identical pixels
  // (the HUD is drawn on the window only, never into screenshots).
  EXPECT_EQ(differingPixels(path("render.png"), path("view.png")), 0);
  // The same holds with exposure and tone-mapping flags.
  const std::string look = size + " --exposure 1.5 --tonemap clamp";
  ASSERT_EQ(run("render " + path("cornell.plf") + " -o " + path("render2.png") + look), 0);
  ASSERT_EQ(run("view " + path("cornell.plf") + " --renderer cpu --frames 2 --screenshot " + path("view2.png") + look), 0);
  EXPECT_EQ(differingPixels(path("render2.png"), path("view2.png")), 0);
  // And the image is not the same for both looks (the flags reached the viewer).
  EXPECT_GT(differingPixels(path("view.png"), path("view2.png")), 0);
}

TEST_F(ViewerCliTest, ScriptedPathEndsWhereRenderOfTheLastKeyframeIs) {
  {
    std::ofstream json(path("walk.json"));
    json << R"({"fps": 4, "keyframes": [
      {"time": 0, "eye": [278, 273, -800], "target": [278, 273, 0], "fov": 39},
      {"time": 0.5, "eye": [200, 300, -500], "target": [300, 250, 200]},
      {"time": 1, "eye": [350, 250, -300], "target": [250, 150, 300], "fov": 55}]})";
  }
  const std::string size = " --width 96 --height 72";
  std::string errors;
  // 1 s at 4 fps: frames at 0, 0.25, 0.5, 0.75, 1 — the last one on the last keyframe. The
  // moving camera is drawn at a reduced resolution (a 1000 fps target), the screenshot at full.
  ASSERT_EQ(run("view " + path("cornell.plf") + " --renderer cpu --target-fps 1000 --path " + path("walk.json") +
                    " --screenshot " + path("view.png") + size,
                nullptr, &errors),
            0)
      << errors;
  ASSERT_EQ(run("render " + path("cornell.plf") + " -o " + path("last.png") +
                " --eye 350,250,-300 --target 250,150,300 --fov 55" + size),
            0);
  EXPECT_EQ(differingPixels(path("view.png"), path("last.png")), 0);

  // The walk-through through `render --path`: 5 frames; its last frame is the same image.
  ASSERT_EQ(run("render " + path("cornell.plf") + " --path " + path("walk.json") + " -o " + path("frames/f%02d.png") +
                    " --stats " + path("stats.json") + size,
                nullptr, &errors),
            0)
      << errors;
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(fs::exists(path("frames/f0" + std::to_string(k) + ".png"))) << k;
  EXPECT_FALSE(fs::exists(path("frames/f05.png")));
  EXPECT_EQ(differingPixels(path("frames/f04.png"), path("last.png")), 0);
  EXPECT_GT(differingPixels(path("frames/f00.png"), path("frames/f02.png")), 0);  // the camera moved
  std::ifstream stats(path("stats.json"));
  std::stringstream text;
  text << stats.rdbuf();
  EXPECT_NE(text.str().find("\"frames\": 5"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("\"ms_per_frame_median\""), std::string::npos);
  EXPECT_NE(text.str().find("\"fps\""), std::string::npos);
}

// The GPU renderer in the viewer: its screenshot is the image `render --renderer gpu` writes,
// headless (SDL's dummy driver) and in an X window (Xvfb).
TEST_F(ViewerCliTest, GpuScreenshotEqualsGpuRender) {
  const std::string size = " --width 160 --height 120";
  std::string out, errors;
  ASSERT_EQ(run("render " + path("cornell.plf") + " --renderer gpu -o " + path("render.png") + size, nullptr, &errors), 0)
      << errors;
  ASSERT_EQ(run("view " + path("cornell.plf") + " --renderer gpu --frames 3 --screenshot " + path("view.png") + size, &out,
                &errors),
            0)
      << errors;
  EXPECT_NE(out.find("renderer gpu ("), std::string::npos) << out;  // "renderer gpu (llvmpipe …, OpenGL 4.5 …)"
  EXPECT_EQ(differingPixels(path("render.png"), path("view.png")), 0);
}

TEST_F(ViewerCliTest, GpuScreenshotUnderXvfbEqualsGpuRender) {
  if (!xvfbInstalled()) GTEST_SKIP() << "xvfb-run is not installed (scripts/bootstrap.sh installs it)";
  writeWalkToTheSide();
  const std::string size = " --width 128 --height 96";
  std::string out, errors;
  ASSERT_EQ(run("render " + path("cornell.plf") + " --renderer gpu -o " + path("render.png") + size +
                    " --eye 350,250,-300 --target 250,150,300 --fov 55",
                nullptr, &errors),
            0)
      << errors;
  const int code = cli_test::runPlenoptic("view " + path("cornell.plf") + " --renderer gpu --path " + path("walk.json") +
                                              " --screenshot " + path("view.png") + size + " --quiet",
                                          dir_, &out, &errors, kInXvfb);
  ASSERT_EQ(code, 0) << out << errors;
  EXPECT_NE(out.find("renderer gpu ("), std::string::npos) << out;
  EXPECT_EQ(differingPixels(path("render.png"), path("view.png")), 0);
}

// What the window shows, read back from it (--window-shot): in an X window under Xvfb the GPU
// renderer draws and presents in the window's own OpenGL context; headless (SDL's dummy driver)
// its frame is read back and SDL blits it. Below the HUD, whose figures differ from run to run,
// the two windows show the same pixels.
TEST_F(ViewerCliTest, WindowShowsTheSamePixelsThroughOpenGlAndSdl) {
  if (!xvfbInstalled()) GTEST_SKIP() << "xvfb-run is not installed (scripts/bootstrap.sh installs it)";
  writeWalkToTheSide();
  constexpr int kWidth = 128, kHeight = 224;
  // The HUD: at most 5 lines here (no relighting), kLineAdvance·2 pixels each and 6 more.
  constexpr int kBelowHud = 5 * 9 * 2 + 6;
  const std::string view = "view " + path("cornell.plf") + " --path " + path("walk.json") + " --width " +
                           std::to_string(kWidth) + " --height " + std::to_string(kHeight) + " --quiet --window-shot ";
  std::string out, errors;
  ASSERT_EQ(cli_test::runPlenoptic(view + path("gl.png") + " --renderer gpu --vsync off --stats " + path("gl.json"), dir_, &out, &errors, kInXvfb),
            0)
      << out << errors;
  ASSERT_EQ(run(view + path("sdl.png") + " --renderer gpu --stats " + path("sdl.json"), nullptr, &errors), 0) << errors;
  const nlohmann::json glStats = nlohmann::json::parse(std::ifstream(path("gl.json")));
  EXPECT_EQ(glStats["presentation"], "opengl");
  EXPECT_EQ(glStats["vsync"], false);  // (--vsync off: swapped as soon as drawn)
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(path("sdl.json")))["presentation"], "sdl");
  const Image gl = readImage(path("gl.png")), sdl = readImage(path("sdl.png"));
  for (const Image* image : {&gl, &sdl}) {
    ASSERT_EQ(image->width, kWidth);
    ASSERT_EQ(image->height, kHeight);
  }
  int differ = 0, variedFromFirst = 0;
  for (int y = kBelowHud; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const size_t i = size_t(y) * kWidth + size_t(x);
      differ += gl.pixels[i] != sdl.pixels[i];
      variedFromFirst += gl.pixels[i] != gl.pixels[size_t(kBelowHud) * kWidth];
    }
  EXPECT_EQ(differ, 0);
  EXPECT_GT(variedFromFirst, kWidth * (kHeight - kBelowHud) / 2);  // a picture, not a cleared window
  // The HUD is there: its half-transparent backdrop darkens the window's top-left corner.
  const Image screenshot = [&] {
    EXPECT_EQ(run("render " + path("cornell.plf") + " --renderer gpu -o " + path("render.png") +
                  " --eye 350,250,-300 --target 250,150,300 --fov 55 --width 128 --height 224"),
              0);
    return readImage(path("render.png"));
  }();
  EXPECT_LT(gl.pixels[size_t(kWidth) * 2 + 2].g, screenshot.pixels[size_t(kWidth) * 2 + 2].g);
}

/// A light field with mirror-like lobes (a chart the GPU renderer does not draw yet).
/// The mirror-like Cornell box lit by a sky map too: environment maps lighting mirror-like
/// lobes are what the GPU renderer does not draw yet.
void writeMapLitMirrorLightField(const std::string& file) {
  Scene sky = test_support::mirrorLikeCornellBox();
  sky.environment.map = std::make_shared<const EnvironmentMap>(test_support::skyWithSun(30.0f));
  writeLightField(file, test_support::randomLightField(std::move(sky), 5));
}

/// The lines of `text` that contain `word`.
int linesWith(const std::string& text, const std::string& word) {
  std::istringstream lines(text);
  int count = 0;
  for (std::string line; std::getline(lines, line);) count += line.find(word) != std::string::npos;
  return count;
}

// By default the viewer takes the GPU renderer where it can; otherwise it draws with the CPU
// one after one warning line saying why — and the picture is the CPU renderer's.
TEST_F(ViewerCliTest, FallsBackToTheCpuRendererWithOneWarningLine) {
  const std::string size = " --width 96 --height 72";
  ASSERT_EQ(run("render " + path("cornell.plf") + " --renderer cpu -o " + path("cpu.png") + size), 0);
  struct Case {
    std::string environment, why;
  };
  const bool software = [] {
    const GpuProbe probe = probeGpu();
    return probe.available && probe.software;
  }();
  std::vector<Case> cases = {{"MESA_GL_VERSION_OVERRIDE=3.3", "EGL_BAD_MATCH"},
                             {"__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json", "no OpenGL 4.5 core context"}};
  if (software) cases.push_back({"", "software rasteriser"});  // llvmpipe: the tests' machines
  for (const Case& c : cases) {
    SCOPED_TRACE(c.environment);
    std::string out, errors;
    ASSERT_EQ(cli_test::runPlenoptic("view " + path("cornell.plf") + " --frames 2 --screenshot " + path("view.png") + size +
                                         " --quiet",
                                     dir_, &out, &errors, c.environment),
              0)
        << errors;
    EXPECT_EQ(linesWith(errors, "warning"), 1) << errors;
    EXPECT_NE(errors.find("plenoptic: warning: view uses the CPU renderer: "), std::string::npos) << errors;
    EXPECT_NE(errors.find(c.why), std::string::npos) << errors;
    EXPECT_NE(out.find("renderer cpu"), std::string::npos) << out;
    EXPECT_EQ(differingPixels(path("cpu.png"), path("view.png")), 0);
    // Asked for by name, the GPU renderer is an error instead.
    if (c.environment.empty()) continue;
    EXPECT_NE(cli_test::runPlenoptic("view " + path("cornell.plf") + " --renderer gpu --frames 1" + size + " --quiet", dir_,
                                     nullptr, &errors, c.environment),
              0);
    EXPECT_NE(errors.find(c.why), std::string::npos) << errors;
  }
  // A light field the GPU renderer does not draw yet: the warning names the feature.
  writeMapLitMirrorLightField(path("mirror.plf"));
  std::string out, errors;
  ASSERT_EQ(run("view " + path("mirror.plf") + " --frames 1" + size, &out, &errors), 0) << errors;
  EXPECT_EQ(linesWith(errors, "warning"), 1) << errors;
  EXPECT_NE(errors.find("view uses the CPU renderer: the GPU renderer does not draw environment maps lighting "
                        "mirror-like lobes"),
            std::string::npos)
      << errors;
  EXPECT_NE(run("view " + path("mirror.plf") + " --renderer gpu --frames 1" + size, nullptr, &errors), 0);
  EXPECT_NE(errors.find("environment maps lighting mirror-like lobes"), std::string::npos) << errors;
  EXPECT_NE(errors.find("--renderer cpu"), std::string::npos) << errors;
  // A thin lens is drawn by the GPU renderer too.
  ASSERT_EQ(run("view " + path("cornell.plf") + " --renderer gpu --aperture 2.8 --frames 1" + size, nullptr, &errors), 0)
      << errors;
  EXPECT_EQ(linesWith(errors, "warning"), 0) << errors;
  // The CPU renderer asked for: no warning.
  ASSERT_EQ(run("view " + path("cornell.plf") + " --renderer cpu --frames 1" + size, nullptr, &errors), 0) << errors;
  EXPECT_EQ(linesWith(errors, "warning"), 0) << errors;
}

// `view --stats`: the session's frames and timings as JSON, the renderer and its device named as
// `render --stats` names them; an unwritable stats path is refused before the window opens.
TEST_F(ViewerCliTest, StatsJsonHasTheSessionsTimings) {
  for (const std::string renderer : {"cpu", "gpu"}) {
    SCOPED_TRACE(renderer);
    std::string errors;
    ASSERT_EQ(run("view " + path("cornell.plf") + " --renderer " + renderer + " --frames 3 --width 64 --height 48 --stats " +
                      path("stats.json") + " --quiet",
                  nullptr, &errors),
              0)
        << errors;
    const nlohmann::json stats = nlohmann::json::parse(std::ifstream(path("stats.json")));
    EXPECT_EQ(stats["frames"], 3);
    EXPECT_EQ(stats["width"], 64);
    EXPECT_EQ(stats["height"], 48);
    EXPECT_EQ(stats["renderer"], renderer);
    EXPECT_EQ(stats["presentation"], "sdl");  // (SDL's dummy driver: no OpenGL in the window)
    EXPECT_EQ(stats["vsync"], false);
    EXPECT_EQ(stats.contains("device"), renderer == "gpu");
    if (renderer == "gpu") {
      EXPECT_NE(stats["device"].get<std::string>().find("OpenGL 4.5"), std::string::npos) << stats;
    }
    const double ms = stats["ms_per_frame_median"], renderMs = stats["render_ms_median"], fps = stats["fps"];
    EXPECT_GT(renderMs, 0.0);
    EXPECT_GE(ms, renderMs);  // a frame is its render, display and present
    EXPECT_NEAR(fps * ms, 1000.0, 1e-6 * fps * ms);
    // The GPU's own time: within the frame's render (which waits for it), and only with it. (The
    // two come from different clocks, GL timestamps and the steady clock, read at different
    // moments: 0.5 ms of slack, where a GPU time counted twice would exceed it by whole passes.)
    EXPECT_EQ(stats.contains("gpu_ms_median"), renderer == "gpu");
    if (renderer == "gpu") {
      EXPECT_GT(stats["gpu_ms_median"].get<double>(), 0.0);
      EXPECT_LE(stats["gpu_ms_median"].get<double>(), renderMs + 0.5);
    }
  }
  std::string errors;
  EXPECT_NE(run("view " + path("cornell.plf") + " --frames 1 --stats " + path("missing/stats.json"), nullptr, &errors), 0);
  EXPECT_NE(errors.find("--stats " + path("missing/stats.json") + ": directory"), std::string::npos) << errors;
}

TEST_F(ViewerCliTest, BadInputsAreClearErrors) {
  std::string errors;
  EXPECT_NE(run("view " + path("cornell.plf") + " --renderer vulkan --frames 1", nullptr, &errors), 0);
  EXPECT_NE(run("view " + path("cornell.plf") + " --target-fps -1 --frames 1", nullptr, &errors), 0);
  EXPECT_NE(run("view " + path("cornell.plf") + " --vsync maybe --frames 1", nullptr, &errors), 0);
  EXPECT_NE(errors.find("--vsync"), std::string::npos) << errors;
  EXPECT_NE(run("view " + path("cornell.plf") + " --screenshot " + path("x.png"), nullptr, &errors), 0);
  EXPECT_NE(errors.find("--screenshot needs --frames"), std::string::npos) << errors;
  EXPECT_NE(run("view " + path("cornell.plf") + " --window-shot " + path("w.png"), nullptr, &errors), 0);
  EXPECT_NE(errors.find("--window-shot needs --frames"), std::string::npos) << errors;
  EXPECT_NE(run("view " + path("cornell.plf") + " --frames 1 --window-shot " + path("w.exr"), nullptr, &errors), 0);
  EXPECT_NE(errors.find("--window-shot " + path("w.exr")), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(path("w.exr")));
  {
    std::ofstream json(path("bad.json"));
    json << R"({"keyframes": [{"time": 0, "eye": [0, 0, 1]}]})";
  }
  EXPECT_NE(run("view " + path("cornell.plf") + " --frames 1 --path " + path("bad.json"), nullptr, &errors), 0);
  EXPECT_NE(errors.find(path("bad.json") + ": keyframe 0: missing 'target'"), std::string::npos) << errors;
  EXPECT_NE(run("render " + path("cornell.plf") + " --path " + path("bad.json") + " -o " + path("f%03d.png"),
                nullptr, &errors),
            0);
  EXPECT_NE(errors.find("missing 'target'"), std::string::npos) << errors;
  EXPECT_NE(run("render " + path("cornell.plf") + " --path " + path("missing.json") + " -o " + path("f%03d.png"),
                nullptr, &errors),
            0);
  EXPECT_NE(errors.find(path("missing.json") + ": cannot open"), std::string::npos) << errors;
  // A path needs several outputs; a pattern needs a path.
  EXPECT_NE(run("render " + path("cornell.plf") + " --path " + path("bad.json") + " -o " + path("one.png"),
                nullptr, &errors),
            0);
  EXPECT_NE(errors.find("frame pattern"), std::string::npos) << errors;
  EXPECT_NE(run("render " + path("cornell.plf") + " -o " + path("f%03d.png"), nullptr, &errors), 0);
  EXPECT_NE(errors.find("needs a camera path"), std::string::npos) << errors;
  // The removed `--fast` flag (the fast renderer is the default) is now an unknown option.
  EXPECT_NE(run("render " + path("cornell.plf") + " --fast -o " + path("x.png"), nullptr, &errors), 0);
  // MP4 without ffmpeg on PATH: a clear message, before any rendering.
  {
    std::ofstream json(path("good.json"));
    json << R"({"keyframes": [{"time": 0, "eye": [278, 273, -800], "target": [278, 273, 0]}]})";
  }
  EXPECT_NE(cli_test::runPlenoptic("render " + path("cornell.plf") + " --path " + path("good.json") + " -o " +
                                        path("walk.mp4") + " --quiet",
                                    dir_, nullptr, &errors, "PATH=/nonexistent-plenoptic-dir"),
            0);
  EXPECT_NE(errors.find("MP4 output needs ffmpeg, which is not installed"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(path("walk.mp4")));
}

TEST_F(ViewerCliTest, FastAndReferenceRenderersWriteTheSameImage) {
  const std::string size = " --width 80 --height 60";
  ASSERT_EQ(run("render " + path("cornell.plf") + " -o " + path("fast.pfm") + size), 0);
  ASSERT_EQ(run("render " + path("cornell.plf") + " --reference -o " + path("reference.pfm") + size), 0);
  const Image fast = readImage(path("fast.pfm")), reference = readImage(path("reference.pfm"));
  ASSERT_EQ(fast.pixels.size(), reference.pixels.size());
  double maxDifference = 0.0;
  for (size_t i = 0; i < fast.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) maxDifference = std::max(maxDifference, double(std::abs(fast.pixels[i][c] - reference.pixels[i][c])));
  // Float rounding of the hit point only (see realtime/fast_renderer_test.cpp): values ≈ 1.
  EXPECT_LT(maxDifference, 1e-4);
}

TEST_F(ViewerCliTest, DemoWithoutDisplayRendersTheWalkThroughToFiles) {
  ::setenv("SDL_VIDEODRIVER", "dummy", 1);  // no display: the demo must write files
  Progress::setEnabled(false);
  ThreadPool pool(2);
  LightField lf = cornellLightField();
  lf.scene.finalize();
  const Accel accel(lf.scene);
  const std::vector<std::string> done =
      runDemoWalkthrough(lf, accel, lf.scene.cameras.front(), 0.001f, (dir_ / "demo").string());
  ASSERT_FALSE(done.empty());
  EXPECT_NE(done.front().find("no display"), std::string::npos) << done.front();
  // orbitPath: 4 s at 30 fps = 121 frames.
  EXPECT_TRUE(fs::exists(dir_ / "demo" / "frames" / "0000.png"));
  EXPECT_TRUE(fs::exists(dir_ / "demo" / "frames" / "0120.png"));
  EXPECT_FALSE(fs::exists(dir_ / "demo" / "frames" / "0121.png"));
  EXPECT_EQ(fs::exists(dir_ / "demo" / "walk.mp4"), !findFfmpeg().empty());
}


// Relighting keys headless: `--relight-keys` without --frames runs until the relit light field
// has converged, and its screenshot is the render of a bake of the relit scene.
TEST_F(ViewerCliTest, RelightingKeysConvergeToTheRelitScene) {
  std::string err, out;
  const std::string flags = " --preset draft --tixels-across 8 --directions 64 --tolerance 1e-4";
  ASSERT_EQ(run("bake cornell -o " + path("baked.plf") + flags, nullptr, &err), 0) << err;
  ASSERT_EQ(run("view " + path("baked.plf") + " --relight-keys ] --width 48 --height 32 --screenshot " +
                    path("relit.pfm"),
                &out, &err),
            0)
      << err;
  EXPECT_NE(out.find("view: relit:"), std::string::npos) << out;
  EXPECT_NE(out.find("(converged)"), std::string::npos) << out;
  // The emitters × 1.25: the same image as the baked one × 1.25.
  ASSERT_EQ(run("render " + path("baked.plf") + " -o " + path("baked.pfm") + " --width 48 --height 32", nullptr, &err), 0)
      << err;
  const Image relit = readImage(path("relit.pfm")), baked = readImage(path("baked.pfm"));
  ASSERT_EQ(relit.pixels.size(), baked.pixels.size());
  double a = 0.0, b = 0.0;
  for (size_t i = 0; i < relit.pixels.size(); ++i) a += relit.pixels[i].g, b += baked.pixels[i].g;
  EXPECT_NEAR(a, 1.25 * b, 1e-3 * a);
  // Keys that are not relighting keys, or no visibility field: refused before any window.
  EXPECT_NE(run("view " + path("baked.plf") + " --relight-keys x --frames 1", nullptr, &err), 0);
  EXPECT_NE(err.find("'x'"), std::string::npos) << err;
  fs::remove(path("baked.plv"));
  EXPECT_NE(run("view " + path("baked.plf") + " --relight-keys ] --frames 1", nullptr, &err), 0);
  EXPECT_NE(err.find("visibility"), std::string::npos) << err;
}

}  // namespace
}  // namespace pl
