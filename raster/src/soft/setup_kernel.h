// softraster's batched triangle setup: the triangles that need no clipping, gathered in SoA
// batches and set up by a kernel compiled once per instruction set (kernels/, chosen with the
// fill kernel). It repeats TriangleSetup::emit's arithmetic exactly, so every SetupTriangle is
// the same bytes as the scalar path's. Plain data only, as fill_kernel.h.
#pragma once

#include <cstdint>

#include "soft/setup_triangle.h"

namespace rvr::soft {

// Snapping moves a vertex by at most half a sub-pixel step in x and in y.
constexpr double kSnapDistance = 0.7072 / double(kSub);

// Triangles per kernel call: enough to amortize the call and fill vectors after the empty ones
// are dropped, few enough that the batch and the kernel's SoA scratch stay in L1.
constexpr int kSetupBatch = 64;

// Up to kSetupBatch triangles whose three vertices lie in front of the near plane and inside
// the guard band, in submission order: per vertex v its screen position (sx, sy), the same in
// fixed point (fx, fy), its view depth w = clip.w and 1 / w.
struct SetupBatch {
  int count = 0;
  int64_t fx[3][kSetupBatch], fy[3][kSetupBatch];
  double sx[3][kSetupBatch], sy[3][kSetupBatch], w[3][kSetupBatch], inv_w[3][kSetupBatch];
  uint32_t object[kSetupBatch], primitive[kSetupBatch];
};

}  // namespace rvr::soft
