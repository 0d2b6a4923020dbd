// A chart's legend (div.legend): keys of a colour swatch or a small drawing, each with its
// words; and the swatch alone, as tables and captions use it.
#pragma once

#include <string>
#include <vector>

namespace rvr::present {

// A square of `colour` (a CSS colour) in line with text.
std::string swatch(const std::string& colour);

// A key: the swatch of `colour` and `words` (markup).
std::string swatch_key(const std::string& colour, const std::string& words);
// A key: `drawing` (SVG markup in a 30 × 14 box) and `words` (markup).
std::string drawing_key(const std::string& drawing, const std::string& words);
// A key of its own making (markup), as one of the legend's entries.
std::string custom_key(const std::string& css_class, const std::string& markup);

// The keys in a row that wraps.
std::string legend(const std::vector<std::string>& keys);

}  // namespace rvr::present
