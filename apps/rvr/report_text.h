// Numbers and text as the report writes them. Private to apps/rvr.
#pragma once

#include <string>

#include "rvr/present/html_escape.h"

namespace rvr::report {

using ::rvr::present::escape_html;  // rvr/present/html_escape.h
// printf of one number, with n/a and infinity spelt out for HTML.
std::string fmt(const char* format, double v);
std::string fmt_seconds(double s);
// A number as people write it: 1e-6 rather than 1e-06 or 9.99999997e-07 (a float widened), and
// powers of ten of one form (1e-2 next to 1e-5, not 0.01).
std::string short_number(double v);
// Seconds as the timing chart labels them: three significant digits, always in seconds.
std::string fmt_s(double s);

}  // namespace rvr::report
