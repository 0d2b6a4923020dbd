// Numbers and text as the report writes them (see report_text.h).
#include "report_text.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <string>

namespace rvr::report {

std::string fmt(const char* format, double v) {
  if (std::isnan(v)) return "n/a";
  if (std::isinf(v)) return v > 0 ? "&infin;" : "&minus;&infin;";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string fmt_seconds(double s) {
  if (!std::isfinite(s)) return fmt("%g", s);
  if (s < 1e-3) return fmt("%.1f &micro;s", s * 1e6);
  if (s < 1.0) return fmt("%.2f ms", s * 1e3);
  return fmt("%.3f s", s);
}

// A number as people write it: 1e-6 rather than 1e-06 or 9.99999997e-07 (a float widened), and
// powers of ten of one form (1e-2 next to 1e-5, not 0.01).
std::string short_number(double v) {
  if (v > 0 && std::isfinite(v)) {
    const double e = std::round(std::log10(v));
    if (std::fabs(v / std::pow(10.0, e) - 1.0) < 1e-6 && std::fabs(e) >= 2)
      return "1e" + std::to_string(int(e));
  }
  std::string t = fmt("%.6g", v);
  for (const char* from : {"e-0", "e+0", "e+"}) {
    size_t at = t.find(from);
    if (at != std::string::npos) t.replace(at, std::strlen(from), from[1] == '-' ? "e-" : "e");
  }
  return t;
}

// Seconds as the timing chart labels them: three significant digits, always in seconds.
std::string fmt_s(double s) {
  return fmt("%.3g s", s);
}

}  // namespace rvr::report
