// The Scene's lights in Python (bindings.h bindLights): the lights' emission, set through the
// light module's one entry point (light/lights.h setLightEmission), whatever the light type.

#include <vector>

#include "bindings.h"
#include "core/error.h"
#include "light/lights.h"

namespace pl::python {

void bindLights(py::class_<Scene, std::shared_ptr<Scene>>& scene) {
  scene
      .def_property_readonly("light_count", [](const Scene& s) { return s.lights.size(); },
                             "point, spot, directional, … lights (emissive surfaces are materials)")
      .def("set_light_color",
           [](Scene& s, size_t index, const std::vector<float>& rgb) {
             if (index >= s.lights.size())
               throw UsageError(fmt::format("{}: light {} does not exist ({} lights)", s.sourcePath, index, s.lights.size()));
             setLightEmission(s.lights[index], nonNegative(toRgb(rgb, "set_light_color"), "set_light_color"));
           },
           py::arg("index"), py::arg("rgb"),
           "Sets light `index`'s intensity (W/sr) or, for a directional light, its irradiance (W/m^2)");
}

}  // namespace pl::python
