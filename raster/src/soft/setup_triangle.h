// What softraster's setup hands the tile rasterizer for one screen triangle. Plain data (C
// arrays), so the per-ISA setup kernels (kernels/setup_kernels.inl) can write it.
#pragma once

#include <cstdint>
#include <vector>

#include "soft/huge_page_allocator.h"

namespace rvr::soft {

// Sub-pixel precision of the edge functions: finer than GL's usual 8 bits, so that snapping
// an edge-on sliver (a sphere's silhouette) rarely makes it cover a centre it does not.
constexpr int kSubBits = 12;
constexpr int64_t kSub = int64_t(1) << kSubBits;

// A screen-space triangle after clipping. One input triangle gives up to a few of these.
// No default member values: setup writes every field, and a vector of them is resized a batch at
// a time (HugePageAllocator default-initialises), so a value-initialising memset per batch
// (192 bytes a triangle, 10^6 times a frame) would be work thrown away.
// Hot and cold halves: draw_tile reads the first cache line of every binned triangle (pixel
// box, hi-z bound, edge functions) and the other two only for triangles with a block to fill;
// at 10^6 scattered triangles a chunk is far beyond L2, so lines not touched are misses saved.
struct alignas(64) SetupTriangle {
  // --- hot: one cache line
  int x0, y0, x1, y1;  // pixel bounding box, inclusive, on screen
  // No fragment is nearer than this (view depth): the hi-z test's bound (see min_depth_bound).
  double min_depth;
  // Fixed point, oriented so the edge functions are >= 0 inside. Guard-band coordinates are
  // below 2^28 in magnitude (triangle_setup.h), so 32 bits hold them exactly.
  int32_t x[3], y[3];
  bool top_left[3];  // edge i runs from vertex i to vertex i+1
  // --- cold: read only to fill pixels
  // q_j(p) = q0[j] + qa[j]*(px - ox) + qb[j]*(py - oy) = (barycentric j of the ORIGINAL
  // triangle) / w: linear in screen space, so sum_j q_j = 1/w = 1/view depth, and q_j/sum is
  // the perspective-correct barycentric. From the unsnapped vertices, in double: P must be
  // exact where 1/|L - P|^2 is steep (surfaces next to a light).
  alignas(64) double q0[3];
  double qa[3], qb[3];
  double ox, oy;
  uint32_t object, primitive;

  double inv_w(double px, double py, double (&q)[3]) const {
    double s = 0;
    for (int j = 0; j < 3; ++j) {
      // Clamped: a sliver may cover a centre just outside itself (snapping); it is then seen
      // at its nearest edge point instead of extrapolating depth.
      const double v = q0[j] + qa[j] * (px - ox) + qb[j] * (py - oy);
      q[j] = v > 0.0 ? v : 0.0;
      s += q[j];
    }
    return s;
  }
};
static_assert(sizeof(SetupTriangle) == 192, "a hot cache line and two cold ones");

// A run of set-up triangles (a sub-chunk's, in submission order).
using SetupTriangles = std::vector<SetupTriangle, HugePageAllocator<SetupTriangle>>;

}  // namespace rvr::soft
