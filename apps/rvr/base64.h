// RFC 4648 base64, for the report's data URIs.
#pragma once

#include <string>

namespace rvr {

// RFC 4648 base64 (for data URIs).
std::string base64(const std::string& bytes);

}  // namespace rvr
