#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {

void TriangleMesh::bounding_balls(std::vector<BoundingBall>& out) const {
  for (const glm::vec3& p : positions) out.push_back({p, 0.0f});
}

TriangleForm TriangleMesh::triangle_form(const TessellationOptions&) const {
  TriangleForm form;
  form.mesh = this;
  form.is_object_mesh = true;
  form.names_triangles = true;
  return form;
}

}  // namespace rvr
