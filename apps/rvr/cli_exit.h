// Leaving the program with an error's exit status from any depth: the commands call fail, take
// and check; main catches Exit. Private to apps/rvr.
#pragma once

#include <utility>  // IWYU pragma: keep (std::move in take(), a template)

#include "rvr/core/expected.h"

namespace rvr::cli {

// Thrown inside this program only, to leave with an exit status from any depth.
struct Exit {
  int status;
};

// Prints "error: ..." and throws Exit with the error's status.
[[noreturn]] void fail(const Error& e);

template <class T>
T take(Expected<T> result) {
  if (!result) fail(result.error());
  return std::move(result).value();
}

void check(const Status& status);

}  // namespace rvr::cli
