#include "approximated_pixels.h"

#include <cstring>

#include "rvr/core/camera.h"
#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/screen_bounds.h"

namespace rvr {

std::vector<uint8_t> approximated_pixels(const Scene& scene, const TraceGeometry& geometry) {
  const int w = scene.image.width, h = scene.image.height;
  const CameraFrame frame = make_camera_frame(scene.camera, w, h);
  std::vector<uint8_t> mask(size_t(w) * size_t(h), 0);
  for (const Aabb& box : geometry.approximated_bounds()) {
    const PixelRect r = screen_bounds(frame, scene.camera.near, box);
    for (int y = r.y0; y < r.y1; ++y)
      if (r.x1 > r.x0)
        std::memset(mask.data() + size_t(y) * size_t(w) + size_t(r.x0), 1, size_t(r.x1 - r.x0));
  }
  return mask;
}

}  // namespace rvr
