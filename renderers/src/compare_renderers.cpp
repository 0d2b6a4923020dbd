#include "rvr/renderers/compare_renderers.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "rvr/compare/effect_errors.h"
#include "rvr/compare/mismatch_classes.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/timer.h"

namespace rvr {

DepthStore depth_store_of(const std::string& name, const RenderOutput& output) {
  auto stated = output.info.find("depth_format");
  if (stated != output.info.end())
    if (std::optional<DepthStore> store = parse_depth_store(stated->second)) return *store;
  if (name == "raster" || name == "hybrid") return DepthStore::Window32F;
  return DepthStore::ViewFloat;
}

namespace {

// A warning for a renderer whose image is all, or nearly all, background; empty otherwise.
std::string background_warning(const ComparedRenderer& r) {
  const FrameBuffers& fb = r.output.buffers;
  size_t covered = 0;
  for (uint32_t id : fb.object_id) covered += id != kNoId;
  const size_t n = fb.pixel_count();
  if (covered == 0)
    return r.name +
           ": nothing visible: every pixel is background, so agreement with it says "
           "nothing about visibility (is the model between the camera's near and far "
           "planes, and in front of it?)";
  if (double(covered) >= kNearlyAllBackground * double(n)) return "";
  return r.name + ": nearly all background: " + std::to_string(covered) + " of " +
         std::to_string(n) +
         " pixels show a surface, so agreement is mostly agreement on "
         "background";
}

// How near a renderer's loop order is to the tracer's ray tree, which the effect masks are read
// from: the tracers, then the hybrids (the tracer's rays after a z-buffer), then the z-buffers.
int mask_rank(const std::string& name) {
  const Expected<RendererChoice> choice = find_renderer_choice(name);
  if (!choice.ok()) return 3;
  switch (choice->info->order) {
    case LoopOrder::PixelMajor:
      return 0;
    case LoopOrder::Hybrid:
      return 1;
    case LoopOrder::TriangleMajor:
      return 2;
  }
  return 3;
}

ComparedPair compare_pair(const Scene& scene, const CompareResult& result, size_t ia, size_t ib,
                          const CompareOptions& compare) {
  const ComparedRenderer& ra = result.renderers[ia];
  const ComparedRenderer& rb = result.renderers[ib];
  const FrameBuffers& a = ra.output.buffers;
  const FrameBuffers& b = rb.output.buffers;
  MismatchContext context;
  context.scene = &scene;
  context.store_a = depth_store_of(ra.name, ra.output);
  context.store_b = depth_store_of(rb.name, rb.output);
  context.sphere_segments = compare.sphere_segments;
  context.polygon_sphere_segments = compare.polygon_sphere_segments;
  ComparedPair p;
  p.a = ia;
  p.b = ib;
  p.metrics = compare_buffers(a, b, context);
  p.metrics.effects_mask_from = mask_rank(rb.name) < mask_rank(ra.name) ? rb.name : ra.name;
  const FrameBuffers& masks = p.metrics.effects_mask_from == ra.name ? a : b;
  p.metrics.effects = effect_errors(scene, compare.mode, masks, a, b);
  if (!p.metrics.effects.empty()) p.effects = effect_mask_image(scene, compare.mode, masks);
  const FrameBuffers* answered = answering_frame(a, b);
  if (answered && !p.metrics.effects.empty()) {
    p.metrics.answers_from = answered == &a ? ra.name : rb.name;
    p.answers = answer_image(*answered);
  }
  p.diff = diff_heat_map(ra.image, rb.image, compare.heat_map_scale);
  p.id_mismatch = id_mismatch_image(a, b);
  p.depth_diff = depth_diff_image(a, b, compare.depth_diff_scale);
  p.mismatch_classes = mismatch_class_image(a, classify_mismatches(a, b, context));
  return p;
}

}  // namespace

Expected<CompareResult> compare_renderers(const Scene& scene, const std::vector<std::string>& names,
                                          const RenderOptions& options,
                                          const CompareOptions& compare) {
  using Clock = std::chrono::steady_clock;
  if (names.size() < 2) return bad_input("need at least two renderers to compare");
  auto phase = [&](const std::string& label, const std::string& name) {
    if (compare.on_phase) compare.on_phase(label, name);
  };
  // Every name is checked before the first, possibly long, render.
  std::vector<std::unique_ptr<Renderer>> made;
  for (const std::string& name : names) {
    RVR_TRY_ASSIGN(r, make_renderer(name, compare.config));
    made.push_back(std::move(r).value());
  }

  CompareResult result;
  for (size_t i = 0; i < made.size(); ++i) {
    phase(std::to_string(i + 1) + "/" + std::to_string(made.size()) + " " + names[i], "render");
    auto start = Clock::now();
    RVR_TRY_ASSIGN(out, made[i]->render(scene, options));
    ComparedRenderer r;
    r.name = names[i];
    r.seconds = seconds_since(start);
    r.output = std::move(out).value();
    result.renderers.push_back(std::move(r));
  }

  phase("", "compare");
  CompareOptions comparing = compare;
  comparing.mode = options.mode;
  if (options.spheres == SphereMode::Mesh)
    comparing.sphere_segments = options.sphere_segments;
  else
    comparing.polygon_sphere_segments = options.sphere_segments;
  return compare_rendered(scene, std::move(result.renderers), comparing);
}

CompareResult compare_rendered(const Scene& scene, std::vector<ComparedRenderer> rendered,
                               const CompareOptions& compare) {
  CompareResult result;
  result.renderers = std::move(rendered);
  for (ComparedRenderer& r : result.renderers) {
    const FrameBuffers& fb = r.output.buffers;
    r.image = colour_image(fb);
    double total = 0;
    for (float c : fb.cost) total += c;
    r.has_cost = total > 0;
    if (r.has_cost) {
      float scale = 0;
      r.cost_image = cost_image(fb, &scale);
      r.cost_scale = scale;
      r.cost_mean = total / double(std::max<size_t>(1, fb.pixel_count()));
    }
  }
  for (size_t i = 0; i < result.renderers.size(); ++i)
    for (size_t j = i + 1; j < result.renderers.size(); ++j)
      result.pairs.push_back(compare_pair(scene, result, i, j, compare));
  for (const ComparedRenderer& r : result.renderers)
    if (std::string w = background_warning(r); !w.empty()) result.warnings.push_back(std::move(w));
  return result;
}

}  // namespace rvr
