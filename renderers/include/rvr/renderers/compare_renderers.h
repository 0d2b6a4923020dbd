// `rvr compare` without the files and the printing: every renderer renders the scene, every pair
// is compared pixel by pixel, and the pictures of the comparison are made.
#pragma once

#include <stddef.h>

#include <functional>
#include <string>
#include <vector>

#include "rvr/compare/compare.h"
#include "rvr/compare/mismatch_classes.h"
#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/image_codec/image_io.h"
#include "rvr/renderers/registry.h"

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
  // > 0: the renders drew and traced spheres as tessellate_sphere(sphere, sphere_segments)
  // (SphereMode::Mesh), whose facets are then primitives; compare_renderers sets it.
  int sphere_segments = 0;
  // > 0: spheres were analytic, the z-buffers drew tessellate_sphere(sphere,
  // polygon_sphere_segments) (MismatchContext); compare_renderers sets it.
  int polygon_sphere_segments = 0;
  // The mode the renders were made in: which effects act (effect_errors.h); compare_renderers
  // sets it.
  RenderMode mode = RenderMode::Local;
};

// Two of the renderers compared, a before b in the order asked for; a is the reference of the
// mismatch classes.
struct ComparedPair {
  size_t a = 0, b = 1;  // indices into CompareResult::renderers
  ComparisonMetrics metrics;
  Image diff;              // colour difference heat map
  Image id_mismatch;       // id mismatches over grey
  Image depth_diff;        // relative depth difference
  Image mismatch_classes;  // mismatched pixels coloured by class over grey
  Image effects;           // the effect masks (effect_mask_image); empty when none acts
  Image answers;           // the z-buffer's answers (answer_image); empty without answers_from
};

// A renderer whose image shows a surface in fewer than this fraction of its pixels is warned
// about: agreement with it is mostly agreement on background. 1e-3 is about a 15x15 pixel
// patch at 480x480, too small for the agreement figures to say much about visibility.
inline constexpr double kNearlyAllBackground = 1e-3;

struct CompareResult {
  std::vector<ComparedRenderer> renderers;  // in the order asked for
  // Every pair (i, j), i < j: (0, 1), (0, 2), ..., (1, 2), ...; the first is the pair the
  // single-pair outputs (metrics.json's top level, diff.png) are about.
  std::vector<ComparedPair> pairs;
  // What makes the figures say less than they seem to, e.g. "raster: nothing visible: ...".
  std::vector<std::string> warnings;
};

// How the named renderer's visibility test stores depth: what its output states in
// info["depth_format"] (d24, d32f, d32f_reversed, float), else the GL z-buffers' (raster,
// hybrid) GL_DEPTH_COMPONENT32F, else float view depth (the tracers; softraster orders doubles).
DepthStore depth_store_of(const std::string& name, const RenderOutput& output);

// At least two names, all in the table (a BadInput error otherwise, before any rendering).
// Stops at the first renderer that fails.
Expected<CompareResult> compare_renderers(const Scene& scene, const std::vector<std::string>& names,
                                          const RenderOptions& options,
                                          const CompareOptions& compare = {});

// The comparing half of compare_renderers, over renders already made (each with its name,
// seconds and output; at least two, all of the scene's size): their images and cost pictures,
// every pair and the warnings.
CompareResult compare_rendered(const Scene& scene, std::vector<ComparedRenderer> rendered,
                               const CompareOptions& compare = {});

}  // namespace rvr
