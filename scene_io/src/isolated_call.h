// Running untrusted-input code in a child process. Private to scene_io/src.
//
// Assimp 5.2's readers crash (null dereferences, reads past arrays) or spin on some malformed
// files; a crash in-process would take rvr down with it, whatever the loader's checks (found by
// fuzzing, tests/fuzz/regressions/mesh). So imports run in a fork()ed child that sends its
// result back through a pipe: a child that dies, or runs past its CPU time, is an error for
// the parent, not a crash.
#pragma once

#include <functional>
#include <string>

namespace rvr::scene_load {

struct IsolatedResult {
  enum class Status { Ok, Crashed, OutOfTime, CannotStart };
  Status status = Status::CannotStart;
  std::string bytes;    // what the child wrote (complete when Ok)
  std::string problem;  // for the other statuses: how the child ended, in words
};

// Runs `work` in a child process with `cpu_seconds` of CPU time to start with (see
// extend_cpu_time) and returns the bytes it produced. `work` must not throw; the child ends
// with _exit, running no atexit handlers or static destructors.
IsolatedResult run_isolated(const std::function<std::string()>& work, double cpu_seconds);

// Inside an isolated child, grants `seconds` more CPU time (an importer opening another file);
// elsewhere does nothing.
void extend_cpu_time(double seconds);

}  // namespace rvr::scene_load
