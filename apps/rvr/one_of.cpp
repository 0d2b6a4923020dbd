#include "one_of.h"

#include <fmt/format.h>

#include <algorithm>
#include <functional>

#include "suggest.h"

namespace rvr::cli {

CLI::Validator one_of(std::vector<std::string> names) {
  const std::string description = fmt::format("{}", fmt::join(names, "|"));
  return CLI::Validator(
      [names](std::string& value) -> std::string {
        if (std::find(names.begin(), names.end(), value) != names.end()) return "";
        return not_one_of(value, names);
      },
      description);
}

}  // namespace rvr::cli
