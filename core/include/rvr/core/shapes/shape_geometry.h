// The vocabulary every shape describes its geometry in for the other modules: the balls that
// bound it (camera framing), what its triangle form is asked with, and that triangle form (what
// the z-buffers draw, and what the tracers trace where they do not trace the shape analytically).
// Each shape type (shapes/*.h) provides, as members:
//   void bounding_balls(std::vector<BoundingBall>& out) const;
//   uint64_t triangle_count(const TessellationOptions& options) const;  // of its triangle form
//   TriangleForm triangle_form(const TessellationOptions& options) const;
//   bool traced_analytically(const TessellationOptions& options) const;
// and rvr/core/shapes.h lists the shapes.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>

namespace rvr {

struct TriangleMesh;

// A point with a radius (0 for a vertex); a shape lies inside the union of its balls.
struct BoundingBall {
  glm::vec3 centre{0.0f};
  float radius = 0.0f;
};

// How the renderers ask for triangle forms: spheres as UV spheres of `sphere_segments`
// longitudes; `spheres_as_mesh`: the tracers trace spheres as those triangles (--spheres mesh).
struct TessellationOptions {
  int sphere_segments = 64;
  bool spheres_as_mesh = false;
};

// A shape's triangle form. `mesh` null: it has none (a CSG solid, which no z-buffer draws).
struct TriangleForm {
  const TriangleMesh* mesh = nullptr;
  std::unique_ptr<const TriangleMesh> made;  // owns `mesh` when it was made for the shape
  bool is_object_mesh = false;               // `mesh` is the object's own (textures apply)
  // The triangles' indices are the primitive ids the tracers report too: the tracers trace these
  // very triangles (a mesh; a sphere under --spheres mesh). Otherwise the tracers see one
  // primitive and report 0.
  bool names_triangles = false;
};

}  // namespace rvr
