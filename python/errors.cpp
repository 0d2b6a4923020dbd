#include "errors.h"

#include <Python.h>
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "stub_docs.h"

namespace rvr::python {

[[noreturn]] void raise(const Error& e) {
  if (e.kind == ErrorKind::BadInput) throw BadInputError(e.message);
  throw std::runtime_error(e.message);
}

void bind_errors(pybind11::module_& m) {
  auto& bad_input = pybind11::register_exception<BadInputError>(m, "BadInput", PyExc_ValueError);
  bad_input.attr("__doc__") = docs::BadInput;
}

}  // namespace rvr::python
