// The Python module `plenoptic` (pybind11): a second front end over the library jobs of
// jobs/jobs.h, as the command line is the first. Images cross as NumPy float32 arrays of
// shape (height, width, 3), linear Rec.709 radiance in W·sr⁻¹·m⁻², top row first; stats cross
// as dicts holding exactly the --stats JSON of the matching command. Every call that does real
// work (trace, bake, render, reading and writing light fields, the environment tools) runs it
// through runInterruptible: the GIL is released meanwhile, and Ctrl-C raises KeyboardInterrupt.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/eval.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "camera/camera_path.h"
#include "core/cancel.h"
#include "core/error.h"
#include "env/env.h"
#include "env/ibl.h"
#include "image/compare.h"
#include "image/frame_output.h"
#include "image/image.h"
#include "jobs/jobs.h"
#include "plenoptic_version.h"  // generated at build time (cmake/version.cmake)
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

/// Runs `work` — library code only, no Python objects — on a worker thread while this thread
/// waits with the GIL released, taking it back every 50 ms to run Python's signal handlers
/// (PyErr_CheckSignals: they only run on the main thread, which is why the work may not run
/// here). When a handler raises — Ctrl-C's KeyboardInterrupt — cancellation is requested
/// (core/cancel.h): the job stops at its next cancellation point and unwinds, removing the
/// outputs it had not committed, and once the worker has stopped the handler's exception is
/// raised here (also if the job happened to finish first). Otherwise work's result, or its
/// exception, is passed on as if it had run on this thread.
template <typename Work>
auto runInterruptible(Work&& work) -> decltype(work()) {
  using Result = decltype(work());
  using Stored = std::conditional_t<std::is_void_v<Result>, bool, Result>;
  std::optional<Stored> result;
  std::exception_ptr failure;
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  std::thread worker([&] {
    try {
      if constexpr (std::is_void_v<Result>) {
        work();
        result.emplace(true);
      } else {
        result.emplace(work());
      }
    } catch (...) {
      failure = std::current_exception();
    }
    const std::lock_guard lock(mutex);
    done = true;
    finished.notify_one();
  });
  std::optional<py::error_already_set> interruption;
  for (;;) {
    bool stopped = false;
    {
      py::gil_scoped_release release;
      std::unique_lock lock(mutex);
      stopped = finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; });
    }
    if (stopped) break;
    if (!interruption && PyErr_CheckSignals() != 0) {
      interruption.emplace();  // takes the handler's exception off the interpreter
      requestCancellation();
    }
  }
  worker.join();
  if (interruption) {
    clearCancellation();
    throw *interruption;
  }
  if (failure) std::rethrow_exception(failure);
  if constexpr (!std::is_void_v<Result>) return std::move(*result);
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

Vec3 toVec3(const std::vector<float>& v, const char* what) {
  if (v.size() != 3) throw UsageError(fmt::format("Camera: {} must be three numbers (x, y, z)", what));
  return Vec3(v[0], v[1], v[2]);
}

/// A camera built in Python: pinhole (fstop 0) or thin lens, the scene's units. Checked here
/// (UsageError) with the renderers' own camera checks, so a bad camera fails when it is made.
CameraDesc makeCamera(const std::vector<float>& eye, const std::vector<float>& target, const std::vector<float>& up,
                      float fov, float fstop, float focusDistance, const std::string& name) {
  CameraDesc desc;
  desc.name = name;
  desc.eye = toVec3(eye, "eye");
  desc.target = toVec3(target, "target");
  desc.up = toVec3(up, "up");
  desc.fovYDegrees = fov;
  if (!(fstop >= 0.0f) || !std::isfinite(fstop))
    throw UsageError(fmt::format("Camera: fstop {} must be positive (or 0 for a pinhole)", fstop));
  if (!(focusDistance >= 0.0f) || !std::isfinite(focusDistance))
    throw UsageError(fmt::format("Camera: focus_distance {} must be positive (or 0 for the distance to the target)",
                                 focusDistance));
  desc.fNumber = fstop;
  desc.focusDistance = focusDistance;
  try {
    CameraDesc pinhole = desc;  // the lens needs the scene's unit, checked when rendering
    pinhole.fNumber = 0.0f;
    (void)Camera(pinhole, 1, 1, false, 1.0f);
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
  return desc;
}

/// The camera and image-size arguments shared by trace and render. camera: None (the scene's
/// default), a camera name of the scene (str) or a Camera.
ViewSettings viewSettings(int width, int height, const py::object& camera) {
  ViewSettings view;
  view.width = width;
  view.height = height;
  if (camera.is_none()) return view;
  if (py::isinstance<py::str>(camera)) view.camera = camera.cast<std::string>();
  else if (py::isinstance<CameraDesc>(camera)) view.cameraDesc = camera.cast<CameraDesc>();
  else throw py::value_error("camera: expected None, a camera name (str) or a plenoptic.Camera");
  return view;
}

/// A lat-long environment array (height, 2·height, 3), float32, radiance; ValueError otherwise.
LatLongMap envFromArray(const py::handle& object, const char* what) {
  LatLongMap map;
  map.image = fromArray(object, what);
  if (map.image.width != 2 * map.image.height)
    throw UsageError(fmt::format("{}: a lat-long environment must be twice as wide as high, got {}x{}", what,
                                 map.image.width, map.image.height));
  return map;
}

/// `value` within [low, high], else a UsageError naming `what` (the command line's ranges).
int inRange(int value, int low, int high, const char* what) {
  if (value < low || value > high) throw UsageError(fmt::format("{} {} is out of range ({}..{})", what, value, low, high));
  return value;
}

/// The exposure and tone-mapping keywords of exposure_scale, tone_map and write_image, as the
/// command line's --exposure/--fstop/--shutter/--iso/--tonemap/--key/--auto-key/--white.
ViewSettings pictureSettings(std::optional<float> ev, std::optional<float> fstop, std::optional<float> shutter,
                             std::optional<float> iso, const std::string& tonemap, std::optional<float> key, bool autoKey,
                             std::optional<float> white) {
  const int given = int(fstop.has_value()) + int(shutter.has_value()) + int(iso.has_value());
  if (given != 0 && given != 3)
    throw UsageError("fstop, shutter and iso: give all three (photographic exposure) or none");
  ViewSettings view;
  view.exposureEv = ev;
  view.fstop = fstop;
  view.shutterSeconds = shutter;
  view.iso = iso;
  view.tonemap = tonemap;
  view.key = key;
  view.autoKey = autoKey;
  view.white = white;
  try {
    (void)view.exposureScale();
    (void)view.toneMapSettings();
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
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
  // The version `plenoptic --version` prints: the project version, and the git revision built.
  m.attr("__version__") = PLENOPTIC_VERSION;
  m.attr("build") = PLENOPTIC_VERSION_STRING;

  // Errors: plenoptic.Error for every failure (the CLI's message, without 'plenoptic: error: '),
  // plenoptic.UsageError (also a ValueError) for a wrong request — what the CLI exits 2 for —
  // and plenoptic.FileError (also an OSError, with `filename`) for a file that cannot be opened,
  // read or written (pl::FileError).
  static py::exception<pl::Error> error(m, "Error", PyExc_RuntimeError);
  static py::handle usageError = [&] {
    py::object type = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
        "plenoptic.UsageError", "A wrong request (bad argument or value): the command line's usage errors.",
        py::make_tuple(error, py::handle(PyExc_ValueError)).ptr(), nullptr));
    m.attr("UsageError") = type;
    return type.release();
  }();
  static py::handle fileError = [&] {
    // Defined in Python for its __str__: the message alone, as for the other errors (OSError's
    // own str would print "[Errno None] None: 'filename'" once filename is set).
    py::dict scope;
    scope["__builtins__"] = py::module_::import("builtins");
    scope["Error"] = error;
    py::exec(R"(
class FileError(Error, OSError):
    """A file that cannot be opened, read or written; `filename` names it."""
    __module__ = "plenoptic"
    def __str__(self):
        return str(self.args[0]) if self.args else ""
)",
             scope);
    py::object type = scope["FileError"];
    m.attr("FileError") = type;
    return type.release();
  }();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const pl::FileError& e) {
      py::object exception = fileError(e.what());
      exception.attr("filename") = e.path();
      PyErr_SetObject(fileError.ptr(), exception.ptr());
    } catch (const pl::UsageError& e) {
      PyErr_SetString(usageError.ptr(), e.what());
    } catch (const pl::Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    }
  });

  py::class_<CameraDesc>(m, "Camera",
                         "A camera: eye, target and up in scene units, vertical field of view in degrees, thin lens\n"
                         "f-number fstop (0 = pinhole) focused at focus_distance (scene units; 0 = the distance to target).")
      .def(py::init(&makeCamera), py::arg("eye"), py::arg("target"), py::arg("up") = std::vector<float>{0.0f, 1.0f, 0.0f},
           py::arg("fov") = 40.0f, py::arg("fstop") = 0.0f, py::arg("focus_distance") = 0.0f, py::arg("name") = "python")
      .def_property_readonly("name", [](const CameraDesc& c) { return c.name; })
      .def_property_readonly("eye", [](const CameraDesc& c) { return std::vector<float>{c.eye.x, c.eye.y, c.eye.z}; })
      .def_property_readonly("target",
                             [](const CameraDesc& c) { return std::vector<float>{c.target.x, c.target.y, c.target.z}; })
      .def_property_readonly("up", [](const CameraDesc& c) { return std::vector<float>{c.up.x, c.up.y, c.up.z}; })
      .def_property_readonly("fov", [](const CameraDesc& c) { return c.fovYDegrees; }, "vertical, degrees")
      .def_property_readonly("fstop", [](const CameraDesc& c) { return c.fNumber; }, "thin lens f-number (0 = pinhole)")
      .def_property_readonly("focus_distance", [](const CameraDesc& c) { return c.focusDistance; }, "scene units")
      .def("__repr__", [](const CameraDesc& c) {
        return fmt::format("plenoptic.Camera(eye=[{}, {}, {}], target=[{}, {}, {}], up=[{}, {}, {}], fov={}, fstop={}, "
                           "focus_distance={}, name='{}')",
                           c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z,
                           c.fovYDegrees, c.fNumber, c.focusDistance, c.name);
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
                             "point, spot, directional, … lights (emissive surfaces are materials)")
      .def("camera", [](const Scene& s, const std::string& name) { return s.camera(name); }, py::arg("name"),
           "The scene's camera `name` as a Camera")
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
             setLightEmission(s.lights[index], nonNegative(toRgb(rgb, "set_light_color"), "set_light_color"));
           },
           py::arg("index"), py::arg("rgb"),
           "Sets light `index`'s intensity (W/sr) or, for a directional light, its irradiance (W/m^2)");

  m.def(
      "load_scene",
      [](const std::string& path) { return runInterruptible([&] { return std::make_shared<Scene>(loadScene(path)); }); },
      py::arg("path"),
      "Loads 'cornell' (built in) or a .obj, .gltf, .glb or .json scene.");

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

  py::class_<PyLightField>(m, "LightField", "A baked light field.")
      .def_readonly("stats", &PyLightField::stats, "The bake's --stats JSON as a dict (empty for a loaded file)")
      .def(
          "save",
          [](const PyLightField& lf, const std::string& path, const std::string& compress) {
            const ValuesCodec codec = parseValuesCodec(compress);
            runInterruptible([&] { writeLightField(path, *lf.lightField, codec); });
          },
          py::arg("path"), py::arg("compress") = "none", "Writes the .plf file (compress: none, lossless, bc1, hdr).")
      .def(
          "render",
          [](const PyLightField& lf, int width, int height, int samples, const py::object& camera, uint64_t seed,
             bool reference, int threads, bool textureLod) {
            RenderJobOptions options;
            options.render.samplesPerPixel = samples;
            options.render.seed = seed;
            options.render.textureLod = textureLod;
            options.reference = reference;
            options.view = viewSettings(width, height, camera);
            options.threads = threads;
            const RenderJob job(std::move(options));
            return toArray(runInterruptible([&] { return job.run(*lf.lightField).image; }));
          },
          py::arg("width") = 640, py::arg("height") = 480, py::arg("samples") = 0, py::arg("camera") = py::none(),
          py::arg("seed") = 0, py::arg("reference") = false, py::arg("threads") = 0, py::arg("texture_lod") = true,
          "Renders the light field (what `plenoptic render` does): float32 (height, width, 3), W/(sr m^2).\n"
          "samples=0: 1 per pixel for a pinhole camera, 16 for a thin lens. reference=True: the reference renderer.\n"
          "texture_lod=False: albedo textures at full resolution (`--texture-lod off`).\n"
          "camera: a Camera, or a camera name of the scene (default: its first, else automatic).")
      .def(
          "render_path",
          [](const PyLightField& lf, const py::object& path, int width, int height, int samples,
             const py::object& camera, uint64_t seed, bool reference, int threads, bool textureLod) {
            // The frames' cameras: a list of Cameras as they are, or a camera path file's frames
            // (camera/camera_path.h: frame k at t0 + k/fps) posed on `camera` (its lens, and
            // its fov where the path has none).
            std::vector<CameraDesc> cameras;
            const ViewSettings base = viewSettings(width, height, camera);
            if (py::isinstance<py::str>(path)) {
              const CameraPath cameraPath = loadCameraPath(path.cast<std::string>());
              const CameraDesc baseCamera = base.resolveCamera(lf.lightField->scene);
              for (int frame = 0; frame < cameraPath.frameCount(); ++frame)
                cameras.push_back(applyPose(baseCamera, cameraPath.at(cameraPath.frameTime(frame))));
            } else {
              for (const py::handle item : py::iter(path)) {
                if (!py::isinstance<CameraDesc>(item))
                  throw py::value_error("render_path: expected a camera path file name (str) or a list of plenoptic.Camera");
                cameras.push_back(item.cast<CameraDesc>());
              }
              if (cameras.empty()) throw UsageError("render_path: the list of cameras is empty");
            }
            const std::vector<Image> frames = runInterruptible([&] {
              std::vector<Image> images;
              for (const CameraDesc& frameCamera : cameras) {
                RenderJobOptions options;
                options.render.samplesPerPixel = samples;
                options.render.seed = seed;
                options.render.textureLod = textureLod;
                options.reference = reference;
                options.view = base;
                options.view.cameraDesc = frameCamera;
                options.threads = threads;
                images.push_back(RenderJob(std::move(options)).run(*lf.lightField).image);
              }
              return images;
            });
            py::list arrays;
            for (const Image& frame : frames) arrays.append(toArray(frame));
            return arrays;
          },
          py::arg("path"), py::arg("width") = 640, py::arg("height") = 480, py::arg("samples") = 0,
          py::arg("camera") = py::none(), py::arg("seed") = 0, py::arg("reference") = false, py::arg("threads") = 0,
          py::arg("texture_lod") = true,
          "Renders a walk-through: path is a camera path JSON file (what `plenoptic render --path` renders, frame k at\n"
          "t0 + k/fps, posed on `camera`) or a list of Cameras. Returns a list of float32 (height, width, 3) frames.");

  m.def(
      "bake",
      [](const Scene& scene, const std::string& preset, uint64_t seed, int threads, std::optional<std::string> visibility,
         bool reuseVisibility, bool sunMasks, bool punctualHighlights) {
        BakeJobOptions options;
        options.sunMasks = sunMasks;
        options.punctualHighlights = punctualHighlights;
        options.sceneName = scene.sourcePath;
        options.preset = preset;
        options.seed = seed;
        options.threads = threads;
        if (visibility) options.visibilityPath = *visibility;
        options.reuseVisibility = reuseVisibility;
        const BakeJob job(std::move(options));
        BakeJobResult result = runInterruptible([&] {
          // The bake keeps its scene (in the light field); a copy must be finalized again to
          // get the vertex padding Embree reads (scene.h), which also checks the edits.
          Scene copy = scene;
          copy.finalize();
          return job.run(std::move(copy));
        });
        PyLightField lf;
        lf.stats = statsDict(result.stats.toJson());
        lf.lightField = std::make_shared<const LightField>(std::move(result.lightField));
        return lf;
      },
      py::arg("scene"), py::arg("preset") = "default", py::arg("seed") = 0, py::arg("threads") = 0,
      py::arg("visibility") = py::none(), py::arg("reuse_visibility") = false, py::arg("sun_masks") = true,
      py::arg("punctual_highlights") = true,
      "Bakes `scene`'s light field (what `plenoptic bake` does). visibility: a .plv path where the visibility field\n"
      "is saved; with reuse_visibility=True it is read back when the geometry and settings match (so a bake after\n"
      "editing only lights or emission re-runs the propagation alone). sun_masks=False: `--sun-masks off`;\n"
      "punctual_highlights=False: `--punctual-highlights off`.");

  m.def(
      "load_light_field",
      [](const std::string& path) {
        PyLightField lf;
        lf.lightField = runInterruptible([&] { return std::make_shared<const LightField>(readLightField(path)); });
        return lf;
      },
      py::arg("path"), "Reads a .plf file.");

  m.def("read_image", [](const std::string& path) { return toArray(readImage(path)); }, py::arg("path"),
        "Reads .exr, .hdr, .pfm (linear) or .png/.jpg (sRGB-decoded): float32 (height, width, 3).");
  // The exposure and tone-mapping keywords shared by exposure_scale, tone_map and write_image.
  const auto pictureArgs = [] {
    return std::make_tuple(py::arg("ev") = py::none(), py::arg("fstop") = py::none(), py::arg("shutter") = py::none(),
                           py::arg("iso") = py::none(), py::arg("tonemap") = "reinhard", py::arg("key") = py::none(),
                           py::arg("auto_key") = false, py::arg("white") = py::none());
  };
  using OptFloat = std::optional<float>;
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
              const Image radiance = fromArray(image, "tone_map");
              const Image8 display = toneMap(exposedCopy(radiance, view.exposureScale()), view.toneMapSettings());
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
            "Writes a float32 (height, width, 3) radiance array (atomically): .exr, .hdr, .pfm get radiance times the\n"
            "exposure; .png the exposure, tone mapping and sRGB encoding (tone_map).");
      },
      pictureArgs());
  // Environment tools (env/ibl.h) on lat-long arrays (height, 2·height, 3), the layout of
  // `plenoptic env` with --layout latlong; the command line's ranges.
  constexpr int kMaxMapSize = 16384, kMaxSamples = 1 << 20;
  m.def(
      "sh9",
      [](const py::handle& env) {
        const EnvImage map = envFromArray(env, "sh9");
        const Sh9 sh = runInterruptible([&] { return projectSh9(map); });
        py::array_t<double, py::array::c_style> array({py::ssize_t(9), py::ssize_t(3)});
        for (int k = 0; k < 9; ++k)
          for (int c = 0; c < 3; ++c) array.mutable_at(k, c) = sh.coefficients[size_t(k)][c];
        return array;
      },
      py::arg("env"),
      "The 9 radiance SH coefficients (bands 0-2, Ramamoorthi-Hanrahan 2001 basis order) of a lat-long environment\n"
      "(height, 2*height, 3) float32 radiance: float64 (9, 3), W/m^2 per unit basis.");
  m.def(
      "irradiance",
      [](const py::handle& env, int size, const std::string& method) {
        if (method != "sh" && method != "brute") throw UsageError("irradiance: method must be 'sh' or 'brute'");
        inRange(size, 1, 4096, "irradiance: size");
        const EnvImage map = envFromArray(env, "irradiance");
        const EnvImage result = runInterruptible([&] {
          return method == "sh" ? irradianceFromSh(projectSh9(map), false, size) : irradianceBruteForce(map, false, size);
        });
        return toArray(std::get<LatLongMap>(result).image);
      },
      py::arg("env"), py::arg("size") = 32, py::arg("method") = "sh",
      "Irradiance E(n) = integral of L max(0, n.w) dw, W/m^2, at each texel direction of a lat-long map of height\n"
      "`size`: float32 (size, 2*size, 3). method: 'sh' (from sh9) or 'brute' (sum over every texel of env).");
  m.def(
      "prefilter",
      [](const py::handle& env, int levels, int height, int samples, const std::string& model) {
        PrefilterOptions options;
        if (model != "ggx" && model != "blinn-phong")
          throw UsageError(fmt::format("prefilter: unknown model '{}' (expected ggx or blinn-phong)", model));
        options.model = parseSpecularModel(model);
        options.levels = inRange(levels, 1, 32, "prefilter: levels");
        options.height = inRange(height, 4, kMaxMapSize, "prefilter: height");
        options.samples = inRange(samples, 1, kMaxSamples, "prefilter: samples");
        const EnvImage map = envFromArray(env, "prefilter");
        const std::vector<PrefilteredLevel> result = runInterruptible([&] { return prefilter(map, options); });
        py::list out;
        for (const PrefilteredLevel& level : result) out.append(py::make_tuple(level.roughness, toArray(level.map.image)));
        return out;
      },
      py::arg("env"), py::arg("levels") = 6, py::arg("height") = 128, py::arg("samples") = 1024,
      py::arg("model") = "ggx",
      "Prefiltered specular maps (split sum, Karis 2013): a list of (roughness, float32 lat-long radiance) for\n"
      "roughness k/(levels-1); level k has height `height` halved k times, not below 16. model: ggx, blinn-phong.");
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
