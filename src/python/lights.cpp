// The Scene's lights in Python (bindings.h bindLights): the only binding code that knows the
// light types of scene/scene.h.

#include <type_traits>
#include <variant>
#include <vector>

#include "bindings.h"
#include "core/error.h"

namespace pl::python {

void bindLights(py::class_<Scene, std::shared_ptr<Scene>>& scene) {
  scene
      .def_property_readonly("light_count", [](const Scene& s) { return s.lights.size(); },
                             "point, spot and directional lights (emissive surfaces are materials)")
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
}

}  // namespace pl::python
