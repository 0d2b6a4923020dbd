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
  // Row-major, y = 0 the top row; object_id kNoId where nothing was drawn. primitive_id is read
  // only where an object was drawn, and is then the triangle in the object for meshes; for
  // analytic shapes (squares) it is ignored (0 from GL, the tessellation's triangle from
  // softraster's ids-only pass, RenderOptions::visibility_ids_only).
  std::span<const uint32_t> object_id;
  std::span<const uint32_t> primitive_id;
  // Empty, or the z-buffer's texture level of detail per pixel (FrameBuffers::lod: NaN where the
  // surface is not textured): a primary hit rebuilt from this buffer samples its texture there.
  std::span<const float> lod;
};

}  // namespace rvr
