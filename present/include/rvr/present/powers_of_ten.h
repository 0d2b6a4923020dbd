// Numbers written "2.1×10^6" in plain text (study.md, tooltips) with the power of ten raised
// when placed in a page: as <sup> in HTML text, as a raised <tspan> in SVG text.
#pragma once

#include <string>

namespace rvr::present {

// escape_html(s) with every "10^k" written as 10<sup>k</sup> (for HTML text).
std::string html_with_powers(const std::string& s);

// "10<tspan class="exp" ...>k</tspan>": the decade 10^k as SVG text (a log axis' tick label).
std::string decade_svg(int k);

}  // namespace rvr::present
