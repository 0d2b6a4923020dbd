// softraster's CSG solids (csg_leaves.h): after a view's triangle stream, each CSG object of the
// draw list is drawn leaf by leaf, two depth passes per leaf (its triangles that face the eye,
// then those that face away) into a target of its own, and combined per pixel by the object's
// tree; the surface found is written into the view's target where it is nearer, with the ids and
// barycentrics of the leaf triangle it lies on, so that shading treats it like any triangle.
#pragma once

#include <tbb/task_arena.h>

#include <cstddef>
#include <glm/glm.hpp>
#include <optional>

#include "soft/draw_triangles.h"
#include "soft/tile_raster.h"

namespace rvr::soft {

struct CsgPassResult {
  size_t objects = 0;      // CSG objects drawn
  size_t leaf_passes = 0;  // depth passes, two per leaf
  size_t pixels = 0;       // pixels where a CSG surface was written
  DrawResult drawn;        // the leaf passes' counts, summed
};

// Draws every CSG object of `list` through `view_projection`, as seen from `eye` (the view's
// centre of projection), into `target`, after the triangle stream drew the rest. `keep` as in
// draw_triangles.
CsgPassResult draw_csg_objects(const DrawList& list, const glm::dmat4& view_projection,
                               const glm::vec3& eye, const std::optional<glm::dvec4>& keep,
                               DepthTarget& target, tbb::task_arena& arena);

}  // namespace rvr::soft
