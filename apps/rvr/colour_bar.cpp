// The inferno colour bar (see colour_bar.h).
#include "colour_bar.h"

#include <string>
#include <vector>

#include "rvr/present/svg.h"

namespace rvr::report {
namespace {

// OpenImageIO's / matplotlib's inferno map at 0, 0.1, ..., 1 (sRGB), for the colour bars.
const char* kInfernoStops[] = {"#000004", "#160b39", "#420a68", "#6a176e", "#932667", "#bc3754",
                               "#dd513a", "#f37819", "#fca50a", "#f6d746", "#fcffa4"};

}  // namespace

std::string inferno_bar(const std::string& id, const std::string& label,
                        const std::vector<std::pair<double, std::string>>& ticks) {
  constexpr double kX0 = 10, kWidth = 300;
  std::string stops;
  for (int i = 0; i <= 10; ++i)
    stops += present::element(
        "stop", {{"offset", std::to_string(i * 10) + "%"}, {"stop-color", kInfernoStops[i]}});
  std::string o = "<defs>" + present::element("linearGradient", {{"id", id}}, stops) + "</defs>";
  o += present::rect({{"fill", "url(#" + id + ")"}, {"stroke", "#9aa3b5"}, {"stroke-width", "0.5"}},
                     kX0, 2, kWidth, 14);
  for (const auto& [pos, text] : ticks) {
    const double x = kX0 + pos * kWidth;
    o += present::line({{"stroke", "#4a5366"}}, x, 16, x, 21) +
         present::text({{"text-anchor", pos < 0.01   ? "start"
                                        : pos > 0.99 ? "end"
                                                     : "middle"}},
                       x, 33, text);
  }
  return present::element("svg",
                          {{"class", "bar"},
                           {"viewBox", "0 0 320 40"},
                           {"width", "320"},
                           {"height", "40"},
                           {"role", "img"},
                           {"aria-label", label}},
                          o);
}

}  // namespace rvr::report
