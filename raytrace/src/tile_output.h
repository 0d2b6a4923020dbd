// One tile of the tracer's frame, staged before it goes to the frame buffers: the blocks of the
// tile write their pixels here one by one, then the tile is copied out a buffer at a time and a
// row at a time, so that each buffer receives runs of whole tile rows (the z-buffers write
// theirs row by row too) instead of a few bytes to each of six buffers per pixel. The runs go
// with streaming stores (stream_copy.h), as softraster's rows do.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>

#include "rvr/core/framebuffers.h"
#include "rvr/core/stream_copy.h"

namespace rvr {

class TileOutput {
 public:
  static constexpr int kMaxWidth = 64, kMaxHeight = 8;

  // Stages pixels [x0, x1) x [y0, y1) (at most kMaxWidth x kMaxHeight).
  void begin(int x0, int y0, int x1, int y1) {
    x0_ = x0;
    y0_ = y0;
    x1_ = x1;
    y1_ = y1;
  }
  size_t index(int x, int y) const { return size_t(y - y0_) * kMaxWidth + size_t(x - x0_); }

  void set_background(size_t i, const glm::vec3& background) {
    colour[i] = background;
    depth[i] = std::numeric_limits<float>::infinity();
    object_id[i] = kNoId;
    primitive_id[i] = kNoId;
    normal[i] = glm::vec3(0.0f);
    cost[i] = 0.0f;
  }

  // Every staged pixel into fb.
  void write_to(FrameBuffers& fb) const {
    copy_rows(colour, fb.colour.data(), fb);
    copy_rows(normal, fb.normal.data(), fb);
    copy_rows(depth, fb.depth.data(), fb);
    copy_rows(object_id, fb.object_id.data(), fb);
    copy_rows(primitive_id, fb.primitive_id.data(), fb);
    copy_rows(cost, fb.cost.data(), fb);
    if (!fb.lod.empty()) copy_rows(lod, fb.lod.data(), fb);
    stream_fence();
  }

  glm::vec3 colour[kMaxWidth * kMaxHeight];
  glm::vec3 normal[kMaxWidth * kMaxHeight];
  float depth[kMaxWidth * kMaxHeight];
  uint32_t object_id[kMaxWidth * kMaxHeight];
  uint32_t primitive_id[kMaxWidth * kMaxHeight];
  float cost[kMaxWidth * kMaxHeight];
  // Written (and copied out) only when the frame buffers have a lod AOV (a textured scene).
  float lod[kMaxWidth * kMaxHeight];

 private:
  template <class T>
  void copy_rows(const T* from, T* to, const FrameBuffers& fb) const {
    const size_t run = size_t(x1_ - x0_) * sizeof(T);
    for (int y = y0_; y < y1_; ++y)
      stream_copy(static_cast<void*>(to + fb.index(x0_, y)), from + index(x0_, y), run);
  }

  int x0_ = 0, y0_ = 0, x1_ = 0, y1_ = 0;
};

}  // namespace rvr
