// What softraster's setup hands the tile rasterizer for one screen triangle. Plain data (C
// arrays), so the per-ISA setup kernels (kernels/setup_kernels.inl) can write it.
#pragma once

#include <cstddef>
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
// would be work thrown away.
// Two cache lines, hot and cold: draw_tile reads the first line of every binned triangle (pixel
// box, hi-z bound) and the second only for triangles with pixels to fill. Setup writes both for
// every triangle it keeps: at 10^6 triangles a chunk lies beyond the caches, so each line a
// triangle takes is memory traffic in the setup and again in the raster.
struct alignas(64) SetupTriangle {
  // --- hot: one cache line
  int16_t x0, y0, x1, y1;  // pixel bounding box, inclusive, on screen (sides <= kMaxImageSide)
  // No fragment is nearer than this (view depth): the hi-z test's bound (see min_depth_bound).
  double min_depth;
  // Fixed point, oriented so the edge functions are >= 0 inside. Guard-band coordinates are
  // below 2^28 in magnitude (triangle_setup.h), so 32 bits hold them exactly.
  int32_t x[3], y[3];
  // q_j(p) = q0[j] + qa[j]*(px - ox()) + qb[j]*(py - oy()) = (barycentric j of the ORIGINAL
  // triangle) / w: linear in screen space, so sum_j q_j = 1/w = 1/view depth, and q_j/sum is
  // the perspective-correct barycentric. From the unsnapped vertices, in double: P must be
  // exact where 1/|L - P|^2 is steep (surfaces next to a light). The planes' origin is the
  // snapped vertex 0, which the fixed-point x[0], y[0] give exactly, so it takes no bytes.
  double q0[3];
  // --- cold: read only to fill pixels
  double qa[3], qb[3];
  uint32_t object, primitive;
  bool top_left[3];  // edge i runs from vertex i to vertex i+1

  double ox() const { return double(x[0]) * (1.0 / double(kSub)); }
  double oy() const { return double(y[0]) * (1.0 / double(kSub)); }
  double inv_w(double px, double py, double (&q)[3]) const {
    double s = 0;
    for (int j = 0; j < 3; ++j) {
      // Clamped: a sliver may cover a centre just outside itself (snapping); it is then seen
      // at its nearest edge point instead of extrapolating depth.
      const double v = q0[j] + qa[j] * (px - ox()) + qb[j] * (py - oy());
      q[j] = v > 0.0 ? v : 0.0;
      s += q[j];
    }
    return s;
  }
};
static_assert(sizeof(SetupTriangle) == 128, "a hot cache line and a cold one");
static_assert(offsetof(SetupTriangle, qa) == 64, "the planes' slopes start the cold line");

// The value at the snapped vertex 0 (ox, oy) of the plane through (sx0, sy0) with value f0 and
// slopes qa, qb: setup's scalar path and its batch kernels alike, in this order of operations.
// Internal linkage: each kernel unit compiles its own copy (a shared inline copy built for a
// wider instruction set could be the one the linker keeps for baseline code).
static inline double plane_at_snapped_origin(double f0, double qa, double qb, double sx0,
                                             double sy0, int32_t x0, int32_t y0) {
  return (f0 + qa * (double(x0) * (1.0 / double(kSub)) - sx0)) +
         qb * (double(y0) * (1.0 / double(kSub)) - sy0);
}

// A run of set-up triangles (a sub-chunk's, in submission order).
using SetupTriangles = std::vector<SetupTriangle, HugePageAllocator<SetupTriangle>>;

}  // namespace rvr::soft
