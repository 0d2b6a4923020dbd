#include "arguments.h"

#include <array>

#include "errors.h"

namespace py = pybind11;

namespace rvr::python {

std::string type_name(const py::handle& value) {
  const py::handle type = py::type::handle_of(value);
  const std::string module = py::cast<std::string>(type.attr("__module__"));
  const std::string name = py::cast<std::string>(type.attr("__qualname__"));
  return module == "builtins" ? name : module + "." + name;
}

std::string path_of(const char* name, const py::handle& value, const char* expected) {
  if (py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__")) {
    const py::object path = py::module_::import("os").attr("fspath")(value);
    if (py::isinstance<py::str>(path)) return py::cast<std::string>(path);
  }
  throw BadInputError(std::string(name) + ": expected " + expected + ", got " + type_name(value));
}

std::vector<std::string> names_of(const char* name, const py::handle& value) {
  if (py::isinstance<py::str>(value)) return {py::cast<std::string>(value)};
  std::vector<std::string> names;
  if (py::isinstance<py::sequence>(value)) {
    for (const py::handle item : py::reinterpret_borrow<py::sequence>(value)) {
      if (!py::isinstance<py::str>(item))
        throw BadInputError(std::string(name) + ": expected names (str), got " + type_name(item));
      names.push_back(py::cast<std::string>(item));
    }
    return names;
  }
  throw BadInputError(std::string(name) + ": expected a name or a sequence of names, got " +
                      type_name(value));
}

}  // namespace rvr::python
