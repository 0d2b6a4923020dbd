// N copies of a scene's geometry in a grid (see grid_of_copies.h).
#include "rvr/study/grid_of_copies.h"

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "rvr/scene_io/camera_framing.h"

namespace rvr::study {
namespace {

bool copied(const Object& o) {
  return o.type == ObjectType::Triangles || o.type == ObjectType::Sphere;
}

Object translated(const Object& o, glm::vec3 offset, size_t copy) {
  Object out = o;
  out.name = o.name + "#" + std::to_string(copy);
  if (o.type == ObjectType::Sphere) out.sphere.center += offset;
  for (glm::vec3& p : out.mesh.positions) p += offset;
  return out;
}

}  // namespace

Expected<Scene> grid_of_copies(const Scene& base, size_t copies) {
  Scene geometry_only = base;
  std::erase_if(geometry_only.objects, [](const Object& o) { return !copied(o); });
  BoundingSphere bounds = scene_bounds(geometry_only);
  if (bounds.empty)
    return bad_input(base.source + ": objects: no mesh or sphere to copy for the study's sweep");
  const size_t columns = size_t(std::ceil(std::sqrt(double(copies))));
  const float spacing = 2.2f * std::max(bounds.radius, 1e-6f);
  Scene out = base;
  out.objects.clear();
  for (const Object& o : base.objects)
    if (!copied(o)) out.objects.push_back(o);
  for (size_t k = 0; k < copies; ++k) {
    const size_t column = k % columns, row = k / columns;
    glm::vec3 offset(spacing * float(column), spacing * float(row), 0.0f);
    for (const Object& o : base.objects)
      if (copied(o)) out.objects.push_back(k == 0 ? o : translated(o, offset, k));
  }
  glm::vec3 from = base.camera.eye - base.camera.target;
  if (!(glm::length(from) > 0)) from = default_view_from();
  Scene framed_part = out;
  std::erase_if(framed_part.objects, [](const Object& o) { return !copied(o); });
  frame_camera(out, scene_bounds(framed_part), from);
  return out;
}

}  // namespace rvr::study
