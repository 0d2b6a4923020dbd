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
        std::string message = fmt::format("'{}' is not one of {}", value, fmt::join(names, ", "));
        if (const std::string near = nearest(value, names); !near.empty())
          message += fmt::format(": did you mean '{}'?", near);
        return message;
      },
      description);
}

}  // namespace rvr::cli
