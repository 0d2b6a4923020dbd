// The square: the scene format's "plane" (ObjectType::Plane), finite so that it can be drawn.
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "rvr/core/ray.h"
#include "rvr/core/shapes/scene_field.h"
#include "rvr/core/shapes/shape_geometry.h"
// TriangleForm destroys the mesh it owns: the type must be complete here.
#include "rvr/core/shapes/triangle_mesh.h"  // IWYU pragma: keep

namespace rvr {

// A square of side 2*half_size centred at point, facing normal (unit length).
struct Square {
  glm::vec3 point{0.0f};
  glm::vec3 normal{0.0f, 1.0f, 0.0f};
  float half_size = 10.0f;

  bool operator==(const Square&) const = default;

  // Its keys in the scene format (scene_field.h): the file calls it a "plane".
  static constexpr const char* kSceneType = "plane";
  template <class Self, class F>
  static void scene_fields(Self& self, F&& field) {
    field(SceneField{"point", SceneFieldKind::Point, "the point"}, self.point);
    field(SceneField{"normal", SceneFieldKind::Direction, "the normal"}, self.normal);
    field(SceneField{"half_size", SceneFieldKind::Length, "half_size", false}, self.half_size);
  }

  // As a shape (shape_geometry.h): its corners bound it; its triangle form is two triangles
  // (tessellate_plane); the tracers always trace it exactly.
  void bounding_balls(std::vector<BoundingBall>& out) const;
  uint64_t triangle_count(const TessellationOptions& options) const;
  TriangleForm triangle_form(const TessellationOptions& options) const;
  bool traced_analytically(const TessellationOptions&) const { return true; }
  struct Traced;
  Traced traced() const;
};

// Ray-plane: the plane equation N.(P - point) = 0, then the square's bounds along the
// plane's axes (u, v from plane_axes).
inline bool intersect_square(const Ray& ray, const Square& plane, const glm::vec3& u,
                             const glm::vec3& v, float& t_hit) {
  float denom = glm::dot(plane.normal, ray.dir);
  if (denom == 0.0f) return false;  // parallel
  float t = glm::dot(plane.normal, plane.point - ray.origin) / denom;
  if (!(t > ray.tmin && t < ray.tmax)) return false;
  glm::vec3 local = ray.origin + t * ray.dir - plane.point;
  if (std::abs(glm::dot(local, u)) > plane.half_size) return false;
  if (std::abs(glm::dot(local, v)) > plane.half_size) return false;
  t_hit = t;
  return true;
}

// The square as the tracers trace it, with its axes (plane_axes) worked out once.
struct Square::Traced {
  Square square;
  glm::vec3 axis_u{0.0f}, axis_v{0.0f};

  static constexpr bool kTriangleFormExact = true;
  void bounding_balls(std::vector<BoundingBall>& out) const { square.bounding_balls(out); }
  bool intersect(const Ray& ray, ShapeHit& hit) const {
    return intersect_square(ray, square, axis_u, axis_v, hit.t);
  }
  glm::vec3 normal_at(const glm::vec3&, const ShapeHit&) const { return square.normal; }
};

}  // namespace rvr
