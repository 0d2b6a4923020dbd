// A scene or model file grown for the study: N copies of its geometry side by side in a grid,
// so that triangles grow while each copy keeps its own shape, size and screen share per copy.
#pragma once

#include <cstddef>

#include "rvr/core/expected.h"
#include "rvr/core/scene.h"

namespace rvr::study {

// `copies` copies of `base`'s meshes and spheres in a near-square grid of columns along +x and
// rows along +y, one bounding diameter and a tenth apart; planes and CSG objects are kept once
// (copying a floor or a CSG tree would not grow what the loop orders iterate over). The camera
// is framed on the grid from the base camera's direction (camera_framing.h), the image size,
// materials and lights kept. BadInput when `base` has no mesh or sphere to copy.
Expected<Scene> grid_of_copies(const Scene& base, size_t copies);

}  // namespace rvr::study
