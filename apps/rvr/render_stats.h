// The --stats document of `rvr render` (docs/cli.md): what was rendered, the phase times, the
// renderer's counters, info and warnings, peak memory. The Python module's Render.stats is the
// same document.
#pragma once

#include <string>

#include "rvr/shared/renderer.h"
#include "rvr/shared/scene.h"

namespace rvr {

struct RenderTimes {
  double load = 0.0, render = 0.0, write = 0.0;  // seconds
};

// The document as JSON text, indented by two, ending in a newline.
std::string render_stats_json(const std::string& renderer, const Scene& scene, RenderMode mode,
                              const RenderTimes& times, const RenderOutput& out);

}  // namespace rvr
