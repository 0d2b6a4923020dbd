// The rays through the pixel centres of one frame, from the camera's eye. camera_ray_direction
// (rvr/core/camera.h) divides twice per ray; here the horizontal term of each column and the
// vertical term of each row are computed once per frame with the same float operations, and a
// ray's direction is forward + right * column + up * row, glm's order: the same bits, with no
// division per ray.
#pragma once

#include <stddef.h>

#include <glm/glm.hpp>
#include <vector>

#include "rvr/core/camera.h"
#include "rvr/core/ray.h"
#include "rvr/raytrace/wide_bvh_layout.h"

namespace rvr {

class PrimaryRays {
 public:
  // t in (tmin, tmax) along a direction with forward component 1 is view depth.
  PrimaryRays(const CameraFrame& frame, float tmin, float tmax);

  // The centre rays of pixels [x0, x0 + w) x [y0, y0 + h), row by row (w * h <= kPacketRays).
  RayPacket packet(int x0, int y0, int w, int h) const;
  // Ray k of a packet as a single ray.
  static Ray ray_of(const RayPacket& packet, int k) {
    return Ray{{packet.origin[0], packet.origin[1], packet.origin[2]},
               {packet.dir[0][k], packet.dir[1][k], packet.dir[2][k]},
               packet.tmin,
               packet.tmax};
  }
  // The centre ray of pixel (x, y).
  Ray ray(int x, int y) const;

 private:
  glm::vec3 direction(int x, int y) const {
    return frame_.forward + frame_.right * column_[size_t(x)] + frame_.up * row_[size_t(y)];
  }

  CameraFrame frame_;
  float tmin_, tmax_;
  std::vector<float> column_;  // ndc_x * tan_half_fov_y * aspect of each column's centre
  std::vector<float> row_;     // ndc_y * tan_half_fov_y of each row's centre
};

}  // namespace rvr
