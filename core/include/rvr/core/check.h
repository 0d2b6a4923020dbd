// Invariant checks, for programmer errors only (bad input still returns an Expected/Status):
//   RVR_CHECK(cond, message parts...)   always on; cheap checks at boundaries and in builders.
//   RVR_DCHECK(cond, message parts...)  on where NDEBUG is not defined or RVR_ENABLE_DCHECK is
//                                       (debug builds, `make sanitize`, `make fuzz`): hot paths.
// A broken invariant prints "rvr: invariant broken: <cond> (<message>) at <file>:<line>" on stderr
// and aborts. The message parts are written with operator<<, only on failure. A disabled
// RVR_DCHECK still compiles its condition (so it cannot rot) but never evaluates it.
//
// The message is streamed by a lambda local to the caller into an ostream owned by check.cpp: no
// function template is instantiated at the call site, so the SIMD kernel units (which may define
// no external code, tests/check_kernel_symbols.sh) can use the checks too.
#pragma once

#include <ostream>

namespace rvr::detail {

// The failure being reported: construct, write the message to message(), then abort().
class CheckFailure {
 public:
  CheckFailure(const char* condition, const char* file, int line);
  CheckFailure(const CheckFailure&) = delete;
  CheckFailure& operator=(const CheckFailure&) = delete;
  std::ostream& message();
  [[noreturn]] void abort();

 private:
  const char* condition_;
  const char* file_;
  int line_;
};

}  // namespace rvr::detail

#define RVR_CHECK(cond, ...)                                                    \
  do {                                                                          \
    if (!(cond)) [[unlikely]] {                                                 \
      ::rvr::detail::CheckFailure rvr_check_failure(#cond, __FILE__, __LINE__); \
      [](std::ostream& rvr_out, const auto&... rvr_parts) {                     \
        ((rvr_out << rvr_parts), ...);                                          \
      }(rvr_check_failure.message() __VA_OPT__(, ) __VA_ARGS__);                \
      rvr_check_failure.abort();                                                \
    }                                                                           \
  } while (false)

#if !defined(NDEBUG) || defined(RVR_ENABLE_DCHECK)
#define RVR_DCHECK_IS_ON 1
#define RVR_DCHECK(cond, ...) RVR_CHECK(cond __VA_OPT__(, ) __VA_ARGS__)
#else
#define RVR_DCHECK_IS_ON 0
#define RVR_DCHECK(cond, ...)                              \
  do {                                                     \
    if (false) RVR_CHECK(cond __VA_OPT__(, ) __VA_ARGS__); \
  } while (false)
#endif
