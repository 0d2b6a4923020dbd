// The --stats document of `rvr render` (docs/cli.md): what was rendered, the phase times, the
// renderer's counters, info and warnings, peak memory. The Python module's Render.stats is the
// same document.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include "rvr/core/renderer.h"
#include "rvr/core/stats.h"
#include "rvr/core/scene.h"

namespace rvr {

struct RenderTimes {
  double load = 0.0, render = 0.0, write = 0.0;  // seconds
};

// A stat of RenderOutput::stats as a JSON value (nlohmann::json or ordered_json): a count
// (stat_kind) as an integer, seconds and ratios as numbers, null when not finite (JSON has no
// infinity or NaN). A count that is not a whole number stays a number, so nothing is lost.
template <class Json>
Json stat_json(const std::string& name, double value) {
  if (!std::isfinite(value)) return Json();
  if (stat_kind(name) == StatKind::Count && value == std::floor(value) && std::fabs(value) < 0x1p63)
    return Json(int64_t(value));
  return Json(value);
}

// The document as JSON text, indented by two, ending in a newline.
std::string render_stats_json(const std::string& renderer, const Scene& scene, RenderMode mode,
                              const RenderTimes& times, const RenderOutput& out);

}  // namespace rvr
