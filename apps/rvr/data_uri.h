// A file of the output folder as a data URI, so report.html needs nothing beside it. Private to
// apps/rvr.
#pragma once

#include <string>

#include "rvr/core/expected.h"

namespace rvr::report {

// The data URI of out_dir/file, or an error naming the path.
Expected<std::string> data_uri(const std::string& out_dir, const std::string& file);

}  // namespace rvr::report
