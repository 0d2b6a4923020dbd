// The per-pixel loop of softraster (and its batched triangle setup, setup_kernel.h), as SIMD
// kernels compiled once per instruction set (src/soft/kernels/, like the tracer's) and chosen
// at run time: edge functions and depths of
// 2 (SSE), 4 (AVX2) or 8 (AVX-512) pixels at once, in the same double-precision operations as the
// scalar formulas of SetupTriangle, so every kernel draws the same bytes. Plain data only: a
// kernel translation unit must not instantiate inline code that baseline code also uses.
#pragma once

#include <cstdint>

#include "soft/setup_kernel.h"

namespace rvr::soft {

// One triangle over one span of pixels, from (x0, y0).
struct FillTriangle {
  int64_t row0[3];    // edge functions at pixel (x0, y0)'s centre, minus the top-left bias
  int64_t step_x[3];  // change per pixel to the right
  int64_t step_y[3];  // change per row down
  double q0[3], qa[3], qb[3], ox, oy;  // SetupTriangle's perspective planes
  uint32_t object, primitive;
};

// What the depth test compares (FillTarget::depth_format): the view depth itself (exact), or the
// value a z-buffer of that format would store for it (kernels/depth_key.inl). The stored array
// always holds the view depth: the value a format stores is a function of it.
constexpr int kDepthExact = 0;
constexpr int kDepthD24 = 1;
constexpr int kDepthD32F = 2;
constexpr int kDepthD32FReversed = 3;

// The frame's z-buffer state (DepthTarget's arrays).
struct FillTarget {
  double* depth;
  uint32_t* object;
  uint32_t* primitive;
  float* bary;
  uint32_t* fragments;
  uint16_t* block_empty;
  int width;
  int blocks_x;
  double near_plane, far_plane;
  bool depth_only;         // no ids, barycentrics or fragment counts
  bool keep_barycentrics;  // bary written
  bool count_fragments;    // fragments counted
  int depth_format;        // kDepthExact, kDepthD24, ...
};

struct FillResult {
  uint64_t generated = 0;  // fragments: covered centres depth-tested
  bool drawn = false;      // some pixel took the triangle
};

struct FillKernels {
  const char* isa;
  // Pixels [x0, x1] x [y0, y1]; `full`: every centre is known to be covered (no edge tests).
  void (*fill)(const FillTriangle& t, const FillTarget& target, int x0, int y0, int x1, int y1,
               bool full, FillResult& result);
  // Sets up batch's triangles into out[0 .. returned count): those emit would keep, in order.
  int (*setup)(const SetupBatch& batch, int width, int height, SetupTriangle* out);
  // TriangleSetup::project for `count` vertices (float x, y, z each), into `out`'s arrays.
  void (*project)(const ProjectionParams& params, const float* xyz, size_t count,
                  const ProjectedRun& out);
};

namespace isa_sse {
extern const FillKernels kFillKernels;
}
namespace isa_avx2 {
extern const FillKernels kFillKernels;
}
namespace isa_avx512 {
extern const FillKernels kFillKernels;
}

}  // namespace rvr::soft
