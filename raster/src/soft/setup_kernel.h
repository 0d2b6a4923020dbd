// softraster's batched triangle setup: the triangles that need no clipping, gathered in batches
// of vertex indices and set up by a kernel compiled once per instruction set (kernels/, chosen
// with the fill kernel). It repeats TriangleSetup::emit's arithmetic exactly, so every
// SetupTriangle is the same bytes as the scalar path's. The vertices come from a projection
// kernel that repeats TriangleSetup::project's arithmetic for a run of vertices in SoA. Plain
// data only, as fill_kernel.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "soft/setup_triangle.h"

namespace rvr::soft {

// Snapping moves a vertex by at most half a sub-pixel step in x and in y.
constexpr double kSnapDistance = 0.7072 / double(kSub);

// Triangles per kernel call: enough to amortize the call and fill vectors after the empty ones
// are dropped, few enough that the batch and the kernel's SoA scratch stay in L1.
constexpr int kSetupBatch = 64;

// A vertex flag beside TriangleSetup::project's clip planes (bits 0-4): in front of every clip
// plane but its fixed point does not fit in 30 bits (NaN or infinite input); the batch's 32-bit
// arithmetic would not be emit's, so its triangles take the scalar path.
constexpr uint8_t kScalarOnly = 1u << 5;

// Projected vertices in SoA (TriangleSetup::project's results for vertices in front of every
// clip plane): screen position (sx, sy), the same in fixed point (fx, fy: guard-band
// coordinates, below 2^29 in magnitude), view depth w = clip.w and 1 / w.
struct VertexArrays {
  int32_t* fx;
  int32_t* fy;
  double* sx;
  double* sy;
  double* w;
  double* inv_w;
};

// Up to kSetupBatch triangles whose three vertices lie in front of the near plane and inside
// the guard band, in submission order: per corner v the index of its vertex in `vertices`.
struct SetupBatch {
  int count = 0;
  VertexArrays vertices{};
  uint32_t vertex[3][kSetupBatch];
  uint32_t object[kSetupBatch], primitive[kSetupBatch];
};

// What TriangleSetup::project needs: the view-projection matrix (glm's column-major m[col][row]),
// the viewport and the guard planes' offsets.
struct ProjectionParams {
  double m[4][4];
  double width, height;
  double gx, gy;
};

// The projection kernel's output for `count` vertices: `vertices` for those in front of every
// clip plane, and per vertex project()'s reject bits and clip bits (plus kScalarOnly).
struct ProjectedRun {
  VertexArrays vertices;
  uint8_t* reject;
  uint8_t* clip;
};

}  // namespace rvr::soft
