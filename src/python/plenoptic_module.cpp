// The Python module `plenoptic` (pybind11): a second front end over the library jobs of
// jobs/jobs.h, as the command line is the first. Images cross as NumPy float32 arrays of
// shape (height, width, 3), linear Rec.709 radiance in W·sr⁻¹·m⁻², top row first; stats cross
// as dicts holding exactly the --stats JSON of the matching command. The GIL is released while
// a trace, bake or render runs.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "core/error.h"
#include "image/compare.h"
#include "image/image.h"
#include "jobs/jobs.h"
#include "plf/compression.h"
#include "plf/plf_file.h"
#include "scene/scene.h"

namespace py = pybind11;

namespace pl {
namespace {

using FloatArray = py::array_t<float, py::array::c_style>;

/// An Image as a new (height, width, 3) float32 array.
FloatArray toArray(const Image& image) {
  FloatArray array({py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(3)});
  std::memcpy(array.mutable_data(), image.pixels.data(), image.pixels.size() * sizeof(Rgb));
  return array;
}

/// A (height, width, 3) float32 array as an Image; anything else is a ValueError naming `what`
/// (no conversion from other dtypes or layouts: they would hide a caller's mistake).
Image fromArray(const py::handle& object, const char* what) {
  if (!py::isinstance<py::array>(object)) throw py::value_error(std::string(what) + ": expected a NumPy array");
  const py::array array = py::reinterpret_borrow<py::array>(object);
  if (!array.dtype().is(py::dtype::of<float>()))
    throw py::value_error(std::string(what) + ": expected dtype float32, got " + std::string(py::str(array.dtype())));
  if (array.ndim() != 3 || array.shape(2) != 3)
    throw py::value_error(std::string(what) + ": expected shape (height, width, 3), got " +
                          std::string(py::str(py::tuple(py::cast(std::vector<py::ssize_t>(
                              array.shape(), array.shape() + array.ndim()))))));
  if (array.shape(0) < 1 || array.shape(1) < 1) throw py::value_error(std::string(what) + ": empty image");
  if (!(array.flags() & py::array::c_style))
    throw py::value_error(std::string(what) + ": expected a C-contiguous array (use numpy.ascontiguousarray)");
  Image image(int(array.shape(1)), int(array.shape(0)));
  std::memcpy(image.pixels.data(), array.data(), image.pixels.size() * sizeof(Rgb));
  return image;
}

py::dict statsDict(const std::string& json) { return py::module_::import("json").attr("loads")(json); }

Rgb toRgb(const std::vector<float>& v, const char* what) {
  if (v.size() != 3) throw py::value_error(std::string(what) + ": expected three numbers (r, g, b)");
  return Rgb(v[0], v[1], v[2]);
}

Rgb nonNegative(const Rgb& value, const char* what) {
  if (!isFinite(value) || std::min(value.r, std::min(value.g, value.b)) < 0.0f)
    throw UsageError(std::string(what) + ": expected finite, non-negative numbers");
  return value;
}

/// The camera and image-size arguments shared by trace and render.
ViewSettings viewSettings(int width, int height, const std::optional<std::string>& camera) {
  ViewSettings view;
  view.width = width;
  view.height = height;
  if (camera) view.camera = *camera;
  return view;
}

/// A baked or loaded light field, shared by the Python objects that refer to it.
struct PyLightField {
  std::shared_ptr<const LightField> lightField;
  py::dict stats;  ///< the bake's --stats JSON (empty for a loaded file)
};

}  // namespace
}  // namespace pl

PYBIND11_MODULE(plenoptic, m) {
  using namespace pl;
  m.doc() =
      "plenoptic: physically based global illumination precomputed as a light field.\n"
      "Images are float32 arrays (height, width, 3) of linear Rec.709 radiance in W/(sr m^2).";

  // Errors: plenoptic.Error for every failure (the CLI's message, without 'plenoptic: error: '),
  // plenoptic.UsageError (also a ValueError) for a wrong request — what the CLI exits 2 for.
  static py::exception<pl::Error> error(m, "Error", PyExc_RuntimeError);
  static py::handle usageError = [&] {
    py::object type = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
        "plenoptic.UsageError", "A wrong request (bad argument or value): the command line's usage errors.",
        py::make_tuple(error, py::handle(PyExc_ValueError)).ptr(), nullptr));
    m.attr("UsageError") = type;
    return type.release();
  }();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const pl::UsageError& e) {
      PyErr_SetString(usageError.ptr(), e.what());
    } catch (const pl::Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    }
  });

  py::class_<Scene, std::shared_ptr<Scene>>(m, "Scene", "A loaded scene (units as in its file; the built-in Cornell box is in millimetres).")
      .def_property_readonly("source", [](const Scene& s) { return s.sourcePath; }, "'cornell' or the file it was loaded from")
      .def_property_readonly("triangle_count", &Scene::triangleCount)
      .def_property_readonly("material_names",
                             [](const Scene& s) {
                               std::vector<std::string> names;
                               for (const Material& mat : s.materials) names.push_back(mat.name);
                               return names;
                             })
      .def_property_readonly("camera_names",
                             [](const Scene& s) {
                               std::vector<std::string> names;
                               for (const CameraDesc& c : s.cameras) names.push_back(c.name);
                               return names;
                             })
      .def_property_readonly("light_count", [](const Scene& s) { return s.lights.size(); },
                             "point, spot and directional lights (emissive surfaces are materials)")
      .def("emission",
           [](const Scene& s, const std::string& material) {
             for (const Material& mat : s.materials)
               if (mat.name == material) return std::vector<float>{mat.emission.r, mat.emission.g, mat.emission.b};
             throw UsageError(fmt::format("{}: no material '{}'", s.sourcePath, material));
           },
           py::arg("material"), "Emitted radiance (r, g, b) of a material, W/(sr m^2)")
      .def("set_emission",
           [](Scene& s, const std::string& material, const std::vector<float>& rgb) {
             for (Material& mat : s.materials)
               if (mat.name == material) {
                 mat.emission = nonNegative(toRgb(rgb, "set_emission"), "set_emission");
                 return;
               }
             throw UsageError(fmt::format("{}: no material '{}'", s.sourcePath, material));
           },
           py::arg("material"), py::arg("rgb"), "Sets the emitted radiance (r, g, b) of a material, W/(sr m^2)")
      .def("set_light_color",
           [](Scene& s, size_t index, const std::vector<float>& rgb) {
             if (index >= s.lights.size())
               throw UsageError(fmt::format("{}: light {} does not exist ({} lights)", s.sourcePath, index, s.lights.size()));
             const Rgb value = nonNegative(toRgb(rgb, "set_light_color"), "set_light_color");
             std::visit(
                 [&](auto& light) {
                   using T = std::decay_t<decltype(light)>;
                   if constexpr (std::is_same_v<T, DirectionalLight>) light.irradiance = value;
                   else light.intensity = value;
                 },
                 s.lights[index]);
           },
           py::arg("index"), py::arg("rgb"),
           "Sets light `index`'s intensity (point, spot: W/sr) or irradiance (directional: W/m^2)");

  m.def("load_scene", [](const std::string& path) { return std::make_shared<Scene>(loadScene(path)); }, py::arg("path"),
        "Loads 'cornell' (built in) or a .obj, .gltf, .glb or .json scene.");

  m.def(
      "trace",
      [](const Scene& scene, int width, int height, int spp, uint64_t seed, int threads, std::optional<std::string> camera,
         int maxDepth, bool variance) {
        TraceJobOptions options;
        options.sceneName = scene.sourcePath;
        options.trace.spp = spp;
        options.trace.seed = seed;
        options.trace.maxDepth = maxDepth;
        options.view = viewSettings(width, height, camera);
        options.threads = threads;
        TraceJobResult result;
        {
          const TraceJob job(std::move(options));
          py::gil_scoped_release release;
          result = job.run(scene);
        }
        py::dict stats = statsDict(result.stats.toJson());
        if (variance) return py::make_tuple(toArray(result.radiance), stats, toArray(result.variance));
        return py::make_tuple(toArray(result.radiance), stats);
      },
      py::arg("scene"), py::arg("width") = 640, py::arg("height") = 480, py::arg("spp") = 64, py::arg("seed") = 0,
      py::arg("threads") = 0, py::arg("camera") = py::none(), py::arg("max_depth") = -1, py::arg("variance") = false,
      "Path-traces `scene` (what `plenoptic trace` does): returns (radiance, stats), or (radiance, stats, variance of\n"
      "the mean) with variance=True. radiance: float32 (height, width, 3), W/(sr m^2); stats: the --stats JSON.\n"
      "threads=0: all hardware threads. camera: a camera name of the scene (default: its first, else automatic).");

  py::class_<PyLightField>(m, "LightField", "A baked light field.")
      .def_readonly("stats", &PyLightField::stats, "The bake's --stats JSON as a dict (empty for a loaded file)")
      .def(
          "save",
          [](const PyLightField& lf, const std::string& path, const std::string& compress) {
            const ValuesCodec codec = parseValuesCodec(compress);
            py::gil_scoped_release release;
            writeLightField(path, *lf.lightField, codec);
          },
          py::arg("path"), py::arg("compress") = "none", "Writes the .plf file (compress: none, lossless, bc1, hdr).")
      .def(
          "render",
          [](const PyLightField& lf, int width, int height, int samples, std::optional<std::string> camera, uint64_t seed,
             bool reference, int threads) {
            RenderJobOptions options;
            options.render.samplesPerPixel = samples;
            options.render.seed = seed;
            options.reference = reference;
            options.view = viewSettings(width, height, camera);
            options.threads = threads;
            RenderJobResult result;
            {
              const RenderJob job(std::move(options));
              py::gil_scoped_release release;
              result = job.run(*lf.lightField);
            }
            return toArray(result.image);
          },
          py::arg("width") = 640, py::arg("height") = 480, py::arg("samples") = 0, py::arg("camera") = py::none(),
          py::arg("seed") = 0, py::arg("reference") = false, py::arg("threads") = 0,
          "Renders the light field (what `plenoptic render` does): float32 (height, width, 3), W/(sr m^2).\n"
          "samples=0: 1 per pixel for a pinhole camera, 16 for a thin lens. reference=True: the reference renderer.");

  m.def(
      "bake",
      [](const Scene& scene, const std::string& preset, uint64_t seed, int threads, std::optional<std::string> visibility,
         bool reuseVisibility) {
        BakeJobOptions options;
        options.sceneName = scene.sourcePath;
        options.preset = preset;
        options.seed = seed;
        options.threads = threads;
        if (visibility) options.visibilityPath = *visibility;
        options.reuseVisibility = reuseVisibility;
        BakeJobResult result;
        {
          const BakeJob job(std::move(options));
          py::gil_scoped_release release;
          // The bake keeps its scene (in the light field); a copy must be finalized again to
          // get the vertex padding Embree reads (scene.h), which also checks the edits.
          Scene copy = scene;
          copy.finalize();
          result = job.run(std::move(copy));
        }
        PyLightField lf;
        lf.stats = statsDict(result.stats.toJson());
        lf.lightField = std::make_shared<const LightField>(std::move(result.lightField));
        return lf;
      },
      py::arg("scene"), py::arg("preset") = "default", py::arg("seed") = 0, py::arg("threads") = 0,
      py::arg("visibility") = py::none(), py::arg("reuse_visibility") = false,
      "Bakes `scene`'s light field (what `plenoptic bake` does). visibility: a .plv path where the visibility field\n"
      "is saved; with reuse_visibility=True it is read back when the geometry and settings match (so a bake after\n"
      "editing only lights or emission re-runs the propagation alone).");

  m.def(
      "load_light_field",
      [](const std::string& path) {
        PyLightField lf;
        py::gil_scoped_release release;
        lf.lightField = std::make_shared<const LightField>(readLightField(path));
        return lf;
      },
      py::arg("path"), "Reads a .plf file.");

  m.def("read_image", [](const std::string& path) { return toArray(readImage(path)); }, py::arg("path"),
        "Reads .exr, .hdr, .pfm (linear) or .png/.jpg (sRGB-decoded): float32 (height, width, 3).");
  m.def(
      "write_image", [](const std::string& path, const py::handle& image) { writeHdrImage(path, fromArray(image, "write_image")); },
      py::arg("path"), py::arg("image"), "Writes a float32 (height, width, 3) array as .exr, .hdr or .pfm (atomically).");
  m.def(
      "compare",
      [](const py::handle& a, const py::handle& reference) {
        const ImageComparison c = compareImages(fromArray(a, "compare: a"), fromArray(reference, "compare: reference"));
        py::dict d;
        d["rel_mse"] = c.relMseAverage;
        d["rel_mse_rgb"] = c.relMse;
        d["rmse"] = c.rmse;
        d["psnr"] = c.psnr;
        d["mean_ratio_rgb"] = c.meanRatio;
        d["mean_luminance_ratio"] = c.meanLuminanceRatio;
        d["non_finite_pixels"] = c.nonFinitePixels;
        return d;
      },
      py::arg("a"), py::arg("reference"),
      "Compares two images as `plenoptic compare` does: rel_mse (mean over channels of (a-b)^2/(b^2+0.01)), rmse,\n"
      "psnr (peak 1), mean ratios a/b per channel and of luminance.");
}
