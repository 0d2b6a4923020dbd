// rvr compare: the compared renderers' images, the difference pictures, metrics.json and
// report.html.
#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "cli_exit.h"
#include "commands.h"
#include "report.h"
#include "rvr/raster/gl_rasterizer.h"
#include "rvr/raytrace/ray_tracer.h"
#include "rvr/renderers/compare_renderers.h"
#include "rvr/renderers/registry.h"
#include "rvr/shared/compare.h"
#include "rvr/shared/image_io.h"
#include "rvr/shared/isa.h"
#include "rvr/shared/limits.h"
#include "rvr/shared/scene_loader.h"
#include "rvr/shared/scene_writer.h"
#include "terminal_progress.h"

namespace rvr::cli {

int run_compare(const CompareArgs& a, const std::string& command_line) {
  if (a.renderers.size() < 2)
    fail(bad_input("--renderers: need at least two renderers to compare"));
  refuse_overwriting_inputs({a.common.scene},
                            {a.out_dir + "/metrics.json", a.out_dir + "/report.html"});
  TerminalProgress progress(progress_wanted(a.common.quiet));
  progress.begin("", "load");
  RenderOptions options = render_options(a.common, "local");
  double load_seconds = 0;
  Scene scene = load(a.common, options, load_seconds);
  options.progress = progress.sink();

  CompareOptions compare;
  compare.config.gl = gl_backend(a.common);
  compare.on_phase = [&](const std::string& label, const std::string& phase) {
    progress.begin(label, phase);
  };
  // Everything is computed before the first file is written.
  CompareResult result = take(compare_renderers(scene, a.renderers, options, compare));

  ReportInput report;
  report.scene = scene.source;
  report.width = scene.image.width;
  report.height = scene.image.height;
  report.mode = to_string(options.mode);
  report.command_line = command_line;
  report.out_dir = a.out_dir;
  report.metrics = result.metrics;
  report.heat_map_scale = compare.heat_map_scale;
  report.depth_diff_scale = compare.depth_diff_scale;
  for (const ComparedRenderer& c : result.renderers) {
    ReportRenderer r;
    r.name = c.name;
    r.image_file = r.name + ".png";
    r.seconds = c.seconds;
    r.warnings = c.output.warnings;
    r.stats = c.output.stats;
    r.info = c.output.info;
    r.stats["time.load"] = load_seconds;
    if (c.has_cost) {
      r.cost_file = r.name + ".cost.png";
      r.cost_scale = c.cost_scale;
      r.cost_mean = c.cost_mean;
    }
    report.renderers.push_back(r);
  }

  for (size_t i = 0; i < result.renderers.size(); ++i) {
    check(write_image(a.out_dir + "/" + report.renderers[i].image_file, result.renderers[i].image));
    if (!report.renderers[i].cost_file.empty())
      check(write_image(a.out_dir + "/" + report.renderers[i].cost_file,
                        result.renderers[i].cost_image, false));
  }
  check(write_image(a.out_dir + "/diff.png", result.diff, false));
  check(write_image(a.out_dir + "/id_mismatch.png", result.id_mismatch, false));
  check(write_image(a.out_dir + "/depth_diff.png", result.depth_diff, false));
  check(write_text_file(a.out_dir + "/metrics.json", metrics_json(report)));
  check(write_text_file(a.out_dir + "/report.html", take(report_html(report))));

  progress.stop();  // before the warnings and the table
  const ComparisonMetrics& m = report.metrics;
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  for (const ReportRenderer& r : report.renderers)
    for (const std::string& w : r.warnings)
      std::fprintf(stderr, "warning: %s: %s\n", r.name.c_str(), w.c_str());
  std::printf("%s  %dx%d  mode %s\n", scene.source.c_str(), scene.image.width, scene.image.height,
              report.mode.c_str());
  for (const ReportRenderer& r : report.renderers)
    std::printf("  %-12s %9.3f s\n", r.name.c_str(), r.seconds);
  std::printf("  %s vs %s:\n", a.renderers[0].c_str(), a.renderers[1].c_str());
  std::printf("  id agreement      %.5f  (%zu of %zu pixels differ, %zu off edges)\n",
              m.visibility.id_agreement, m.visibility.mismatched_pixels, m.visibility.pixels,
              m.visibility.mismatched_off_edge);
  std::printf("  depth rel error   max %.3g  mean %.3g  p99 %.3g  p99.9 %.3g\n",
              m.depth.max_rel_error, m.depth.mean_rel_error, m.depth.p99_rel_error,
              m.depth.p999_rel_error);
  if (m.depth.outliers)
    std::printf("  depth outliers    %zu above %g: %zu at silhouettes, %zu elsewhere\n",
                m.depth.outliers, kDepthOutlierThreshold, m.depth.outliers_at_silhouettes,
                m.depth.outliers_elsewhere);
  std::printf("  colour            rmse %.4g  psnr %.2f dB  max %.4g  ssim %.4f\n", m.color.rmse,
              m.color.psnr_db, m.color.max_abs, m.color.ssim);
  std::printf(
      "  wrote %s/{%s.png,%s.png,diff.png,depth_diff.png,id_mismatch.png,metrics.json,"
      "report.html}\n",
      a.out_dir.c_str(), a.renderers[0].c_str(), a.renderers[1].c_str());
  if (a.fail_below_agreement && m.visibility.id_agreement < *a.fail_below_agreement) {
    std::fprintf(stderr, "id agreement %.5f is below %.5f\n", m.visibility.id_agreement,
                 *a.fail_below_agreement);
    return 1;
  }
  return 0;
}

}  // namespace rvr::cli
