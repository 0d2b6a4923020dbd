// softraster's triangle stream: every object's triangles, in submission order, set up, binned and
// drawn into a DepthTarget through one view-projection. The camera pass and every face of every
// shadow cube go through it.
#pragma once

#include <stdint.h>
#include <tbb/task_arena.h>

#include <cstddef>
#include <glm/glm.hpp>
#include <optional>
#include <vector>

#include "rvr/core/progress.h"
#include "rvr/core/scene.h"
#include "rvr/core/shapes/csg.h"
#include "rvr/core/shapes/triangle_mesh.h"
#include "soft/tile_raster.h"

namespace rvr::soft {

// What is drawn of one object; tessellated shapes point into meshes the renderer owns. A CSG
// object (`csg` not null) is not in the triangle stream: its mesh, the leaves' tessellations of
// `csg_leaf_triangles` triangles each, is drawn by the CSG pass (csg_pass.h), which writes its
// triangles' ids for shading.
struct DrawObject {
  const TriangleMesh* mesh = nullptr;  // null: nothing to draw
  const Material* material = nullptr;
  bool smooth = false;
  bool use_primitive_id = false;
  const CsgNode* csg = nullptr;
  uint32_t csg_leaf_triangles = 0;
};

struct DrawList {
  std::vector<DrawObject> objects;
  std::vector<size_t> first;  // first[i]: submission index of object i's triangle 0 (a CSG
                              // object submits none)
  size_t triangles() const { return first.empty() ? 0 : first.back(); }
};

DrawList make_draw_list(std::vector<DrawObject> objects);

struct DrawResult {
  size_t clipped = 0, set_up = 0;
  size_t peak_chunk_bytes = 0;
  double setup_seconds = 0, bin_seconds = 0, raster_seconds = 0;
  TileCounters counters;  // summed over tiles
};

// Draws every triangle of `list` into `target` (sized to the viewport) through
// `view_projection`. `progress` (may be null) advances by triangles, with fragments as the rate.
// `keep`, a world plane: only what lies on its positive side is drawn (a planar mirror's view).
DrawResult draw_triangles(const DrawList& list, const glm::dmat4& view_projection,
                          DepthTarget& target, tbb::task_arena& arena, ProgressSink* progress,
                          const std::optional<glm::dvec4>& keep = std::nullopt);

}  // namespace rvr::soft
