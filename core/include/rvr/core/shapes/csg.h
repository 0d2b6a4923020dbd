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

// One leaf's interval on a line, in the line's parameter: the line enters the leaf at `enter`
// and leaves it at `leave` (enter < leave); `hit` false: it misses the leaf.
// `enter_facet` and `leave_facet`: the triangles crossed there when the leaf is tessellated.
struct CsgInterval {
  double enter = 0.0, leave = 0.0;
  bool hit = false;
  uint32_t enter_facet = 0, leave_facet = 0;
};

// Where a line crosses the boundary of a CSG solid: at `t`, into the solid (`entering`) or out
// of it, on the surface of leaf `leaf` (depth-first number), on its triangle `facet` when it is
// tessellated; `flip`: that surface's outward normal points into the solid (the surface of a
// subtracted leaf).
struct CsgBoundary {
  double t = 0.0;
  bool entering = false;
  uint32_t leaf = 0;
  bool flip = false;
  uint32_t facet = 0;
};

// The solid's first boundary on a line strictly inside (t_min, t_max), from every leaf's interval
// on that line (`leaves`, depth-first, one per leaf of `root`); false when there is none. The
// tracers take the intervals from their rays, the z-buffers from depth passes over each leaf's
// front and back faces: both combine them here.
bool first_csg_boundary(const CsgNode* root, const CsgInterval* leaves, double t_min, double t_max,
                        CsgBoundary& out);

// The leaf spheres of `root`, depth-first.
std::vector<Sphere> csg_leaves(const CsgNode* root);

// A CSG object's tree as a shape (shape_geometry.h): its leaves bound it; it has no triangle
// form (a z-buffer draws its leaves' tessellations, pass by pass, and combines them per pixel);
// the tracers trace it exactly, or with leaves as the z-buffers' tessellations under
// --spheres mesh.
struct CsgSolid {
  const CsgNode* root = nullptr;
  bool operator==(const CsgSolid&) const = default;

  void bounding_balls(std::vector<BoundingBall>& out) const;
  uint64_t triangle_count(const TessellationOptions&) const { return 0; }
  TriangleForm triangle_form(const TessellationOptions&) const { return {}; }
  bool traced_analytically(const TessellationOptions&) const { return true; }
  struct Traced;
  Traced traced() const;
  Traced traced(const TessellationOptions& options) const;
};

// The solid as the tracers trace it: along a ray, every leaf gives an interval (the exact
// sphere's, or its tessellation's when `leaf_meshes` is not empty), combined by the tree's
// operations; a hit's `part` is the leaf whose surface it is (depth-first order), or with
// tessellated leaves leaf * leaf_triangles + the triangle crossed (its normals are interpolated,
// as the z-buffers interpolate them).
struct CsgSolid::Traced {
  const CsgNode* root = nullptr;
  std::vector<Sphere> leaves;             // depth-first
  std::vector<TriangleMesh> leaf_meshes;  // empty, or leaves[i]'s UV sphere
  uint32_t leaf_triangles = 0;            // triangles of each leaf mesh

  static constexpr bool kTriangleFormExact = false;  // it has none
  void bounding_balls(std::vector<BoundingBall>& out) const;
  bool intersect(const Ray& ray, ShapeHit& hit) const;
  glm::vec3 normal_at(const glm::vec3& position, const ShapeHit& hit) const;
  // With tessellated leaves: the plane normal of the triangle crossed (the geometric normal a
  // z-buffer sees there), reversed with the surface; with exact leaves: normal_at's.
  glm::vec3 geometric_normal_at(const glm::vec3& position, const ShapeHit& hit) const;
};

}  // namespace rvr
