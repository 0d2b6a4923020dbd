// The parts of the Python module `rvr`, each registered on the module by its own file.
#pragma once

#include <pybind11/pybind11.h>

namespace rvr::python {

void bind_errors(pybind11::module_& m);   // errors.cpp: rvr.BadInput
void bind_scene(pybind11::module_& m);    // py_scene.cpp: rvr.Scene, rvr.scenes()
void bind_render(pybind11::module_& m);   // py_render.cpp: rvr.render, rvr.Render, renderers()
void bind_compare(pybind11::module_& m);  // py_compare.cpp: rvr.compare, rvr.diff
void bind_study(pybind11::module_& m);    // py_study.cpp: rvr.study

}  // namespace rvr::python
