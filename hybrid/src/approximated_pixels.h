// Where a z-buffer may leave a pixel empty that the tracer would not: inside the screen bounds of
// the shapes it draws only approximately or not at all.
#pragma once

#include <cstdint>
#include <vector>

#include "rvr/core/scene.h"
#include "rvr/raytrace/trace_geometry.h"

namespace rvr {

// 1 at the pixels inside the screen bounds of a shape that a z-buffer draws approximately or not
// at all (TraceGeometry::approximated_bounds), row-major over the scene's image; empty where no
// such shape's bounds reach the image (a frame of triangles alone), so that nothing scans zeros.
std::vector<uint8_t> approximated_pixels(const Scene& scene, const TraceGeometry& geometry);

}  // namespace rvr
