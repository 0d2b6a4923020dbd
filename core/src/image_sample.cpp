#include "rvr/core/image_sample.h"

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "rvr/core/camera.h"
#include "rvr/core/check.h"

namespace rvr {

namespace {

// splitmix64: a frame's samples from its seed alone, the same on every machine.
uint64_t mix(uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

float uniform(uint64_t& state) {
  state = mix(state);
  return float(state >> 40) * (1.0f / 16777216.0f);  // 24 bits: exactly representable, < 1
}

}  // namespace

ImageSample image_sample(const Camera& camera, uint64_t seed, int k, int spp, bool thin_lens) {
  RVR_CHECK(spp >= 1 && k >= 0 && k < spp, "sample ", k, " of ", spp, " per pixel");
  ImageSample s;
  uint64_t state = mix(seed ^ 0x5851F42D4C957F2Dull) ^ uint64_t(uint32_t(k));
  const int m = int(std::sqrt(double(spp)));
  s.jx = uniform(state);
  s.jy = uniform(state);
  if (k < m * m) {
    const int column = k % m, row = k / m;  // sample k's stratum of the m x m grid
    s.jx = (float(column) + s.jx) / float(m);
    s.jy = (float(row) + s.jy) / float(m);
  }
  if (thin_lens && camera.aperture_radius > 0.0f) {
    const float pi = 3.14159265358979f;
    const float radius = camera.aperture_radius * std::sqrt(uniform(state));
    const float angle = 2.0f * pi * (float(k) + uniform(state)) / float(spp);
    s.lens_x = radius * std::cos(angle);
    s.lens_y = radius * std::sin(angle);
  }
  return s;
}

glm::vec3 sample_eye(const Camera& camera, const ImageSample& sample) {
  // The axes the tracer's frame has (make_camera_frame), so a lens point is the same point.
  const CameraFrame frame = make_camera_frame(camera, 1, 1);
  return frame.eye + sample.lens_x * frame.right + sample.lens_y * frame.up;
}

glm::mat4 sample_view_matrix(const Camera& camera, const ImageSample& sample) {
  // Eye space moved by the lens offset; its axes stay those of the pinhole camera.
  return glm::translate(glm::mat4(1.0f), glm::vec3(-sample.lens_x, -sample.lens_y, 0.0f)) *
         view_matrix(camera);
}

glm::mat4 sample_projection_matrix(const Camera& camera, int width, int height,
                                   const ImageSample& sample) {
  glm::mat4 p = projection_matrix(camera, width, height);
  // A point at view depth d = -z, seen from the lens point, lies on the ray through the image
  // position whose pinhole direction is (x' / d + lens / focus): a shift of lens / focus in
  // tangent units, p[0][0] and p[1][1] turning tangents into NDC. The pixel shift moves the
  // image by (0.5 - j) pixels so that each centre samples the image at the pixel's j (NDC y is
  // up, pixel y down). Clip x gains shift * w = shift * (-z): column 2 of the matrix.
  const float focus = camera.focus_distance;
  const float lens_x = focus > 0.0f ? p[0][0] * sample.lens_x / focus : 0.0f;
  const float lens_y = focus > 0.0f ? p[1][1] * sample.lens_y / focus : 0.0f;
  const float pixel_x = 2.0f * (0.5f - sample.jx) / float(width);
  const float pixel_y = -2.0f * (0.5f - sample.jy) / float(height);
  p[2][0] -= lens_x + pixel_x;
  p[2][1] -= lens_y + pixel_y;
  return p;
}

}  // namespace rvr
