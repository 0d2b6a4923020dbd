// Every kind of scene object, in one place: visit_shape hands an object's shape to a generic
// function, which calls the members every shape has (rvr/core/shapes/shape_geometry.h). The
// modules that need a shape's bounds, triangle form or triangle count go through here rather
// than switching on ObjectType themselves.
#pragma once

#include <type_traits>
#include <utility>
#include <variant>

#include "rvr/core/scene.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/shape_list.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {

// The shapes the tracers trace analytically, as each shape's traced() gives them. Each has
//   static constexpr bool kTriangleFormExact;  // its triangle form is exactly it (the square)
//   void bounding_balls(std::vector<BoundingBall>& out) const;
//   bool intersect(const Ray& ray, ShapeHit& hit) const;  // nearest hit in (tmin, tmax)
//   glm::vec3 normal_at(const glm::vec3& position, const ShapeHit& hit) const;  // outward
template <class Shape>
using TracedFormOf = std::decay_t<decltype(std::declval<const Shape&>().traced())>;
#define RVR_TRACED_FORM(Type, Enumerator, member) TracedFormOf<Type>,
using TracedShape = std::variant<RVR_ANALYTIC_SHAPES(RVR_TRACED_FORM) CsgSolid::Traced>;
#undef RVR_TRACED_FORM

// f(shape) for the object's shape: a TriangleMesh, a CsgSolid or an analytic shape of
// shape_list.h.
template <class F>
decltype(auto) visit_shape(const Object& o, F&& f) {
#define RVR_VISIT_SHAPE(Type, Enumerator, member) \
  if (o.type == ObjectType::Enumerator) return f(o.member);
  RVR_ANALYTIC_SHAPES(RVR_VISIT_SHAPE)
#undef RVR_VISIT_SHAPE
  if (o.type == ObjectType::Csg) return f(CsgSolid{o.csg.get()});
  return f(o.mesh);
}

}  // namespace rvr
