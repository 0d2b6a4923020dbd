// Whether two contiguous containers hold the same bytes (floats compared bit for bit, so -0 and
// +0 differ and a NaN equals itself). Empty containers may have a null data(), which memcmp
// must never see, even with a length of 0.
#pragma once

#include <cstring>

namespace rvr::test {

template <class V>
bool same_bytes(const V& a, const V& b) {
  if (a.size() != b.size()) return false;
  if (a.size() == 0) return true;
  return std::memcmp(a.data(), b.data(), a.size() * sizeof(typename V::value_type)) == 0;
}

}  // namespace rvr::test
