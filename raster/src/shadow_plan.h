// Full mode's shadow cube maps, planned once for both z-buffers (GlRasterizer, SoftRasterizer):
// every light sample (a point light, or one stratum centre of an area light) gets a cube of six
// 90 degree faces around it, each texel the distance to the nearest surface. The plan checks
// the options, shrinks the side to a texel budget (with a warning), batches the samples whose
// cubes fit in memory at once, and places the faces' near and far planes; each z-buffer draws
// and samples the cubes its own way.
#pragma once

#include <array>
#include <cstddef>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "rvr/core/expected.h"
#include "rvr/core/renderer.h"
#include "rvr/core/scene.h"

namespace rvr {

struct ShadowMapPlan {
  int size = 0;          // texels per side of a cube face
  size_t batch = 1;      // light samples whose cubes are held and drawn at once
  float near_plane = 0;  // of every face's 90 degree projection: they only clip, as the maps
  float far_plane = 0;   // hold distances (1e-6 and 2x the scene's reach from the lights)
};

// The plan for `samples` light samples (at least one): options.shadow_map_size and
// shadow_bias checked (bad input when not positive / negative), the side at most `max_side`
// and shrunk to the texel budget, the batch at most `max_batch`; `lo`, `hi` bound the scene's
// geometry (`any_geometry` false: an empty scene, reach 1).
Expected<ShadowMapPlan> plan_shadow_maps(const RenderOptions& options,
                                         const std::vector<LightSample>& samples, int max_side,
                                         size_t max_batch, const glm::vec3& lo, const glm::vec3& hi,
                                         bool any_geometry, std::vector<std::string>& warnings);

// Face f of every cube looks along the f-th axis direction (0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z:
// the GL shader's cube_face() and soft/shadow_cube.cpp use the same order); these rotate world
// directions into each face's eye space (looking down -z).
const std::array<glm::mat3, 6>& cube_face_rotations();

}  // namespace rvr
