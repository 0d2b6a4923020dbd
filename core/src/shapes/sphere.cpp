#include "rvr/core/shapes/sphere.h"

#include <memory>

#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/tessellate.h"

namespace rvr {

void Sphere::bounding_balls(std::vector<BoundingBall>& out) const {
  out.push_back({center, radius});
}

uint64_t Sphere::triangle_count(const TessellationOptions& options) const {
  return sphere_triangle_count(options.sphere_segments);
}

TriangleForm Sphere::triangle_form(const TessellationOptions& options) const {
  TriangleForm form;
  form.made =
      std::make_unique<const TriangleMesh>(tessellate_sphere(*this, options.sphere_segments));
  form.mesh = form.made.get();
  form.names_triangles = !traced_analytically(options);
  return form;
}

}  // namespace rvr
