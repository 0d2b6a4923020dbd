// `import rvr`: render, compare and study from Python (docs/python.md).
#include <pybind11/pybind11.h>

#include "bindings.h"

PYBIND11_MODULE(rvr, m) {
  m.doc() =
      "rvr: one scene rendered with both loop orders (rasterization and ray tracing) and "
      "compared pixel by pixel. Frame buffers come back as numpy arrays.";
  m.attr("__version__") = RVR_VERSION;
  rvr::python::bind_errors(m);
  rvr::python::bind_scene(m);
  rvr::python::bind_render(m);
  rvr::python::bind_compare(m);
  rvr::python::bind_study(m);
}
