#include "pass_camera.h"

#include <optional>

#include "rvr/core/camera.h"
#include "rvr/core/image_sample.h"

namespace rvr {

PixelRay PassCamera::ray(int x, int y, double depth_at) const {
  const double ndc_x = 2.0 * (x + 0.5) / width - 1.0, ndc_y = 1.0 - 2.0 * (y + 0.5) / height;
  const glm::dvec4 ha = unproject * glm::dvec4(ndc_x, ndc_y, -1.0, 1.0);
  const glm::dvec4 hb = unproject * glm::dvec4(ndc_x, ndc_y, 1.0, 1.0);
  const glm::dvec3 a = glm::dvec3(ha) / ha.w, b = glm::dvec3(hb) / hb.w;
  const double da = depth(a), db = depth(b);
  return {glm::normalize(b - a), a + (depth_at - da) / (db - da) * (b - a)};
}

PassCamera pass_camera(const Scene& scene, const RenderOptions& options) {
  PassCamera c;
  c.width = scene.image.width;
  c.height = scene.image.height;
  c.view = options.image_sample
               ? glm::dmat4(sample_view_matrix(scene.camera, *options.image_sample))
               : glm::dmat4(view_matrix(scene.camera));
  c.projection = options.image_sample
                     ? glm::dmat4(sample_projection_matrix(scene.camera, c.width, c.height,
                                                           *options.image_sample))
                     : glm::dmat4(projection_matrix(scene.camera, c.width, c.height));
  c.unproject = glm::inverse(c.projection * c.view);
  return c;
}

}  // namespace rvr
