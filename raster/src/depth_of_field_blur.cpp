#include "depth_of_field_blur.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <glm/glm.hpp>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rvr/core/timer.h"

namespace rvr {

bool blurs_depth_of_field(const Scene& scene, const RenderOptions& options) {
  return options.mode == RenderMode::Full && scene.camera.aperture_radius > 0.0f &&
         scene.image.samples_per_pixel > 1 && options.zbuffer_dof == ZBufferDof::Blur &&
         !options.image_sample;
}

float circle_of_confusion_pixels(const Camera& camera, int height, float depth) {
  const double inverse_depth = std::isinf(depth) ? 0.0 : 1.0 / double(depth);
  const double tangent = double(camera.aperture_radius) *
                         std::abs(1.0 / double(camera.focus_distance) - inverse_depth);
  const double pixels_per_tangent =
      double(height) /
      (2.0 * std::tan(0.5 * double(camera.fov_y_deg) * 3.14159265358979323846 / 180.0));
  return float(tangent * pixels_per_tangent);
}

float blur_depth_of_field(const Camera& camera, FrameBuffers& fb, int threads) {
  const int w = fb.width, h = fb.height;
  const size_t n = fb.pixel_count();
  std::vector<float> radius(n);
  float widest = 0.0f;
  for (size_t i = 0; i < n; ++i) {
    const float r = circle_of_confusion_pixels(camera, h, fb.depth[i]);
    widest = std::max(widest, r);
    radius[i] = std::min(r, float(kMaxBlurRadius));
  }
  const int window = int(std::ceil(std::min(widest, float(kMaxBlurRadius))));
  if (window == 0) return widest;
  const std::vector<glm::vec3> sharp(fb.colour.begin(), fb.colour.end());
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
      for (int y = rows.begin(); y != rows.end(); ++y)
        for (int x = 0; x < w; ++x) {
          const size_t p = size_t(y) * size_t(w) + size_t(x);
          glm::vec3 sum(0.0f);
          float weights = 0.0f;
          for (int qy = std::max(0, y - window); qy <= std::min(h - 1, y + window); ++qy)
            for (int qx = std::max(0, x - window); qx <= std::min(w - 1, x + window); ++qx) {
              const size_t q = size_t(qy) * size_t(w) + size_t(qx);
              // Behind p, q's disk reaches p only as far as p's own.
              const float r =
                  fb.depth[q] > fb.depth[p] ? std::min(radius[q], radius[p]) : radius[q];
              const float dx = float(qx - x), dy = float(qy - y);
              if (q != p && dx * dx + dy * dy > r * r) continue;
              const float weight = 1.0f / std::max(3.14159265f * radius[q] * radius[q], 1.0f);
              sum += weight * sharp[q];
              weights += weight;
            }
          fb.colour[p] = sum / weights;
        }
    });
  });
  return widest;
}

void add_depth_of_field_blur(const Scene& scene, const RenderOptions& options, RenderOutput& out) {
  if (!blurs_depth_of_field(scene, options)) return;
  const auto t = std::chrono::steady_clock::now();
  const float widest = blur_depth_of_field(scene.camera, out.buffers, options.threads);
  out.stats["time.dof_blur"] = seconds_since(t);
  out.stats["dof.blur_radius"] = double(widest);
  std::string warning =
      "depth of field by blur: the pinhole image spread over each pixel's circle of confusion "
      "(nothing behind a defocused edge is seen)";
  if (widest > float(kMaxBlurRadius))
    warning += fmt::format("; circles of confusion up to {:.1f} px clamped to {} px", widest,
                           kMaxBlurRadius);
  out.warnings.push_back(warning);
}

}  // namespace rvr
