// Read-only numpy arrays over a render's frame buffers, without a copy: each array's base is a
// capsule holding a reference to the buffers' owner, so an array outlives the rvr.Render it
// came from safely.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <stddef.h>

#include <memory>
#include <vector>

namespace rvr::python {

// `shape` (rows, columns[, channels]) over `data`, C order; `owner` is kept alive by the array.
// `elements`: how many T the buffer holds (the shape must not reach past them).
template <class T>
pybind11::array_t<T> view(std::shared_ptr<const void> owner, const T* data, size_t elements,
                          const std::vector<pybind11::ssize_t>& shape);

extern template pybind11::array_t<float> view(std::shared_ptr<const void>, const float*, size_t,
                                              const std::vector<pybind11::ssize_t>&);
extern template pybind11::array_t<int32_t> view(std::shared_ptr<const void>, const int32_t*, size_t,
                                                const std::vector<pybind11::ssize_t>&);
extern template pybind11::array_t<uint8_t> view(std::shared_ptr<const void>, const uint8_t*, size_t,
                                                const std::vector<pybind11::ssize_t>&);

}  // namespace rvr::python
