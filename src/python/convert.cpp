// Conversions between Python and the library, argument checks and the progress setting
// (bindings.h).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "bindings.h"
#include "camera/exposure.h"
#include "core/error.h"
#include "core/progress.h"

namespace pl::python {

FloatArray toArray(const Image& image) {
  FloatArray array({py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(3)});
  std::memcpy(array.mutable_data(), image.pixels.data(), image.pixels.size() * sizeof(Rgb));
  return array;
}

Image fromArray(const py::handle& object, const char* what) {
  if (!py::isinstance<py::array>(object)) throw py::value_error(std::string(what) + ": expected a NumPy array");
  const py::array array = py::reinterpret_borrow<py::array>(object);
  // Floating dtypes only: an integer array is most likely an 8-bit picture, not radiance.
  if (array.dtype().kind() != 'f')
    throw py::value_error(std::string(what) + ": expected a floating-point array (float16, float32, float64), got dtype " +
                          std::string(py::str(array.dtype())));
  if (array.ndim() != 3 || array.shape(2) != 3)
    throw py::value_error(std::string(what) + ": expected shape (height, width, 3), got " +
                          std::string(py::str(py::tuple(py::cast(std::vector<py::ssize_t>(
                              array.shape(), array.shape() + array.ndim()))))));
  if (array.shape(0) < 1 || array.shape(1) < 1) throw py::value_error(std::string(what) + ": empty image");
  // A C-contiguous float32 copy (no copy when the array already is one): NumPy's casting
  // rounds float64 to nearest and widens float16 exactly.
  const py::array_t<float, py::array::c_style | py::array::forcecast> converted(array);
  Image image(int(array.shape(1)), int(array.shape(0)));
  std::memcpy(image.pixels.data(), converted.data(), image.pixels.size() * sizeof(Rgb));
  return image;
}

LatLongMap envFromArray(const py::handle& object, const char* what) {
  LatLongMap map;
  map.image = fromArray(object, what);
  if (map.image.width != 2 * map.image.height)
    throw UsageError(fmt::format("{}: a lat-long environment must be twice as wide as high, got {}x{}", what,
                                 map.image.width, map.image.height));
  return map;
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

int inRange(int value, int low, int high, const char* what) {
  if (value < low || value > high) throw UsageError(fmt::format("{} {} is out of range ({}..{})", what, value, low, high));
  return value;
}

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

ViewSettings pictureSettings(OptFloat ev, OptFloat fstop, OptFloat shutter, OptFloat iso, const std::string& tonemap,
                             OptFloat key, bool autoKey, OptFloat white) {
  (void)photographicExposure(fstop, shutter, iso, "fstop, shutter and iso");  // all three or none
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

namespace {

/// set_progress's setting: nullopt = automatic (a terminal only).
std::optional<bool> gProgressSetting;

/// True when both the process's stderr (where the library draws) and Python's sys.stderr
/// (which pytest, Jupyter or contextlib.redirect_stderr may have replaced) are a terminal.
bool stderrIsTerminal() {
  if (isatty(STDERR_FILENO) == 0) return false;
  try {
    const py::object stream = py::module_::import("sys").attr("stderr");
    return !stream.is_none() && py::hasattr(stream, "isatty") && stream.attr("isatty")().cast<bool>();
  } catch (const py::error_already_set&) {
    return false;  // a replacement stream whose isatty fails is no terminal
  }
}

}  // namespace

void applyProgressSetting() { Progress::setEnabled(gProgressSetting ? *gProgressSetting : stderrIsTerminal()); }

void bindProgress(py::module_& m) {
  m.def(
      "set_progress", [](std::optional<bool> enabled) { gProgressSetting = enabled; }, py::arg("enabled"),
      "Progress bars on stderr for the calls that do real work: True shows them, False never, None (the default)\n"
      "only when stderr is a terminal. On a terminal a bar redraws one line; elsewhere it prints a line per 10 %.");
  m.def(
      "get_progress", [] { return gProgressSetting; },
      "The progress setting of set_progress: True, False or None (automatic: only on a terminal).");
}

}  // namespace pl::python
