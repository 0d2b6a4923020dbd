// Constructive solid geometry over spheres: the scene format's "csg".
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <vector>

#include "rvr/core/ray.h"
#include "rvr/core/shapes/shape_geometry.h"
#include "rvr/core/shapes/sphere.h"
// TriangleForm destroys the mesh it owns: the type must be complete here.
#include "rvr/core/shapes/triangle_mesh.h"  // IWYU pragma: keep

namespace rvr {

enum class CsgOp { Union, Intersection, Difference };

// A CSG tree: leaves are spheres, inner nodes combine two solids.
struct CsgNode {
  bool is_leaf = true;
  Sphere sphere;  // leaf
  CsgOp op = CsgOp::Union;
  std::shared_ptr<const CsgNode> a, b;  // inner node
};

// A CSG object's tree as a shape (shape_geometry.h): its leaves bound it; it has no triangle
// form (no z-buffer draws it); the tracers trace it exactly.
struct CsgSolid {
  const CsgNode* root = nullptr;
  bool operator==(const CsgSolid&) const = default;

  void bounding_balls(std::vector<BoundingBall>& out) const;
  uint64_t triangle_count(const TessellationOptions&) const { return 0; }
  TriangleForm triangle_form(const TessellationOptions&) const { return {}; }
  bool traced_analytically(const TessellationOptions&) const { return true; }
  struct Traced;
  Traced traced() const;
};

// The solid as the tracers trace it: along a ray, every leaf gives an interval, combined by the
// tree's operations; a hit's `part` is the leaf sphere whose surface it is (depth-first order).
struct CsgSolid::Traced {
  const CsgNode* root = nullptr;
  std::vector<Sphere> leaves;  // depth-first

  static constexpr bool kTriangleFormExact = false;  // it has none
  void bounding_balls(std::vector<BoundingBall>& out) const;
  bool intersect(const Ray& ray, ShapeHit& hit) const;
  glm::vec3 normal_at(const glm::vec3& position, const ShapeHit& hit) const;
};

}  // namespace rvr
