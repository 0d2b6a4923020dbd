// A triangle's texture coordinates and vertex colours at a point inside it, and the base colour
// the shading equation uses there: material diffuse x texture sample x vertex colour. Every
// renderer evaluates the base colour through these functions with its own barycentrics and its
// own level of detail (rvr/core/texture.h).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>

#include "rvr/core/scene.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {

// Whether the object's surface varies in colour: a textured material (with a readable texture)
// on a mesh with uvs, or a mesh with vertex colours. Flat-coloured surfaces need none of this.
bool varies_in_colour(const Scene& scene, const Object& object);
bool textured(const Scene& scene, const Object& object);

// The triangle's uv (after the material's uv_transform) and vertex colour at barycentrics
// (1 - b1 - b2, b1, b2) of its corners. Callers check mesh.textured() / mesh.coloured().
glm::vec2 triangle_uv(const TriangleMesh& mesh, const Material& m, uint32_t triangle, float b1,
                      float b2);
glm::vec3 triangle_colour(const TriangleMesh& mesh, uint32_t triangle, float b1, float b2);

// The triangle's area in uv space (after the uv_transform) and in world space, for a ray cone's
// triangle constant (triangle_lod_constant).
float triangle_uv_area(const TriangleMesh& mesh, const Material& m, uint32_t triangle);
float triangle_world_area(const TriangleMesh& mesh, uint32_t triangle);

// The base colour at a point of a triangle: m.diffuse, times the texture sampled at the uv with
// level of detail `lod` when textured(scene, object), times the vertex colour when the mesh has
// them. For any other surface, m.diffuse.
glm::vec3 base_colour(const Scene& scene, const Object& object, const Material& m,
                      uint32_t triangle, float b1, float b2, float lod);

// m with its diffuse replaced by `diffuse` (what the shading kernels take per pixel).
inline Material with_diffuse(Material m, const glm::vec3& diffuse) {
  m.diffuse = diffuse;
  return m;
}

}  // namespace rvr
