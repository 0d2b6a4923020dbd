#include "accumulation_buffer.h"

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <glm/glm.hpp>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "rvr/core/check.h"
#include "rvr/core/framebuffers.h"
#include "rvr/core/image_sample.h"
#include "rvr/core/progress.h"
#include "rvr/core/timer.h"

namespace rvr {

bool accumulates(const Scene& scene, const RenderOptions& options) {
  const bool blurred = options.mode == RenderMode::Full && scene.camera.aperture_radius > 0.0f &&
                       options.zbuffer_dof == ZBufferDof::Blur;
  return scene.image.samples_per_pixel > 1 && options.mode != RenderMode::Visibility &&
         !options.image_sample && !blurred;
}

Expected<RenderOutput> render_accumulated(const Scene& scene, const RenderOptions& options,
                                          const ZBufferPass& pass) {
  RVR_CHECK(accumulates(scene, options), "an accumulation buffer needs several samples per pixel");
  Expected<RenderOutput> centre = pass(options);
  if (!centre) return centre;
  RenderOutput& out = centre.value();
  FrameBuffers& fb = out.buffers;

  // The tracer's samples: its thin lens in full mode with an aperture, else the pinhole.
  const int spp = scene.image.samples_per_pixel;
  const bool thin_lens = options.mode == RenderMode::Full;
  RenderOptions sample_options = options;
  sample_options.cost_aov = false;  // the cost AOV is the centre pass's
  std::vector<glm::vec3> sum(fb.pixel_count(), glm::vec3(0.0f));
  const auto t = std::chrono::steady_clock::now();
  for (int k = 0; k < spp; ++k) {
    if (is_cancelled(options.progress)) return cancelled_error();  // per accumulation pass
    sample_options.image_sample = image_sample(scene.camera, options.seed, k, spp, thin_lens);
    Expected<RenderOutput> sample = pass(sample_options);
    if (!sample) return sample.error();
    const FrameBuffers& drawn = sample->buffers;
    RVR_CHECK(drawn.width == fb.width && drawn.height == fb.height &&
                  drawn.colour.size() == fb.pixel_count(),
              "every sample's pass has the centre pass's frame");
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += drawn.colour[i];
    for (const std::string& w : sample->warnings)
      if (std::find(out.warnings.begin(), out.warnings.end(), w) == out.warnings.end())
        out.warnings.push_back(w);
  }
  // The tracer's average: the same float operations in the same order.
  for (size_t i = 0; i < sum.size(); ++i) fb.colour[i] = sum[i] / float(spp);
  out.stats["zbuffer.accumulation_passes"] = double(spp);
  out.stats["time.accumulation"] = seconds_since(t);
  return centre;
}

}  // namespace rvr
