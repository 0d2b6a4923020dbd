// Leaving with an error's exit status (see cli_exit.h).
#include "cli_exit.h"

#include <cstdio>
#include <string>

#include "terminal_progress.h"

namespace rvr::cli {

[[noreturn]] void fail(const Error& e) {
  stop_active_progress();  // the error line starts a clean line, not the progress bar's
  std::fprintf(stderr, "error: %s\n", e.message.c_str());
  throw Exit{int(e.kind)};
}

void check(const Status& status) {
  if (!status) fail(status.error());
}

}  // namespace rvr::cli
