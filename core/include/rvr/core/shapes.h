// Every kind of scene object, in one place: visit_shape hands an object's shape to a generic
// function, which calls the members every shape has (rvr/core/shapes/shape_geometry.h). The
// modules that need a shape's bounds, triangle form or triangle count go through here rather
// than switching on ObjectType themselves.
#pragma once

#include <variant>

#include "rvr/core/scene.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/disc.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/square.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {

// The shapes the tracers trace analytically, as each shape's traced() gives them. Each has
//   static constexpr bool kTriangleFormExact;  // its triangle form is exactly it (the square)
//   void bounding_balls(std::vector<BoundingBall>& out) const;
//   bool intersect(const Ray& ray, ShapeHit& hit) const;  // nearest hit in (tmin, tmax)
//   glm::vec3 normal_at(const glm::vec3& position, const ShapeHit& hit) const;  // outward
using TracedShape = std::variant<Sphere, Square::Traced, CsgSolid::Traced, Disc>;

// f(shape) for the object's shape: a TriangleMesh, Sphere, Square, CsgSolid or Disc.
template <class F>
decltype(auto) visit_shape(const Object& o, F&& f) {
  switch (o.type) {
    case ObjectType::Sphere:
      return f(o.sphere);
    case ObjectType::Plane:
      return f(o.plane);
    case ObjectType::Csg:
      return f(CsgSolid{o.csg.get()});
    case ObjectType::Disc:
      return f(o.disc);
    case ObjectType::Triangles:
      break;
  }
  return f(o.mesh);
}

}  // namespace rvr
