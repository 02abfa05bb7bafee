// trace and the image functions: read_image, write_image, write_video, tone_map,
// exposure_scale, compare (bindings.h).

#include <cstring>
#include <string>
#include <tuple>
#include <vector>

#include "bindings.h"
#include "core/error.h"
#include "image/compare.h"
#include "image/frame_output.h"

namespace pl::python {
namespace {

/// The exposure and tone-mapping keywords shared by exposure_scale, tone_map, write_image and
/// write_video (pictureSettings).
auto pictureArgs() {
  return std::make_tuple(py::arg("ev") = py::none(), py::arg("fstop") = py::none(), py::arg("shutter") = py::none(),
                         py::arg("iso") = py::none(), py::arg("tonemap") = "reinhard", py::arg("key") = py::none(),
                         py::arg("auto_key") = false, py::arg("white") = py::none());
}

/// Radiance as the 8-bit sRGB picture the command line writes to a PNG or an MP4 frame.
Image8 displayImage(const Image& radiance, const ViewSettings& view) {
  return toneMap(exposedCopy(radiance, view.exposureScale()), view.toneMapSettings());
}

void bindTrace(py::module_& m) {
  m.def(
      "trace",
      [](const Scene& scene, int width, int height, int spp, uint64_t seed, int threads, const py::object& camera,
         int maxDepth, bool variance) {
        TraceJobOptions options;
        options.sceneName = scene.sourcePath;
        options.trace.spp = spp;
        options.trace.seed = seed;
        options.trace.maxDepth = maxDepth;
        options.view = viewSettings(width, height, camera);
        options.threads = threads;
        const TraceJob job(std::move(options));
        const TraceJobResult result = runInterruptible([&] { return job.run(scene); });
        py::dict stats = statsDict(result.stats.toJson());
        if (variance) return py::make_tuple(toArray(result.radiance), stats, toArray(result.variance));
        return py::make_tuple(toArray(result.radiance), stats);
      },
      py::arg("scene"), py::arg("width") = 640, py::arg("height") = 480, py::arg("spp") = 64, py::arg("seed") = 0,
      py::arg("threads") = 0, py::arg("camera") = py::none(), py::arg("max_depth") = -1, py::arg("variance") = false,
      "Path-traces `scene` (what `plenoptic trace` does): returns (radiance, stats), or (radiance, stats, variance of\n"
      "the mean) with variance=True. radiance: float32 (height, width, 3), W/(sr m^2); stats: the --stats JSON.\n"
      "threads=0: all hardware threads. camera: a Camera, or a camera name of the scene (default: its first, else\n"
      "automatic).");
}

void bindPictures(py::module_& m) {
  std::apply(
      [&](auto... args) {
        m.def(
            "exposure_scale",
            [](OptFloat ev, OptFloat fstop, OptFloat shutter, OptFloat iso, const std::string& tonemap, OptFloat key,
               bool autoKey, OptFloat white) {
              return pictureSettings(ev, fstop, shutter, iso, tonemap, key, autoKey, white).exposureScale();
            },
            args...,
            "The factor from radiance to pixel value (camera/exposure.h): 1 with nothing given, 2^ev, or the ISO 12232\n"
            "saturation-based exposure of fstop, shutter (seconds) and iso (all three), times 2^ev.");
        m.def(
            "tone_map",
            [](const py::handle& image, OptFloat ev, OptFloat fstop, OptFloat shutter, OptFloat iso,
               const std::string& tonemap, OptFloat key, bool autoKey, OptFloat white) {
              const ViewSettings view = pictureSettings(ev, fstop, shutter, iso, tonemap, key, autoKey, white);
              const Image8 display = displayImage(fromArray(image, "tone_map"), view);
              py::array_t<uint8_t, py::array::c_style> array(
                  {py::ssize_t(display.height), py::ssize_t(display.width), py::ssize_t(3)});
              std::memcpy(array.mutable_data(), display.rgb.data(), display.rgb.size());
              return array;
            },
            py::arg("image"), args...,
            "Exposure and tone mapping as the command line's PNG output: uint8 (height, width, 3) sRGB. tonemap:\n"
            "reinhard (key: default 0.18 without an exposure, none with one; auto_key estimates it), linear, clamp;\n"
            "white: the luminance mapped to 1.");
        m.def(
            "write_image",
            [](const std::string& path, const py::handle& image, OptFloat ev, OptFloat fstop, OptFloat shutter,
               OptFloat iso, const std::string& tonemap, OptFloat key, bool autoKey, OptFloat white) {
              ViewSettings::checkImageOutput(path, "write_image");
              const ViewSettings view = pictureSettings(ev, fstop, shutter, iso, tonemap, key, autoKey, white);
              view.writeImage(path, fromArray(image, "write_image"));
            },
            py::arg("path"), py::arg("image"), args...,
            "Writes a (height, width, 3) radiance array (atomically): .exr, .hdr, .pfm get radiance times the\n"
            "exposure; .png the exposure, tone mapping and sRGB encoding (tone_map).");
        m.def(
            "write_video",
            [](const std::string& path, const py::object& frames, double fps, OptFloat ev, OptFloat fstop,
               OptFloat shutter, OptFloat iso, const std::string& tonemap, OptFloat key, bool autoKey, OptFloat white) {
              if (!isVideoOutput(path)) throw UsageError(fmt::format("write_video: {}: expected an .mp4 file name", path));
              if (!(fps > 0.0 && fps <= 1000.0)) throw UsageError(fmt::format("write_video: fps {} is out of range (0..1000]", fps));
              const ViewSettings view = pictureSettings(ev, fstop, shutter, iso, tonemap, key, autoKey, white);
              std::vector<Image8> pictures;
              for (const py::handle frame : py::iter(frames)) {
                pictures.push_back(displayImage(fromArray(frame, "write_video"), view));
                if (pictures.back().width != pictures.front().width || pictures.back().height != pictures.front().height)
                  throw UsageError(fmt::format("write_video: frame {} is {}x{}, frame 0 {}x{}", pictures.size() - 1,
                                               pictures.back().width, pictures.back().height, pictures.front().width,
                                               pictures.front().height));
              }
              if (pictures.empty()) throw UsageError("write_video: no frames");
              runInterruptible([&] {
                VideoWriter writer(path, pictures.front().width, pictures.front().height, fps);
                for (const Image8& picture : pictures) {
                  throwIfCancelled();  // Ctrl-C: the writer removes the partial video
                  writer.write(picture);
                }
                writer.finish();
              });
            },
            py::arg("path"), py::arg("frames"), py::arg("fps") = 30.0, args...,
            "Encodes radiance frames (each (height, width, 3), all of one size, even width and height) as an MP4 video\n"
            "with the ffmpeg program (H.264), as `plenoptic render --path ... -o walk.mp4` does: each frame gets the\n"
            "exposure, tone mapping and sRGB encoding of tone_map. The file appears whole or not at all.");
      },
      pictureArgs());

  m.def("read_image", [](const std::string& path) { return toArray(readImage(path)); }, py::arg("path"),
        "Reads .exr, .hdr, .pfm (linear) or .png/.jpg (sRGB-decoded): float32 (height, width, 3).");
  m.def(
      "compare",
      [](const py::handle& a, const py::handle& reference) {
        const ImageComparison c = compareImages(fromArray(a, "compare: a"), fromArray(reference, "compare: reference"));
        return statsDict(comparisonJson(c));
      },
      py::arg("a"), py::arg("reference"),
      "Compares two images as `plenoptic compare --json` does, with the same keys: relmse (mean over channels of\n"
      "(a-b)^2/(b^2+0.01)), relmse_rgb, rmse, mse_rgb, psnr (peak 1; None when the images are identical), identical,\n"
      "mean_ratio_rgb (mean a / mean b per channel), mean_luminance_ratio, max_abs_error, max_abs_error_pixel,\n"
      "nonfinite_pixels, width, height.");
}

}  // namespace

void bindImages(py::module_& m) {
  bindTrace(m);
  bindPictures(m);
}

}  // namespace pl::python
