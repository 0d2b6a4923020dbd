// The disc: the scene format's "disc", a flat round surface (a lens, a coin, a round mirror, a
// table top), the shape docs/design.md's recipe "Adding a primitive" was written against.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "rvr/core/ray.h"
#include "rvr/core/shapes/scene_field.h"
#include "rvr/core/shapes/shape_geometry.h"
// TriangleForm destroys the mesh it owns: the type must be complete here.
#include "rvr/core/shapes/triangle_mesh.h"  // IWYU pragma: keep

namespace rvr {

// The points of the plane through `center` with unit normal `normal` no farther than `radius`
// from the center.
struct Disc {
  glm::vec3 center{0.0f};
  glm::vec3 normal{0.0f, 1.0f, 0.0f};
  float radius = 1.0f;

  bool operator==(const Disc&) const = default;

  // Its keys in the scene format (scene_field.h).
  static constexpr const char* kSceneType = "disc";
  template <class Self, class F>
  static void scene_fields(Self& self, F&& field) {
    field(SceneField{"center", SceneFieldKind::Point, "the centre"}, self.center);
    field(SceneField{"normal", SceneFieldKind::Direction, "the normal"}, self.normal);
    field(SceneField{"radius", SceneFieldKind::Length, "the radius"}, self.radius);
  }

  // As a shape (shape_geometry.h): the ball of its radius around the center bounds it; its
  // triangle form is a fan of `sphere_segments` triangles around the center whose outer edges
  // touch the circle (tessellate_disc), traced instead of the exact disc under --spheres mesh.
  void bounding_balls(std::vector<BoundingBall>& out) const { out.push_back({center, radius}); }
  uint64_t triangle_count(const TessellationOptions& options) const;
  TriangleForm triangle_form(const TessellationOptions& options) const;
  bool traced_analytically(const TessellationOptions& options) const {
    return !options.spheres_as_mesh;
  }

  // What the tracers trace (the members every traced shape has, rvr/core/shapes.h): the disc
  // itself, which its triangle form covers: a z-buffer never leaves a pixel of the disc empty,
  // and where its polygon covers a pixel centre the disc does not, the hybrids' tracer decides.
  static constexpr bool kTriangleFormExact = false;
  const Disc& traced() const { return *this; }
  bool intersect(const Ray& ray, ShapeHit& hit) const;
  glm::vec3 normal_at(const glm::vec3&, const ShapeHit&) const { return normal; }
};

// Ray-disc: where the ray meets the plane N.(P - center) = 0, if that point is within the radius
// of the center and t is in (tmin, tmax).
inline bool intersect_disc(const Ray& ray, const Disc& disc, float& t_hit) {
  const float denom = glm::dot(disc.normal, ray.dir);
  if (denom == 0.0f) return false;  // parallel
  const float t = glm::dot(disc.normal, disc.center - ray.origin) / denom;
  if (!(t > ray.tmin && t < ray.tmax)) return false;
  const glm::vec3 local = ray.origin + t * ray.dir - disc.center;
  if (glm::dot(local, local) > disc.radius * disc.radius) return false;
  t_hit = t;
  return true;
}

inline bool Disc::intersect(const Ray& ray, ShapeHit& hit) const {
  return intersect_disc(ray, *this, hit.t);
}

// The disc as `segments` (>= 3) triangles around its centre: the regular polygon circumscribed
// about its circle (each outer edge touches it at its midpoint), so that the polygon covers the
// disc. Vertex 0 is the centre, vertex 1 + k the corner at angle 2 pi k / segments from the
// first plane axis (plane_axes) and distance radius / cos(pi / segments); counter-clockwise
// seen from the side the normal points to, flat (no vertex normals).
TriangleMesh tessellate_disc(const Disc& disc, int segments);

}  // namespace rvr
