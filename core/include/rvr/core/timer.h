// Seconds since a point on the steady clock: the one timer behind every phase time rvr reports.
#pragma once

#include <chrono>

namespace rvr {

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace rvr
