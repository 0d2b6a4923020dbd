// The sphere: the scene format's "sphere".
#pragma once

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <utility>
#include <vector>

#include "rvr/core/ray.h"
#include "rvr/core/shapes/scene_field.h"
#include "rvr/core/shapes/shape_geometry.h"
// TriangleForm destroys the mesh it owns: the type must be complete here.
#include "rvr/core/shapes/triangle_mesh.h"  // IWYU pragma: keep

namespace rvr {

struct Sphere {
  glm::vec3 center{0.0f};
  float radius = 1.0f;

  bool operator==(const Sphere&) const = default;

  // Its keys in the scene format (scene_field.h).
  static constexpr const char* kSceneType = "sphere";
  template <class Self, class F>
  static void scene_fields(Self& self, F&& field) {
    field(SceneField{"center", SceneFieldKind::Point, "the centre"}, self.center);
    field(SceneField{"radius", SceneFieldKind::Length, "the radius"}, self.radius);
  }

  // As a shape (shape_geometry.h): its triangle form is a UV sphere (tessellate_sphere), traced
  // instead of the exact sphere under --spheres mesh.
  void bounding_balls(std::vector<BoundingBall>& out) const;
  uint64_t triangle_count(const TessellationOptions& options) const;
  TriangleForm triangle_form(const TessellationOptions& options) const;
  bool traced_analytically(const TessellationOptions& options) const {
    return !options.spheres_as_mesh;
  }

  // What the tracers trace (the members every traced shape has, rvr/core/shapes.h): the sphere
  // itself, whose triangle form lies inside it.
  static constexpr bool kTriangleFormExact = false;
  const Sphere& traced() const { return *this; }
  bool intersect(const Ray& ray, ShapeHit& hit) const;
  glm::vec3 normal_at(const glm::vec3& position, const ShapeHit&) const {
    return (position - center) / radius;
  }
};

// Both roots t0 <= t1 of the ray-sphere quadratic |o + t d - c|^2 = r^2, in the form of
// Ray Tracing Gems ch. 7, which keeps precision when the sphere is small or far away.
// False when the line misses. CSG uses the interval [t0, t1] directly.
inline bool sphere_interval(const Ray& ray, const Sphere& s, float& t0, float& t1) {
  glm::vec3 f = ray.origin - s.center;
  float a = glm::dot(ray.dir, ray.dir);
  float b = -glm::dot(f, ray.dir);      // -b/2 of the textbook quadratic
  glm::vec3 l = f + (b / a) * ray.dir;  // closest approach of the line to the centre
  float disc = a * (s.radius * s.radius - glm::dot(l, l));
  if (disc < 0.0f) return false;
  float c = glm::dot(f, f) - s.radius * s.radius;
  float q = b + std::copysign(std::sqrt(disc), b);
  if (q == 0.0f) {  // origin on the sphere and ray tangent
    t0 = t1 = 0.0f;
    return true;
  }
  t0 = c / q;
  t1 = q / a;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

// Ray-sphere: the nearest root in (tmin, tmax): the near one from outside, the far one from
// inside.
inline bool intersect_sphere(const Ray& ray, const Sphere& s, float& t_hit) {
  float t0, t1;
  if (!sphere_interval(ray, s, t0, t1)) return false;
  if (t0 > ray.tmin && t0 < ray.tmax) {
    t_hit = t0;
    return true;
  }
  if (t1 > ray.tmin && t1 < ray.tmax) {
    t_hit = t1;
    return true;
  }
  return false;
}

inline bool Sphere::intersect(const Ray& ray, ShapeHit& hit) const {
  return intersect_sphere(ray, *this, hit.t);
}

}  // namespace rvr
