// The inferno colour bar under the heat maps, as inline SVG. Private to apps/rvr.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace rvr::report {

// An inline SVG colour bar of the inferno map with labelled ticks (position in [0, 1], text),
// so a heat map can be read without the caption.
std::string inferno_bar(const std::string& id, const std::string& label,
                        const std::vector<std::pair<double, std::string>>& ticks);

}  // namespace rvr::report
