// What both z-buffers do to a scene before drawing it: each object's material (the built-in grey
// for a scene with no material list), the triangles of the analytic shapes, and the CSG objects
// they skip, named in one warning.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "rvr/shared/expected.h"
#include "rvr/shared/renderer.h"
#include "rvr/shared/scene.h"

namespace rvr {

// The object's material, or `fallback` when the scene has no materials at all.
Expected<const Material*> object_material(const Scene& scene, const Object& o,
                                          const Material& fallback);

// The triangles drawn for an analytic sphere or square.
TriangleMesh tessellate_shape(const Object& o, int sphere_segments);

// Whether the object's primitive ids are the indices of the triangles drawn: a mesh's, and a
// sphere's tessellation when the tracers trace that same tessellation (SphereMode::Mesh), so
// that the two loop orders name the same facet. Otherwise (an analytic sphere, a square) the
// tracer sees one primitive and the z-buffers write 0.
bool names_triangles(const Object& o, SphereMode spheres);

// How the skipped-CSG warning names an object.
std::string object_label(const Object& o, size_t index);

// The warning for the CSG objects a z-buffer cannot draw (`labels` not empty).
std::string skipped_csg_warning(const std::vector<std::string>& labels);

}  // namespace rvr
