#include "numpy_views.h"

#include <utility>

#include "rvr/core/check.h"

namespace py = pybind11;

namespace rvr::python {

template <class T>
py::array_t<T> view(std::shared_ptr<const void> owner, const T* data, size_t elements,
                    const std::vector<py::ssize_t>& shape) {
  size_t covered = 1;
  for (py::ssize_t side : shape) {
    RVR_CHECK(side >= 0, "an array side is not negative: ", side);
    covered *= size_t(side);
  }
  RVR_CHECK(covered <= elements && (data != nullptr || covered == 0),
            "a numpy view stays inside its buffer: ", covered, " elements of ", elements);
  auto* held = new std::shared_ptr<const void>(std::move(owner));
  py::capsule base(held, [](void* p) { delete static_cast<std::shared_ptr<const void>*>(p); });
  py::array_t<T> array(shape, data, base);
  array.attr("setflags")(py::arg("write") = false);
  return array;
}

template py::array_t<float> view(std::shared_ptr<const void>, const float*, size_t,
                                 const std::vector<py::ssize_t>&);
template py::array_t<int32_t> view(std::shared_ptr<const void>, const int32_t*, size_t,
                                   const std::vector<py::ssize_t>&);
template py::array_t<uint8_t> view(std::shared_ptr<const void>, const uint8_t*, size_t,
                                   const std::vector<py::ssize_t>&);

}  // namespace rvr::python
