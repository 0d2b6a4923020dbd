// The failure path of RVR_CHECK and RVR_DCHECK: one line on stderr naming the broken invariant,
// the caller's message and where the invariant is stated, then abort (so a core dump or a
// debugger stops in the caller's frame).
#include "rvr/core/check.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>  // IWYU pragma: keep (std::ostringstream; iwyu takes <ostream> for it)
#include <string>

namespace rvr::detail {
namespace {

std::ostringstream& failure_message() {
  thread_local std::ostringstream message;
  return message;
}

}  // namespace

CheckFailure::CheckFailure(const char* condition, const char* file, int line)
    : condition_(condition), file_(file), line_(line) {
  failure_message().str("");
}

std::ostream& CheckFailure::message() {
  return failure_message();
}

void CheckFailure::abort() {
  const std::string message = failure_message().str();
  const bool has_message = !message.empty();
  std::fprintf(stderr, "rvr: invariant broken: %s%s%s%s at %s:%d\n", condition_,
               has_message ? " (" : "", message.c_str(), has_message ? ")" : "", file_, line_);
  std::fflush(stderr);
  std::abort();
}

}  // namespace rvr::detail
