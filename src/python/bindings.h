#pragma once
// The pieces of the Python extension `plenoptic._plenoptic` (pybind11), a second front end
// over the library jobs of jobs/jobs.h as the command line is the first. module.cpp defines
// the module and calls one bind* function per topic:
//   errors.cpp     plenoptic.Error, UsageError, FileError and the C++ → Python translation
//   scene.cpp      Camera, Scene, load_scene (lights.cpp: the Scene's light bindings)
//   lightfield.cpp bake, LightField (save, render, render_path), load_light_field
//   images.cpp     trace, read_image, write_image, write_video, tone_map, exposure_scale, compare
//   env.cpp        sh9, irradiance, prefilter (the tools of `plenoptic env`)
// and this header, with convert.cpp, holds what they share: array conversions, argument
// checks, the progress setting and runInterruptible.
//
// Conventions: images cross as NumPy float32 arrays of shape (height, width, 3), linear
// Rec.709 radiance in W·sr⁻¹·m⁻², top row first (any floating dtype and memory layout is
// accepted and converted); stats cross as dicts holding exactly the --stats JSON of the
// matching command. Every call that does real work runs it through runInterruptible: the GIL
// is released meanwhile, and Ctrl-C raises KeyboardInterrupt.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>  // in every file: the type casters must be the same everywhere

#include <chrono>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/cancel.h"
#include "env/env.h"
#include "image/image.h"
#include "jobs/jobs.h"
#include "scene/scene.h"

namespace pl::python {

namespace py = pybind11;

using FloatArray = py::array_t<float, py::array::c_style>;
using OptFloat = std::optional<float>;

void bindErrors(py::module_& m);
/// Camera and Scene (with bindLights), load_scene.
void bindScene(py::module_& m);
/// The Scene's light bindings (light_count, set_light_color), kept apart from the rest of the
/// Scene so that the light model can change in one place.
void bindLights(py::class_<Scene, std::shared_ptr<Scene>>& scene);
void bindLightField(py::module_& m);
void bindImages(py::module_& m);
void bindEnv(py::module_& m);
/// plenoptic.set_progress and plenoptic.get_progress.
void bindProgress(py::module_& m);

// ---------------------------------------------------------------------------------------
// Conversions (convert.cpp).

/// An Image as a new (height, width, 3) float32 array.
FloatArray toArray(const Image& image);
/// A (height, width, 3) array of any floating dtype (float16, float32, float64, longdouble)
/// and any layout (Fortran order, strided views, negative strides) as an Image, converted to
/// float32; a ValueError naming `what` for anything else: not a NumPy array, an integer or
/// other non-floating dtype (an 8-bit image is not radiance), another shape, an empty image.
Image fromArray(const py::handle& object, const char* what);
/// A lat-long environment array (height, 2·height, 3), radiance, as fromArray converts it.
LatLongMap envFromArray(const py::handle& object, const char* what);
/// A dict from a JSON text (the stats of the jobs, the comparison of compare).
py::dict statsDict(const std::string& json);
/// Three numbers as Rgb; UsageError naming `what` otherwise.
Rgb toRgb(const std::vector<float>& v, const char* what);
/// `value` when finite and non-negative; UsageError naming `what` otherwise.
Rgb nonNegative(const Rgb& value, const char* what);
/// `value` within [low, high], else a UsageError naming `what` (the command line's ranges).
int inRange(int value, int low, int high, const char* what);
/// The camera and image-size arguments shared by trace and render. camera: None (the scene's
/// default), a camera name of the scene (str) or a Camera.
ViewSettings viewSettings(int width, int height, const py::object& camera);
/// The exposure and tone-mapping keywords of exposure_scale, tone_map, write_image and
/// write_video, as the command line's --exposure/--fstop/--shutter/--iso/--tonemap/--key/
/// --auto-key/--white; checked (UsageError).
ViewSettings pictureSettings(OptFloat ev, OptFloat fstop, OptFloat shutter, OptFloat iso, const std::string& tonemap,
                             OptFloat key, bool autoKey, OptFloat white);

// ---------------------------------------------------------------------------------------
// Progress bars (convert.cpp). The library draws them on stderr (core/progress.h); from
// Python they are shown when plenoptic.set_progress(True) was called, never after
// set_progress(False), and by default (None) only when both the process's stderr and
// sys.stderr are a terminal — so captured output (pytest, Jupyter, a pipe) holds none.

/// Enables or silences the library's progress bars for the call about to run, as the setting
/// and the terminal say. Needs the GIL (it reads sys.stderr).
void applyProgressSetting();

// ---------------------------------------------------------------------------------------

/// Runs `work` — library code only, no Python objects — on a worker thread while this thread
/// waits with the GIL released, taking it back every 50 ms to run Python's signal handlers
/// (PyErr_CheckSignals: they only run on the main thread, which is why the work may not run
/// here). When a handler raises — Ctrl-C's KeyboardInterrupt — cancellation is requested
/// (core/cancel.h): the job stops at its next cancellation point and unwinds, removing the
/// outputs it had not committed, and once the worker has stopped the handler's exception is
/// raised here (also if the job happened to finish first). Otherwise work's result, or its
/// exception, is passed on as if it had run on this thread. The progress setting is applied
/// first (applyProgressSetting).
template <typename Work>
auto runInterruptible(Work&& work) -> decltype(work()) {
  using Result = decltype(work());
  using Stored = std::conditional_t<std::is_void_v<Result>, bool, Result>;
  applyProgressSetting();
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

}  // namespace pl::python
