// metrics.json and report.html of `rvr compare`.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "rvr/compare/compare.h"
#include "rvr/core/expected.h"

namespace rvr {

struct ReportRenderer {
  std::string name;
  std::string image_file;  // file name inside the output folder, e.g. "raster.png"
  double seconds = 0.0;
  std::vector<std::string> warnings;
  std::map<std::string, double> stats;
  // Work per pixel (cost AOV) picture in the output folder, or empty when the renderer
  // reports none (embree); the cost at the top of its colour map; the mean over pixels.
  std::string cost_file;
  double cost_scale = 0.0, cost_mean = 0.0;
  std::map<std::string, std::string> info;  // e.g. accel: bvh, kernel: avx2
  std::string depth_format = "float";       // how its visibility test stores depth (to_string)
};

// Two renderers compared: indices into ReportInput::renderers, a before b.
struct ReportPair {
  size_t a = 0, b = 1;
  ComparisonMetrics metrics;
  // Appended to the stems of the pair's pictures: "" for the first pair (diff.png, ...),
  // ".A_vs_B" for the others (diff.A_vs_B.png, ...).
  std::string suffix;
  std::string file(const std::string& stem) const { return stem + suffix + ".png"; }
};

struct ReportInput {
  std::string scene;  // "builtin:cornell" or the file path
  int width = 0, height = 0;
  std::string mode;                       // "local"
  std::vector<ReportRenderer> renderers;  // the first two are the first pair
  ComparisonMetrics metrics;              // of the first pair
  // Every pair compared, the first first; empty: one pair, the first two renderers, `metrics`.
  std::vector<ReportPair> pairs;
  // The scene loader's (e.g. dropped degenerate triangles), then the comparison's (e.g. an
  // image with nothing visible); each renderer's own are in `renderers`.
  std::vector<std::string> warnings;
  float heat_map_scale = 0.1f;      // colour difference at the top of diff.png's colour map
  DepthDiffScale depth_diff_scale;  // relative depth difference at the ends of depth_diff.png
  std::string command_line;
  // Holds the images named here plus each pair's diff, depth_diff, id_mismatch and
  // mismatch_classes pictures.
  std::string out_dir;
};

// input.pairs, or the one pair its `metrics` describe when it lists none.
std::vector<ReportPair> report_pairs(const ReportInput& input);

// The metrics.json document (docs/cli.md), as text.
std::string metrics_json(const ReportInput& input);

// A self-contained report.html: images from out_dir embedded as data URIs, no network.
Expected<std::string> report_html(const ReportInput& input);

}  // namespace rvr
