#include "rvr/raytrace/screen_bounds.h"

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>

#include "rvr/core/check.h"

namespace rvr {

PixelRect screen_bounds(const CameraFrame& frame, float near, const Aabb& box) {
  const PixelRect whole{0, 0, frame.width, frame.height};
  if (box.empty()) return {};
  if (!std::isfinite(box.lo.x + box.lo.y + box.lo.z + box.hi.x + box.hi.y + box.hi.z)) return whole;
  float lo_x = INFINITY, lo_y = INFINITY, hi_x = -INFINITY, hi_y = -INFINITY;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p(corner & 1 ? box.hi.x : box.lo.x, corner & 2 ? box.hi.y : box.lo.y,
                      corner & 4 ? box.hi.z : box.lo.z);
    const glm::vec3 d = p - frame.eye;
    const float depth = glm::dot(d, frame.forward);
    if (!(depth >= near && depth > 0.0f)) return whole;
    // camera_ray_direction inverted: the continuous image position of the corner.
    const float ndc_x = glm::dot(d, frame.right) / depth / (frame.tan_half_fov_y * frame.aspect);
    const float ndc_y = glm::dot(d, frame.up) / depth / frame.tan_half_fov_y;
    const float px = (ndc_x + 1.0f) * 0.5f * float(frame.width);
    const float py = (1.0f - ndc_y) * 0.5f * float(frame.height);
    lo_x = std::min(lo_x, px);
    hi_x = std::max(hi_x, px);
    lo_y = std::min(lo_y, py);
    hi_y = std::max(hi_y, py);
  }
  // Pixel x's centre is x + 0.5: x from floor(lo - 0.5) to ceil(hi - 0.5), two more each side.
  auto clamp = [](float v, int n) { return int(std::clamp(v, -1.0f, float(n) + 1.0f)); };
  PixelRect r;
  r.x0 = std::max(0, clamp(std::floor(lo_x - 0.5f), frame.width) - 2);
  r.x1 = std::min(frame.width, clamp(std::ceil(hi_x - 0.5f), frame.width) + 3);
  r.y0 = std::max(0, clamp(std::floor(lo_y - 0.5f), frame.height) - 2);
  r.y1 = std::min(frame.height, clamp(std::ceil(hi_y - 0.5f), frame.height) + 3);
  RVR_DCHECK(r.x0 >= 0 && r.y0 >= 0 && r.x1 <= frame.width && r.y1 <= frame.height,
             "a screen rectangle lies in the frame");
  return r;
}

}  // namespace rvr
