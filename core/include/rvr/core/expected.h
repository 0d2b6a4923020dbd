// Error values for library APIs: libraries return errors, only the CLI prints and exits.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace rvr {

// Exit status the CLI uses for an error (see docs/cli.md). Cancelled: the work was asked to stop
// part way (ProgressSink::cancel) and returned no result; 130 is a shell's status for Ctrl-C.
// OutOfTime: a step was stopped at the end of the time it was given (the study's budget, which
// catches it: a command never exits with it); 124 is timeout(1)'s status.
enum class ErrorKind { BadInput = 2, Internal = 3, OutOfTime = 124, Cancelled = 130 };

struct Error {
  // Without the "error: " prefix, e.g. "scenes/bad.json: objects[3].radius: must be > 0, got -1".
  std::string message;
  ErrorKind kind = ErrorKind::BadInput;
};

inline Error bad_input(std::string message) {
  return Error{std::move(message), ErrorKind::BadInput};
}
inline Error internal_error(std::string message) {
  return Error{std::move(message), ErrorKind::Internal};
}
inline Error cancelled_error() {
  return Error{"cancelled", ErrorKind::Cancelled};
}
inline Error out_of_time_error(std::string message) {
  return Error{std::move(message), ErrorKind::OutOfTime};
}

// A value or an Error (std::expected is C++23).
template <class T>
class Expected {
 public:
  Expected(T value) : state_(std::move(value)) {}
  Expected(Error error) : state_(std::move(error)) {}

  bool ok() const { return state_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & { return std::get<0>(state_); }
  const T& value() const& { return std::get<0>(state_); }
  T&& value() && { return std::get<0>(std::move(state_)); }
  const Error& error() const { return std::get<1>(state_); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() { return value(); }
  const T& operator*() const { return value(); }

 private:
  std::variant<T, Error> state_;
};

// For operations that produce nothing but may fail.
struct Done {};
using Status = Expected<Done>;
inline Status ok_status() {
  return Done{};
}

}  // namespace rvr

// Error propagation, the one way every library writes it:
//   RVR_TRY(expr);              returns the error of an Expected or Status expression from the
//                               enclosing function (which returns an Expected or a Status);
//   RVR_TRY_ASSIGN(name, expr); declares `name`, the Expected that `expr` gives, and returns its
//                               error from the enclosing function when it holds one.
#define RVR_TRY(expr)                                                                    \
  do {                                                                                   \
    if (auto rvr_try_result_ = (expr); !rvr_try_result_) return rvr_try_result_.error(); \
  } while (0)

// `name` is a declarator, which parentheses would make an expression.
// NOLINTBEGIN(bugprone-macro-parentheses)
#define RVR_TRY_ASSIGN(name, expr) \
  auto name = (expr);              \
  if (!name) return name.error()
// NOLINTEND(bugprone-macro-parentheses)
