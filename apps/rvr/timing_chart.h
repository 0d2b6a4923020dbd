// The report's timing chart: per renderer its phases stacked in one bar, as inline SVG. Private
// to apps/rvr.
#pragma once

#include <string>
#include <vector>

#include "report.h"

namespace rvr::report {

// Inline SVG: per renderer one horizontal bar of its phases stacked, with labels and seconds;
// a <title> and <desc> carry the same numbers as text for screen readers, and every segment
// has a tooltip.
std::string timing_chart(const std::vector<ReportRenderer>& renderers);

}  // namespace rvr::report
