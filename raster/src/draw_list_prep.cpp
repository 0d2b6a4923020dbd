// What both z-buffers do to a scene before drawing it (see draw_list_prep.h).
#include "draw_list_prep.h"

#include <fmt/format.h>
#include <stddef.h>

#include <algorithm>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <utility>
#include <vector>

#include "rvr/core/check.h"
#include "rvr/core/shapes.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/shape_geometry.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/tessellate.h"

namespace rvr {

namespace {

// The object's material, or `fallback` when the scene has no materials at all.
Expected<const Material*> object_material(const Scene& scene, const Object& o,
                                          const Material& fallback) {
  if (o.material < scene.materials.size()) return &scene.materials[o.material];
  if (!scene.materials.empty())
    return bad_input(
        fmt::format("object '{}': material index {} out of range", o.name, o.material));
  return &fallback;  // a hand-made scene with no material list: the built-in grey
}

// The leaves of a CSG tree (depth-first) as UV spheres of `segments` longitudes, one mesh after
// another in one mesh.
TriangleMesh csg_leaf_meshes(const CsgNode* root, int segments) {
  TriangleMesh all;
  for (const Sphere& leaf : csg_leaves(root)) {
    const TriangleMesh m = tessellate_sphere(leaf, segments);
    const uint32_t base = uint32_t(all.positions.size());
    all.positions.insert(all.positions.end(), m.positions.begin(), m.positions.end());
    all.normals.insert(all.normals.end(), m.normals.begin(), m.normals.end());
    for (const glm::uvec3& t : m.triangles) all.triangles.push_back(t + base);
  }
  return all;
}

// Whether the mesh's attributes match its positions and its triangles index only those.
Status check_mesh(const TriangleMesh& m, const std::string& name) {
  const size_t n = m.positions.size();
  if (m.smooth() && m.normals.size() != n)
    return bad_input(
        fmt::format("object '{}': {} normals for {} positions", name, m.normals.size(), n));
  if (m.textured() && m.uvs.size() != n)
    return bad_input(
        fmt::format("object '{}': {} texture coordinates for {} positions", name, m.uvs.size(), n));
  if (m.coloured() && m.colours.size() != n)
    return bad_input(
        fmt::format("object '{}': {} vertex colours for {} positions", name, m.colours.size(), n));
  for (const glm::uvec3& tri : m.triangles)
    if (std::max({tri.x, tri.y, tri.z}) >= n)
      return bad_input(
          fmt::format("object '{}': triangle index out of range ({} positions)", name, n));
  return ok_status();
}

}  // namespace

Expected<PreparedScene> prepare_objects(const Scene& scene, SphereMode spheres, int sphere_segments,
                                        std::span<const uint32_t> left_out) {
  PreparedScene prepared;
  prepared.fallback = std::make_unique<const Material>(default_material());
  prepared.objects.resize(scene.objects.size());
  std::vector<uint8_t> drawn(scene.objects.size(), 1);
  for (uint32_t object : left_out) {
    RVR_CHECK(object < drawn.size(), "an object left out of the z-buffer is a scene object");
    drawn[object] = 0;
  }
  const TessellationOptions tessellation{sphere_segments, spheres == SphereMode::Mesh};
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const Object& o = scene.objects[i];
    PreparedObject& p = prepared.objects[i];
    RVR_TRY_ASSIGN(material, object_material(scene, o, *prepared.fallback));
    p.material = *material;
    if (!drawn[i]) continue;
    if (o.type == ObjectType::Csg) {
      auto leaves = std::make_unique<TriangleMesh>(csg_leaf_meshes(o.csg.get(), sphere_segments));
      p.mesh = leaves.get();
      p.smooth = true;
      p.csg = o.csg.get();
      p.csg_leaf_triangles = uint32_t(sphere_triangle_count(sphere_segments));
      prepared.tessellations.push_back(std::move(leaves));
      continue;
    }
    TriangleForm form =
        visit_shape(o, [&](const auto& shape) { return shape.triangle_form(tessellation); });
    RVR_CHECK(form.mesh != nullptr, "every shape but a CSG solid has a triangle form");
    p.mesh = form.mesh;
    p.own_mesh = form.is_object_mesh;
    p.names_triangles = form.names_triangles;
    if (form.made) prepared.tessellations.push_back(std::move(form.made));
    RVR_TRY(check_mesh(*p.mesh, o.name));
    p.smooth = p.mesh->smooth();
  }
  RVR_CHECK(prepared.objects.size() == scene.objects.size(),
            "one prepared entry per scene object, so its index is the object id");
  return prepared;
}

}  // namespace rvr
