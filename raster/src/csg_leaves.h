// CSG in a z-buffer, after Goldfeather et al. for convex primitives: every leaf of rvr's CSG
// trees is a sphere, drawn as its tessellation, a closed convex mesh. Along a pixel's ray such
// a mesh is entered once, at its nearest triangle that faces the eye, and left once, at its
// nearest triangle that faces away. So two ordinary depth passes per leaf, one over each half
// of its triangles, give every pixel that leaf's interval, and the tree combines the intervals
// per pixel as the tracer combines them per ray (first_csg_boundary). The surface found is
// written into the frame where it is nearer than what the frame holds.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/sphere.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {

// One leaf's triangles split by which side of them an eye is on. `front_triangle[j]` is the
// index in the leaf's mesh of `front.triangles[j]` (the same for `back`).
struct CsgLeafFaces {
  TriangleMesh front, back;
  std::vector<uint32_t> front_triangle, back_triangle;
};

// The triangles `first` .. `first + count` of `mesh` (a leaf's closed convex tessellation around
// `centre`) that face `eye` and those that face away, each with the positions it indexes.
CsgLeafFaces split_by_facing(const TriangleMesh& mesh, uint32_t first, uint32_t count,
                             const glm::vec3& centre, const glm::vec3& eye);

// Where a leaf can show in a view of width x height pixels, rows from the top: the pixel box
// around the projection of its sphere's bounding cube, a pixel wider on each side; the whole
// frame when a corner lies behind the eye's plane (its projection is unbounded); empty off
// screen. [x0, x1) x [y0, y1).
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x0 >= x1 || y0 >= y1; }
};

PixelBox leaf_box(const Sphere& leaf, const glm::dmat4& view_projection, int width, int height);

// A leaf's interval along a pixel's ray from what its two depth passes left at the pixel: the
// nearest depth of its triangles facing the eye (`enter`, on triangle `enter_facet`) and of those
// facing away (`leave`, on `leave_facet`), +inf where that half covered nothing. A convex leaf
// whose front half is not seen where its back half is was entered before the near plane; one
// whose back half is not seen is left past the far plane.
CsgInterval pixel_interval(double enter, double leave, uint32_t enter_facet, uint32_t leave_facet);

}  // namespace rvr
