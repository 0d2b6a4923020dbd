// What metrics.json and report.html are written from, made from a comparison: `rvr compare`
// and the Python module's rvr.compare build it here, so both write the same document.
#pragma once

#include <string>
#include <vector>

#include "report.h"
#include "rvr/core/scene.h"
#include "rvr/renderers/compare_renderers.h"

namespace rvr {

// The renderers' names as metrics.json keys them: a name used again gets "-2", "-3", ...
std::vector<std::string> renderer_keys(const std::vector<std::string>& names);

struct ReportContext {
  std::string mode;           // "local"
  double load_seconds = 0.0;  // stats["time.load"] of every renderer
  std::string command_line;
  std::string out_dir;
};

// The report of `result` (rendered from `scene` with `compare`'s scales): each renderer's
// image and cost picture named after it, each pair's pictures suffixed after its first.
ReportInput report_input(const Scene& scene, const CompareResult& result,
                         const CompareOptions& compare, const ReportContext& context);

}  // namespace rvr
