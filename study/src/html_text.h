// Text for study.html: data strings escaped, numbers with their powers of ten raised. Private
// to the study library.
#pragma once

#include <string>

#include "rvr/core/html_escape.h"

namespace rvr::study {

using ::rvr::escape_html;

// escape_html(s) with every "10^k" written as 10<sup>k</sup> (for HTML text).
std::string html_with_powers(const std::string& s);

// "10<tspan ...>k</tspan>": the label of the decade 10^k in an SVG chart.
std::string decade_svg(int k);

}  // namespace rvr::study
