// The environment tools of `plenoptic env` (env/ibl.h) on lat-long arrays (height, 2·height, 3),
// the layout of `plenoptic env --layout latlong`, with the command line's ranges (bindings.h).

#include <string>
#include <variant>
#include <vector>

#include "bindings.h"
#include "core/error.h"
#include "env/ibl.h"

namespace pl::python {

void bindEnv(py::module_& m) {
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
      "(height, 2*height, 3) of radiance: float64 (9, 3), W/m^2 per unit basis.");
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
}

}  // namespace pl::python
