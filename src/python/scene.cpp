// plenoptic.Camera, plenoptic.Scene and load_scene (bindings.h). The Scene's lights are bound
// in lights.cpp.

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "bindings.h"
#include "camera/camera.h"
#include "core/error.h"

namespace pl::python {
namespace {

Vec3 toVec3(const std::vector<float>& v, const char* what) {
  if (v.size() != 3) throw UsageError(fmt::format("Camera: {} must be three numbers (x, y, z)", what));
  return Vec3(v[0], v[1], v[2]);
}

std::vector<float> fromVec3(const Vec3& v) { return {v.x, v.y, v.z}; }

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

/// "1 camera", "2 cameras".
std::string count(size_t n, const char* noun) { return fmt::format("{} {}{}", n, noun, n == 1 ? "" : "s"); }

}  // namespace

void bindScene(py::module_& m) {
  py::class_<CameraDesc>(m, "Camera",
                         "A camera: eye, target and up in scene units, vertical field of view in degrees, thin lens\n"
                         "f-number fstop (0 = pinhole) focused at focus_distance (scene units; 0 = the distance to target).")
      .def(py::init(&makeCamera), py::arg("eye"), py::arg("target"), py::arg("up") = std::vector<float>{0.0f, 1.0f, 0.0f},
           py::arg("fov") = 40.0f, py::arg("fstop") = 0.0f, py::arg("focus_distance") = 0.0f, py::arg("name") = "python")
      .def_property_readonly("name", [](const CameraDesc& c) { return c.name; })
      .def_property_readonly("eye", [](const CameraDesc& c) { return fromVec3(c.eye); }, "scene units")
      .def_property_readonly("target", [](const CameraDesc& c) { return fromVec3(c.target); }, "scene units")
      .def_property_readonly("up", [](const CameraDesc& c) { return fromVec3(c.up); })
      .def_property_readonly("fov", [](const CameraDesc& c) { return c.fovYDegrees; }, "vertical, degrees")
      .def_property_readonly("fstop", [](const CameraDesc& c) { return c.fNumber; }, "thin lens f-number (0 = pinhole)")
      .def_property_readonly("focus_distance", [](const CameraDesc& c) { return c.focusDistance; }, "scene units")
      .def("__repr__", [](const CameraDesc& c) {
        return fmt::format("plenoptic.Camera(eye=[{}, {}, {}], target=[{}, {}, {}], up=[{}, {}, {}], fov={}, fstop={}, "
                           "focus_distance={}, name='{}')",
                           c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z,
                           c.fovYDegrees, c.fNumber, c.focusDistance, c.name);
      });

  py::class_<Scene, std::shared_ptr<Scene>> scene(
      m, "Scene", "A loaded scene (units as in its file; the built-in Cornell box is in millimetres).");
  scene.def_property_readonly("source", [](const Scene& s) { return s.sourcePath; }, "'cornell' or the file it was loaded from")
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
      .def("set_albedo",
           [](Scene& s, const std::string& material, const std::vector<float>& rgb) {
             const Rgb albedo = nonNegative(toRgb(rgb, "set_albedo"), "set_albedo");
             if (albedo.r > 1.0f || albedo.g > 1.0f || albedo.b > 1.0f)
               throw UsageError("set_albedo: an albedo is at most 1 in every channel");
             for (Material& mat : s.materials)
               if (mat.name == material) {
                 mat.bsdf = withDiffuseAlbedo(mat.bsdf, albedo);
                 return;
               }
             throw UsageError(fmt::format("{}: no material '{}'", s.sourcePath, material));
           },
           py::arg("material"), py::arg("rgb"),
           "Sets the diffuse albedo (r, g, b) of a material (a Lambertian one's albedo; relight() takes only those)")
      .def("__repr__", [](const Scene& s) {
        return fmt::format("<plenoptic.Scene '{}': {}, {}, {}, {}>", s.sourcePath, count(s.triangleCount(), "triangle"),
                           count(s.materials.size(), "material"), count(s.cameras.size(), "camera"),
                           count(s.lights.size(), "light"));
      });
  bindLights(scene);

  m.def(
      "load_scene",
      [](const std::string& path) { return runInterruptible([&] { return std::make_shared<Scene>(loadScene(path)); }); },
      py::arg("path"), "Loads 'cornell' (built in) or a .obj, .gltf, .glb or .json scene.");
}

}  // namespace pl::python
