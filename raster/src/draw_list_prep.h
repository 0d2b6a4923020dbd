// What both z-buffers do to a scene before drawing it: each object classified once into what is
// drawn for it (its material, the built-in grey for a scene with no material list; its triangles,
// the object's own mesh or the tessellation of an analytic shape; whether those are smooth and
// whether their indices are the primitive ids), and the CSG objects they skip, named in one
// warning.
#pragma once

#include <stdint.h>

#include <memory>
#include <span>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/triangle_mesh.h"

namespace rvr {

// One scene object as a z-buffer draws it. A CSG object (`csg` not null): `mesh` holds its
// leaves' tessellations one after another, `csg_leaf_triangles` triangles each (depth-first
// order), drawn leaf by leaf and combined per pixel (csg_leaves.h), not as one mesh.
struct PreparedObject {
  const Material* material = nullptr;
  const TriangleMesh* mesh = nullptr;  // the object's own mesh, or a tessellation of the scene
  bool own_mesh = false;               // `mesh` is the object's mesh (textures apply to it)
  bool smooth = false;                 // the mesh has vertex normals
  // Whether the object's primitive ids are the indices of the triangles drawn: a mesh's, and a
  // sphere's tessellation when the tracers trace that same tessellation (SphereMode::Mesh), so
  // that the two loop orders name the same facet. Otherwise (an analytic sphere, a square) the
  // tracer sees one primitive and the z-buffers write 0.
  bool names_triangles = false;
  const CsgNode* csg = nullptr;
  uint32_t csg_leaf_triangles = 0;
};

// A scene prepared for a z-buffer. Owns the tessellations and the fallback material the objects
// point to, so it must outlive every use of them; moving it keeps the pointers valid.
struct PreparedScene {
  std::vector<PreparedObject> objects;  // one per scene object, in scene order
  std::vector<std::unique_ptr<const TriangleMesh>> tessellations;
  std::unique_ptr<const Material> fallback;  // the built-in grey
};

// Every object of `scene` prepared, spheres tessellated with `sphere_segments` and named as
// `spheres` says; the objects `left_out` (scene indices) get their material only, no mesh, so
// nothing is drawn for them and the others keep their ids. Bad input: a material index out of
// range, or a mesh whose normals, texture coordinates or vertex colours do not match its positions,
// or whose triangles index past them.
Expected<PreparedScene> prepare_objects(const Scene& scene, SphereMode spheres, int sphere_segments,
                                        std::span<const uint32_t> left_out = {});

}  // namespace rvr
