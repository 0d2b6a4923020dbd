// run_isolated: fork, a pipe, a CPU-time limit (see isolated_call.h).
#include "isolated_call.h"

#include <fmt/format.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>

namespace rvr::scene_load {
namespace {

bool g_in_child = false;

bool write_all(int fd, const char* data, size_t size) {
  while (size > 0) {
    ssize_t n = ::write(fd, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= size_t(n);
  }
  return true;
}

rlim_t whole_seconds(double s) {
  return s >= 1e9 ? rlim_t(1e9) : rlim_t(std::ceil(std::max(1.0, s)));
}

}  // namespace

void extend_cpu_time(double seconds) {
  if (!g_in_child) return;
  rlimit r{};
  if (getrlimit(RLIMIT_CPU, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return;
  r.rlim_cur += whole_seconds(seconds);
  if (r.rlim_max != RLIM_INFINITY && r.rlim_cur > r.rlim_max) r.rlim_cur = r.rlim_max;
  setrlimit(RLIMIT_CPU, &r);
}

IsolatedResult run_isolated(const std::function<std::string()>& work, double cpu_seconds) {
  IsolatedResult result;
  int fds[2];
  if (::pipe(fds) != 0) {
    result.problem = fmt::format("cannot make a pipe: {}", std::strerror(errno));
    return result;
  }
  pid_t pid = ::fork();
  if (pid < 0) {
    result.problem = fmt::format("cannot start a process: {}", std::strerror(errno));
    ::close(fds[0]);
    ::close(fds[1]);
    return result;
  }
  if (pid == 0) {
    // The child: only this thread exists here. No exit() (atexit handlers belong to the
    // parent), no exceptions out.
    ::close(fds[0]);
    g_in_child = true;
    // CPU time, not wall time: a loaded machine slows the child without failing it. Past the
    // soft limit SIGXCPU ends it; the hard limit stays open so extend_cpu_time can raise it.
    rlimit r{};
    getrlimit(RLIMIT_CPU, &r);
    r.rlim_cur = whole_seconds(cpu_seconds);
    if (r.rlim_max != RLIM_INFINITY && r.rlim_cur > r.rlim_max) r.rlim_cur = r.rlim_max;
    setrlimit(RLIMIT_CPU, &r);
    std::signal(SIGXCPU, SIG_DFL);
    std::string bytes = work();
    bool ok = write_all(fds[1], bytes.data(), bytes.size());
    ::close(fds[1]);
    ::_exit(ok ? 0 : 3);
  }
  ::close(fds[1]);
  char buffer[1 << 16];
  while (true) {
    ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    result.bytes.append(buffer, size_t(n));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    result.status = IsolatedResult::Status::Ok;
  } else if (WIFSIGNALED(status) && (WTERMSIG(status) == SIGXCPU || WTERMSIG(status) == SIGKILL)) {
    result.status = IsolatedResult::Status::OutOfTime;
    result.problem = fmt::format("ran out of its {:.0f} s of CPU time", cpu_seconds);
  } else {
    result.status = IsolatedResult::Status::Crashed;
    result.problem =
        WIFSIGNALED(status)
            ? fmt::format("crashed (signal {}, {})", WTERMSIG(status), strsignal(WTERMSIG(status)))
            : fmt::format("crashed (exit status {})", WEXITSTATUS(status));
  }
  return result;
}

}  // namespace rvr::scene_load
