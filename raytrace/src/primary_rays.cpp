#include "rvr/raytrace/primary_rays.h"

#include <algorithm>
#include <cassert>

namespace rvr {

PrimaryRays::PrimaryRays(const CameraFrame& frame, float tmin, float tmax)
    : frame_(frame), tmin_(tmin), tmax_(tmax) {
  // camera_ray_direction's expressions, term by term, at px = x + 0.5 and py = y + 0.5.
  column_.resize(size_t(std::max(frame.width, 0)));
  for (int x = 0; x < frame.width; ++x) {
    const float ndc_x = 2.0f * (float(x) + 0.5f) / float(frame.width) - 1.0f;
    column_[size_t(x)] = ndc_x * frame.tan_half_fov_y * frame.aspect;
  }
  row_.resize(size_t(std::max(frame.height, 0)));
  for (int y = 0; y < frame.height; ++y) {
    const float ndc_y = 1.0f - 2.0f * (float(y) + 0.5f) / float(frame.height);
    row_[size_t(y)] = ndc_y * frame.tan_half_fov_y;
  }
}

RayPacket PrimaryRays::packet(int x0, int y0, int w, int h) const {
  assert(w * h <= kPacketRays && x0 + w <= frame_.width && y0 + h <= frame_.height);
  RayPacket packet;
  packet.origin[0] = frame_.eye.x;
  packet.origin[1] = frame_.eye.y;
  packet.origin[2] = frame_.eye.z;
  packet.tmin = tmin_;
  packet.tmax = tmax_;
  packet.count = w * h;
  const float* column = column_.data() + x0;
  for (int j = 0; j < h; ++j) {
    const float row = row_[size_t(y0) + size_t(j)];
    for (int a = 0; a < 3; ++a) {
      // (forward + right * column) + up * row, as glm adds the vec3 terms; vectorizes along i.
      const float forward = frame_.forward[a], right = frame_.right[a], up_row = frame_.up[a] * row;
      float* out = packet.dir[a] + j * w;
      for (int i = 0; i < w; ++i) out[i] = (forward + right * column[i]) + up_row;
    }
  }
  return packet;
}

Ray PrimaryRays::ray(int x, int y) const {
  Ray r;
  r.origin = frame_.eye;
  r.dir = direction(x, y);
  r.tmin = tmin_;
  r.tmax = tmax_;
  return r;
}

}  // namespace rvr
