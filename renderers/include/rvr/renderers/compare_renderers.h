// `rvr compare` without the files and the printing: every renderer renders the scene, the first
// two are compared pixel by pixel, and the pictures of the comparison are made.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "rvr/renderers/registry.h"
#include "rvr/shared/compare.h"
#include "rvr/shared/expected.h"
#include "rvr/shared/image_io.h"
#include "rvr/shared/renderer.h"

namespace rvr {

struct ComparedRenderer {
  std::string name;
  double seconds = 0.0;  // the render alone
  RenderOutput output;   // frame buffers, stats, warnings, info
  Image image;           // linear colour
  // Work per pixel (cost AOV): false when the renderer reports none (embree). Then the
  // colour-mapped picture, the cost at the top of its map and the mean over pixels.
  bool has_cost = false;
  Image cost_image;
  double cost_scale = 0.0, cost_mean = 0.0;
};

struct CompareOptions {
  RendererConfig config;
  float heat_map_scale = 0.1f;      // colour difference at the top of the diff heat map
  DepthDiffScale depth_diff_scale;  // relative depth difference at the ends of its map
  // Told ("1/2 raster", "render") before each renderer and ("", "compare") before comparing,
  // for whoever shows progress; may be empty.
  std::function<void(const std::string& label, const std::string& phase)> on_phase;
};

struct CompareResult {
  std::vector<ComparedRenderer> renderers;  // in the order asked for
  ComparisonMetrics metrics;                // of the first two
  Image diff;                               // colour difference heat map of the first two
  Image id_mismatch;                        // their id mismatches over grey
  Image depth_diff;                         // their relative depth difference
};

// At least two names, all in the table (a BadInput error otherwise, before any rendering).
// Stops at the first renderer that fails.
Expected<CompareResult> compare_renderers(const Scene& scene, const std::vector<std::string>& names,
                                          const RenderOptions& options,
                                          const CompareOptions& compare = {});

}  // namespace rvr
