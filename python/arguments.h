// Python arguments that take more than one form, converted for the libraries: a path as a str or
// an os.PathLike, one name or a sequence of names.
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <vector>

namespace rvr::python {

// os.fspath(value) for a str or an os.PathLike; else rvr.BadInput "NAME: expected EXPECTED, got
// TYPE".
std::string path_of(const char* name, const pybind11::handle& value,
                    const char* expected = "a path");

// A str as one name, or a sequence of str; else rvr.BadInput naming NAME.
std::vector<std::string> names_of(const char* name, const pybind11::handle& value);

// The Python type name of `value`, for messages: 'int', 'numpy.ndarray'.
std::string type_name(const pybind11::handle& value);

}  // namespace rvr::python
