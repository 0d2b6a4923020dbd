#include "numpy_views.h"

#include <utility>

namespace py = pybind11;

namespace rvr::python {

template <class T>
py::array_t<T> view(std::shared_ptr<const void> owner, const T* data,
                    const std::vector<py::ssize_t>& shape) {
  auto* held = new std::shared_ptr<const void>(std::move(owner));
  py::capsule base(held, [](void* p) { delete static_cast<std::shared_ptr<const void>*>(p); });
  py::array_t<T> array(shape, data, base);
  array.attr("setflags")(py::arg("write") = false);
  return array;
}

template py::array_t<float> view(std::shared_ptr<const void>, const float*,
                                 const std::vector<py::ssize_t>&);
template py::array_t<int32_t> view(std::shared_ptr<const void>, const int32_t*,
                                   const std::vector<py::ssize_t>&);

}  // namespace rvr::python
