// Seconds since a point on the steady clock: the one timer behind every phase time rvr reports.
// Ticks of the time-stamp counter, for shares of such a time measured in many short spans.
#pragma once

#include <x86intrin.h>

#include <chrono>
#include <cstdint>

namespace rvr {

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The processor's time-stamp counter: a few cycles to read, where steady_clock::now() costs a
// system-clock read (tens of nanoseconds under a hypervisor). Its rate is constant on the CPUs
// rvr runs on (invariant TSC), so ratios of tick sums are ratios of times; ticks are never
// reported as seconds.
inline uint64_t cycle_ticks() {
  return __rdtsc();
}

}  // namespace rvr
