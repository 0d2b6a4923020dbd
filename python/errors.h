// Library errors as Python exceptions: bad input raises rvr.BadInput (a ValueError) whose text
// is the message the command line prints after "error: "; an internal error raises
// RuntimeError.
#pragma once

#include <stdexcept>
#include <string>

#include "rvr/core/expected.h"

namespace rvr::python {

// Thrown by take() and check(); translated to rvr.BadInput (errors.cpp).
struct BadInputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] void raise(const Error& e);

template <class T>
T take(Expected<T> result) {
  if (!result) raise(result.error());
  return std::move(result).value();
}

inline void check(const Status& status) {
  if (!status) raise(status.error());
}

}  // namespace rvr::python
