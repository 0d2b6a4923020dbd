// The inferno colour bar (see colour_bar.h).
#include "colour_bar.h"

#include <sstream>
#include <string>
#include <vector>

#include "report_text.h"
#include "rvr/core/html_escape.h"

namespace rvr::report {
namespace {

// OpenImageIO's / matplotlib's inferno map at 0, 0.1, ..., 1 (sRGB), for the colour bars.
const char* kInfernoStops[] = {"#000004", "#160b39", "#420a68", "#6a176e", "#932667", "#bc3754",
                               "#dd513a", "#f37819", "#fca50a", "#f6d746", "#fcffa4"};

}  // namespace

std::string inferno_bar(const std::string& id, const std::string& label,
                        const std::vector<std::pair<double, std::string>>& ticks) {
  constexpr double kX0 = 10, kWidth = 300;
  std::ostringstream o;
  o << "<svg class=\"bar\" viewBox=\"0 0 320 40\" width=\"320\" height=\"40\" role=\"img\" "
       "aria-label=\""
    << escape_html(label) << "\"><defs><linearGradient id=\"" << id << "\">";
  for (int i = 0; i <= 10; ++i)
    o << "<stop offset=\"" << i * 10 << "%\" stop-color=\"" << kInfernoStops[i] << "\"/>";
  o << "</linearGradient></defs><rect x=\"" << kX0 << "\" y=\"2\" width=\"" << kWidth
    << "\" height=\"14\" fill=\"url(#" << id << ")\" stroke=\"#9aa3b5\" stroke-width=\"0.5\"/>";
  for (const auto& [pos, text] : ticks) {
    const double x = kX0 + pos * kWidth;
    o << "<line x1=\"" << x << "\" x2=\"" << x << "\" y1=\"16\" y2=\"21\" stroke=\"#4a5366\"/>"
      << "<text x=\"" << x << "\" y=\"33\" text-anchor=\""
      << (pos < 0.01   ? "start"
          : pos > 0.99 ? "end"
                       : "middle")
      << "\">" << text << "</text>";
  }
  o << "</svg>";
  return o.str();
}

}  // namespace rvr::report
