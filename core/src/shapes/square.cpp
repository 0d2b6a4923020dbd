#include "rvr/core/shapes/square.h"

#include <array>
#include <memory>

#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/core/tessellate.h"

namespace rvr {

void Square::bounding_balls(std::vector<BoundingBall>& out) const {
  for (const glm::vec3& p : plane_corners(*this)) out.push_back({p, 0.0f});
}

uint64_t Square::triangle_count(const TessellationOptions&) const {
  return kPlaneTriangleCount;
}

TriangleForm Square::triangle_form(const TessellationOptions&) const {
  TriangleForm form;
  form.made = std::make_unique<const TriangleMesh>(tessellate_plane(*this));
  form.mesh = form.made.get();
  return form;
}

Square::Traced Square::traced() const {
  auto [u, v] = plane_axes(normal);
  return {*this, u, v};
}

}  // namespace rvr
