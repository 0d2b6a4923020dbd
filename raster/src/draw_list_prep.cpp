// What both z-buffers do to a scene before drawing it (see draw_list_prep.h).
#include "draw_list_prep.h"

#include <fmt/format.h>

#include "rvr/shared/tessellate.h"

namespace rvr {

Expected<const Material*> object_material(const Scene& scene, const Object& o,
                                          const Material& fallback) {
  if (o.material < scene.materials.size()) return &scene.materials[o.material];
  if (!scene.materials.empty())
    return bad_input(
        fmt::format("object '{}': material index {} out of range", o.name, o.material));
  return &fallback;  // a hand-made scene with no material list: the built-in grey
}

TriangleMesh tessellate_shape(const Object& o, int sphere_segments) {
  return o.type == ObjectType::Sphere ? tessellate_sphere(o.sphere, sphere_segments)
                                      : tessellate_plane(o.plane);
}

bool names_triangles(const Object& o, SphereMode spheres) {
  return o.type == ObjectType::Triangles ||
         (o.type == ObjectType::Sphere && spheres == SphereMode::Mesh);
}

std::string object_label(const Object& o, size_t index) {
  return o.name.empty() ? fmt::format("csg#{}", index) : o.name;
}

std::string skipped_csg_warning(const std::vector<std::string>& labels) {
  std::string names;
  for (const std::string& s : labels) names += (names.empty() ? "" : ", ") + s;
  return fmt::format("csg objects have no z-buffer form: skipped {} ({})", labels.size(), names);
}

}  // namespace rvr
