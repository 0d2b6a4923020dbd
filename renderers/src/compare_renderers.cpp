#include "rvr/renderers/compare_renderers.h"

#include <algorithm>
#include <chrono>
#include <memory>

#include "rvr/shared/timer.h"

namespace rvr {

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
    Expected<std::unique_ptr<Renderer>> r = make_renderer(name, compare.config);
    if (!r) return r.error();
    made.push_back(std::move(r).value());
  }

  CompareResult result;
  for (size_t i = 0; i < made.size(); ++i) {
    phase(std::to_string(i + 1) + "/" + std::to_string(made.size()) + " " + names[i], "render");
    auto start = Clock::now();
    Expected<RenderOutput> out = made[i]->render(scene, options);
    if (!out) return out.error();
    ComparedRenderer r;
    r.name = names[i];
    r.seconds = seconds_since(start);
    r.output = std::move(out).value();
    result.renderers.push_back(std::move(r));
  }

  phase("", "compare");
  const FrameBuffers& a = result.renderers[0].output.buffers;
  const FrameBuffers& b = result.renderers[1].output.buffers;
  result.metrics = compare_buffers(a, b);
  for (ComparedRenderer& r : result.renderers) {
    const FrameBuffers& fb = r.output.buffers;
    r.image = color_image(fb);
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
  result.diff =
      diff_heat_map(result.renderers[0].image, result.renderers[1].image, compare.heat_map_scale);
  result.id_mismatch = id_mismatch_image(a, b);
  result.depth_diff = depth_diff_image(a, b, compare.depth_diff_scale);
  return result;
}

}  // namespace rvr
