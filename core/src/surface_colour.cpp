#include "rvr/core/surface_colour.h"

#include <stddef.h>

#include <cmath>
#include <memory>
#include <vector>

#include "rvr/core/check.h"
#include "rvr/core/texture.h"

namespace rvr {

bool textured(const Scene& scene, const Object& object) {
  if (object.type != ObjectType::Triangles || !object.mesh.textured()) return false;
  if (object.material >= scene.materials.size()) return false;
  const int32_t t = scene.materials[object.material].texture;
  return t >= 0 && size_t(t) < scene.textures.size() && scene.textures[size_t(t)].mips;
}

bool varies_in_colour(const Scene& scene, const Object& object) {
  return textured(scene, object) ||
         (object.type == ObjectType::Triangles && object.mesh.coloured());
}

glm::vec2 triangle_uv(const TriangleMesh& mesh, const Material& m, uint32_t triangle, float b1,
                      float b2) {
  const glm::uvec3 t = mesh.triangles[triangle];
  RVR_DCHECK(mesh.uvs.size() == mesh.positions.size() && t.x < mesh.uvs.size() &&
                 t.y < mesh.uvs.size() && t.z < mesh.uvs.size(),
             "uvs are per position (the loaders check the counts)");
  const glm::vec2 uv = (1.0f - b1 - b2) * mesh.uvs[t.x] + b1 * mesh.uvs[t.y] + b2 * mesh.uvs[t.z];
  return m.uv_transform.apply(uv);
}

glm::vec3 triangle_colour(const TriangleMesh& mesh, uint32_t triangle, float b1, float b2) {
  const glm::uvec3 t = mesh.triangles[triangle];
  RVR_DCHECK(mesh.colours.size() == mesh.positions.size() && t.x < mesh.colours.size() &&
                 t.y < mesh.colours.size() && t.z < mesh.colours.size(),
             "vertex colours are per position (the loaders check the counts)");
  return (1.0f - b1 - b2) * mesh.colours[t.x] + b1 * mesh.colours[t.y] + b2 * mesh.colours[t.z];
}

float triangle_uv_area(const TriangleMesh& mesh, const Material& m, uint32_t triangle) {
  const glm::uvec3 t = mesh.triangles[triangle];
  const glm::vec2 a = m.uv_transform.apply(mesh.uvs[t.x]);
  const glm::vec2 e1 = m.uv_transform.apply(mesh.uvs[t.y]) - a;
  const glm::vec2 e2 = m.uv_transform.apply(mesh.uvs[t.z]) - a;
  return 0.5f * std::abs(e1.x * e2.y - e1.y * e2.x);
}

float triangle_world_area(const TriangleMesh& mesh, uint32_t triangle) {
  const glm::uvec3 t = mesh.triangles[triangle];
  const glm::vec3 a = mesh.positions[t.x];
  return 0.5f * glm::length(glm::cross(mesh.positions[t.y] - a, mesh.positions[t.z] - a));
}

glm::vec3 base_colour(const Scene& scene, const Object& object, const Material& m,
                      uint32_t triangle, float b1, float b2, float lod) {
  glm::vec3 colour = m.diffuse;
  if (object.type != ObjectType::Triangles) return colour;
  if (textured(scene, object)) {
    const Texture& tex = scene.textures[size_t(m.texture)];
    RVR_DCHECK(triangle < object.mesh.triangles.size(), "the hit triangle is the object's");
    colour *= sample_texture(tex, triangle_uv(object.mesh, m, triangle, b1, b2), lod);
  }
  if (object.mesh.coloured()) colour *= triangle_colour(object.mesh, triangle, b1, b2);
  return colour;
}

}  // namespace rvr
