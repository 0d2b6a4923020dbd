#include "report_input.h"

#include <stddef.h>

#include <algorithm>
#include <map>
#include <memory>

#include "rvr/compare/compare.h"
#include "rvr/compare/mismatch_classes.h"
#include "rvr/core/renderer.h"

namespace rvr {

std::vector<std::string> renderer_keys(const std::vector<std::string>& names) {
  std::vector<std::string> keys;
  for (const std::string& name : names) {
    std::string key = name;
    for (int k = 2; std::find(keys.begin(), keys.end(), key) != keys.end(); ++k)
      key = name + "-" + std::to_string(k);
    keys.push_back(key);
  }
  return keys;
}

ReportInput report_input(const Scene& scene, const CompareResult& result,
                         const CompareOptions& compare, const ReportContext& context) {
  ReportInput report;
  report.scene = scene.source;
  report.width = scene.image.width;
  report.height = scene.image.height;
  report.mode = context.mode;
  report.command_line = context.command_line;
  report.out_dir = context.out_dir;
  report.heat_map_scale = compare.heat_map_scale;
  report.depth_diff_scale = compare.depth_diff_scale;
  // The scene loader's warnings (each names the file), then the comparison's.
  report.warnings = scene.warnings;
  report.warnings.insert(report.warnings.end(), result.warnings.begin(), result.warnings.end());
  std::vector<std::string> names;
  for (const ComparedRenderer& c : result.renderers) names.push_back(c.name);
  // A renderer compared twice writes its images under its key (raytrace-2), not over the first's.
  const std::vector<std::string> keys = renderer_keys(names);
  for (size_t i = 0; i < result.renderers.size(); ++i) {
    const ComparedRenderer& c = result.renderers[i];
    ReportRenderer r;
    r.name = c.name;
    r.image_file = keys[i] + ".png";
    r.seconds = c.seconds;
    r.warnings = c.output.warnings;
    r.stats = c.output.stats;
    r.info = c.output.info;
    r.depth_format = to_string(depth_store_of(c.name, c.output));
    r.stats["time.load"] = context.load_seconds;
    if (c.has_cost) {
      r.cost_file = keys[i] + ".cost.png";
      r.cost_scale = c.cost_scale;
      r.cost_mean = c.cost_mean;
    }
    report.renderers.push_back(r);
  }
  for (size_t k = 0; k < result.pairs.size(); ++k) {
    const ComparedPair& p = result.pairs[k];
    ReportPair rp;
    rp.a = p.a;
    rp.b = p.b;
    rp.metrics = p.metrics;
    rp.suffix = k == 0 ? "" : "." + keys[p.a] + "_vs_" + keys[p.b];
    report.pairs.push_back(rp);
  }
  report.metrics = report.pairs.front().metrics;
  return report;
}

}  // namespace rvr
