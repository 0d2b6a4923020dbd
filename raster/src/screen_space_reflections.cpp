#include "screen_space_reflections.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace rvr {

ScreenSpaceReflections::ScreenSpaceReflections(const FrameBuffers& frame, const PassCamera& camera,
                                               double near, double reach)
    : frame_(frame), camera_(camera), near_(near), reach_(reach) {}

SsrOutcome ScreenSpaceReflections::trace(const glm::dvec3& p, const glm::dvec3& r, uint32_t self,
                                         glm::vec3& colour) const {
  // Where the march ends: the end of the scene, or just before the near plane when the ray
  // turns towards the camera (past it the ray is behind the eye: off screen).
  const double depth_p = camera_.depth(p), per_unit = camera_.depth(p + r) - depth_p;
  double end = reach_;
  bool towards_eye = false;
  if (per_unit < 0.0) {
    const double to_near = (depth_p - near_) / -per_unit;
    if (to_near < end) {
      end = to_near * (1.0 - 1e-9);
      towards_eye = true;
    }
  }
  // Both ends on screen (pixels, row 0 the top) with 1/w, which is affine in screen space.
  const auto screen = [&](const glm::dvec3& q, double& x, double& y, double& inv_w) {
    const glm::dvec4 c = camera_.clip(q);
    inv_w = 1.0 / c.w;
    x = (c.x * inv_w * 0.5 + 0.5) * camera_.width;
    y = (0.5 - c.y * inv_w * 0.5) * camera_.height;
  };
  double x0, y0, k0, x1, y1, k1;
  screen(p, x0, y0, k0);
  screen(p + end * r, x1, y1, k1);
  const double span = std::max(std::abs(x1 - x0), std::abs(y1 - y0));
  // Two samples per pixel crossed, so that no pixel on the way is skipped.
  const int steps = int(std::min(std::ceil(2.0 * span), 8.0 * (camera_.width + camera_.height)));
  double previous = depth_p;                                         // the ray's depth a step ago
  double previous_stored = std::numeric_limits<double>::infinity();  // the frame's there
  for (int i = 1; i <= steps; ++i) {
    const double s = double(i) / double(steps);
    const double x = x0 + s * (x1 - x0), y = y0 + s * (y1 - y0);
    const double ray_depth = 1.0 / (k0 + s * (k1 - k0));
    // Compared as doubles first: a point near the eye's plane lands far out, past any int.
    if (!(x >= 0.0 && y >= 0.0 && x < camera_.width && y < camera_.height))
      return SsrOutcome::OffScreen;
    const int px = int(x), py = int(y);
    const size_t o = size_t(py) * size_t(camera_.width) + size_t(px);
    const double stored = frame_.depth[o];  // +inf on the background
    const double step = std::abs(ray_depth - previous);
    const double surface_step = std::isfinite(previous_stored) && std::isfinite(stored)
                                    ? std::abs(stored - previous_stored)
                                    : 0.0;
    previous = ray_depth;
    previous_stored = stored;
    if (frame_.object_id[o] == self) continue;  // still on the mirror
    if (ray_depth < stored) continue;
    // Behind the stored surface: crossed it within this step, as far as the ray and the surface
    // each moved in depth over it (a hit), or passed behind it (what it meets is hidden).
    if (ray_depth - stored <= std::max(step, surface_step) + 1e-6 * stored) {
      colour = frame_.colour[o];
      return SsrOutcome::Hit;
    }
    return SsrOutcome::Hidden;
  }
  return towards_eye ? SsrOutcome::OffScreen : SsrOutcome::Background;
}

}  // namespace rvr
