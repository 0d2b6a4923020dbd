// Shadow maps for softraster's full mode, the triangle-major answer to shadow rays as the GL
// raster's are: one cube of six 90-degree faces around each light sample, each texel holding the
// distance |P - L| of the nearest surface seen through it, drawn by softraster's own z-buffer
// (draw_triangles into a depth-only DepthTarget). The lookup is the GL raster's
// shadow_visibility (gl_shaders.h) in C++: normal offset, constant plus slope-scaled bias,
// optional 3x3 percentage-closer filtering within a face.
#pragma once

#include <tbb/task_arena.h>

#include <array>
#include <glm/glm.hpp>
#include <vector>

#include "soft/draw_triangles.h"
#include "soft/tile_raster.h"

namespace rvr::soft {

struct ShadowSettings {
  int size = 1024;     // texels per face side
  float bias = 0.01f;  // constant part, scene units
  bool pcf = false;
  glm::dmat4 projection{1.0};  // 90 degrees, square, near/far from the scene's reach
};

class ShadowCube {
 public:
  // Draws every triangle of `list` into the six faces around `light`, through `scratch` (a
  // depth-only target of size x size, cleared here for each face).
  void build(const DrawList& list, const glm::vec3& light, const ShadowSettings& settings,
             DepthTarget& scratch, tbb::task_arena& arena, DrawResult& work);

  // 1 when P is lit by the sample (|P - L| - bias within the stored distance), 0 when shadowed;
  // with PCF the mean over 3x3 texels.
  float visibility(const glm::vec3& P, const glm::vec3& L, const glm::vec3& geometric_normal,
                   const ShadowSettings& settings) const;

 private:
  int size_ = 0;
  std::array<std::vector<float>, 6> distance_;  // row 0 at the top of each face, as drawn
};

}  // namespace rvr::soft
