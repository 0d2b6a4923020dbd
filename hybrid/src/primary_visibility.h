// What the hybrid's z-buffer saw: per pixel the object and primitive id a visibility buffer
// (FrameBuffers::object_id / primitive_id) holds, and its texture level of detail. Plain data,
// no raster type: ZBufferHits rebuilds each pixel's primary hit from it for the tracer.
#pragma once

#include <cstdint>
#include <span>

namespace rvr {

struct PrimaryVisibility {
  int width = 0;
  int height = 0;
  // Row-major, y = 0 the top row; kNoId where nothing was drawn. primitive_id is the triangle in
  // the object for meshes, 0 for analytic shapes (spheres, squares), as every renderer reports.
  std::span<const uint32_t> object_id;
  std::span<const uint32_t> primitive_id;
  // Empty, or the z-buffer's texture level of detail per pixel (FrameBuffers::lod: NaN where the
  // surface is not textured): a primary hit rebuilt from this buffer samples its texture there.
  std::span<const float> lod;
};

}  // namespace rvr
