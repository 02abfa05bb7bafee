// The extension module plenoptic._plenoptic, which the package plenoptic (plenoptic/__init__.py)
// re-exports: one bind* call per topic (bindings.h says which file holds which).
#include "bindings.h"
#include "plenoptic_version.h"  // generated at build time (cmake/version.cmake)

PYBIND11_MODULE(_plenoptic, m) {
  using namespace pl::python;
  m.doc() =
      "plenoptic: physically based global illumination precomputed as a light field.\n"
      "Images are float32 arrays (height, width, 3) of linear Rec.709 radiance in W/(sr m^2).";
  // The version `plenoptic --version` prints: the project version, and the git revision built.
  m.attr("__version__") = PLENOPTIC_VERSION;
  m.attr("build") = PLENOPTIC_VERSION_STRING;
  bindErrors(m);
  bindProgress(m);
  bindScene(m);
  bindLightField(m);
  bindImages(m);
  bindEnv(m);
}
