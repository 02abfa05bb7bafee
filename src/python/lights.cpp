// The Scene's lights in Python (bindings.h bindLights): the lights' emission, set through the
// light module's one entry point (light/lights.h setLightEmission), whatever the light type.

#include <cmath>
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
           "Sets light `index`'s intensity (W/sr) or, for a directional light, its irradiance (W/m^2)")
      .def("set_light_direction",
           [](Scene& s, size_t index, const std::vector<float>& direction) {
             if (index >= s.lights.size())
               throw UsageError(fmt::format("{}: light {} does not exist ({} lights)", s.sourcePath, index, s.lights.size()));
             const Vec3 d = toRgb(direction, "set_light_direction");
             if (!(glm::length(d) > 0.0f) || !std::isfinite(glm::length(d)))
               throw UsageError("set_light_direction: the direction must be finite and not zero");
             Light light = s.lights[index];
             setLightParameters(light, {{"direction", d}}, fmt::format("{}: light {}", s.sourcePath, index));
             normaliseLightDirections(light);
             s.lights[index] = light;
           },
           py::arg("index"), py::arg("direction"),
           "Sets the direction light `index` travels (a directional or spot light; normalised), e.g. the sun's");
}

}  // namespace pl::python
