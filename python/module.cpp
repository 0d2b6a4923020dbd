// `import rvr`: render, compare and study from Python (docs/python.md).
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "stub_docs.h"

PYBIND11_MODULE(rvr, m) {
  m.doc() = rvr::python::docs::module;
  m.attr("__version__") = RVR_VERSION;
  rvr::python::bind_errors(m);
  rvr::python::bind_scene(m);
  rvr::python::bind_render(m);
  rvr::python::bind_compare(m);
  rvr::python::bind_study(m);
}
