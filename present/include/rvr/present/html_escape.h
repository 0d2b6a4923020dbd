// Text from data (scene names, renderer names, warnings) placed in an HTML page: report.html
// and study.html escape it the same way.
#pragma once

#include <string>

namespace rvr::present {

// `s` with & < > " ' replaced by their character references: safe in text and attributes.
std::string escape_html(const std::string& s);

}  // namespace rvr::present
