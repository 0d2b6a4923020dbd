#include "approximated_pixels.h"

#include <cstring>

#include "rvr/core/camera.h"
#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/screen_bounds.h"

namespace rvr {

std::vector<uint8_t> approximated_pixels(const Scene& scene, const TraceGeometry& geometry) {
  const int w = scene.image.width, h = scene.image.height;
  const CameraFrame frame = make_camera_frame(scene.camera, w, h);
  std::vector<uint8_t> mask;
  for (const Aabb& box : geometry.approximated_bounds()) {
    const PixelRect r = screen_bounds(frame, scene.camera.near, box);
    if (r.x1 <= r.x0 || r.y1 <= r.y0) continue;
    if (mask.empty()) mask.assign(size_t(w) * size_t(h), 0);
    for (int y = r.y0; y < r.y1; ++y)
      std::memset(mask.data() + size_t(y) * size_t(w) + size_t(r.x0), 1, size_t(r.x1 - r.x0));
  }
  return mask;
}

}  // namespace rvr
