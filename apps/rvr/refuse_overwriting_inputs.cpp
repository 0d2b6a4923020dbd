// Refusing an output that names a folder or would overwrite an input (see commands.h).
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "cli_exit.h"
#include "commands.h"
#include "rvr/core/expected.h"

namespace rvr::cli {

void refuse_overwriting_inputs(const std::vector<std::string>& inputs,
                               const std::vector<std::string>& outputs) {
  for (const std::string& out : outputs) {
    std::error_code ec;
    if (out.empty()) continue;  // standard output
    if (!std::filesystem::path(out).has_filename() || std::filesystem::is_directory(out, ec))
      fail(bad_input("cannot write '" + out + "': is a directory"));
  }
  for (const std::string& out : outputs) {
    for (const std::string& in : inputs) {
      std::error_code ec;
      if (in.rfind("builtin:", 0) == 0 || !std::filesystem::exists(out, ec)) continue;
      if (std::filesystem::equivalent(out, in, ec))
        fail(bad_input(out + ": is also an input; writing it would destroy it"));
    }
  }
}

}  // namespace rvr::cli
