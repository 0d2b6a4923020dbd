// softraster's batched triangle setup for one instruction set; included once per kernel
// translation unit after RVR_KERNEL_NS is defined. TriangleSetup::emit for the triangles of a
// SetupBatch, as loops over the batch in SoA that the compiler vectorizes for the unit's
// instruction set (these units build with -O3). Identical results by construction: the integer
// edge arithmetic is exact at any vector width, and the double operations are emit's own in its
// order (IEEE add, sub, mul, div and sqrt round the same in every lane; -ffp-contract=off: no
// fused multiply-add). First every triangle's orientation, pixel box and, for boxes of at most
// four centres, coverage test; then the perspective planes and hi-z bound of the survivors
// only (at 10^6 triangles on a 1024x768 frame most hold no centre).
#include <cfloat>
#include <cmath>
#include <cstdint>

#include "soft/setup_kernel.h"

#ifndef RVR_KERNEL_NS
#error "define RVR_KERNEL_NS before including this file"
#endif

namespace rvr::soft {
namespace RVR_KERNEL_NS {
namespace {

// Products of edge function terms: both factors are differences of guard-band fixed-point
// coordinates (|.| < 2^30), so their 32-bit truncations are exact and a 32x32->64 multiply
// (one vpmuldq) gives emit's int64 product.
inline int64_t wide_mul(int64_t a, int64_t b) {
  return int64_t(int32_t(a)) * int64_t(int32_t(b));
}

int setup_batch(const SetupBatch& in, int width, int height, SetupTriangle* out) {
  const int n = in.count;
  constexpr int B = kSetupBatch;
  // Vertices in emit's order (1 and 2 swapped for negative area), pixel boxes, top-left edges.
  alignas(64) int64_t x[3][B], y[3][B];
  alignas(64) int64_t swapped[B], live[B];
  alignas(64) int32_t bx0[B], by0[B], bx1[B], by1[B];
  alignas(64) int64_t top_left[3][B];
  for (int k = 0; k < n; ++k) {
    const int64_t ax = in.fx[0][k], bx = in.fx[1][k], cx = in.fx[2][k];
    const int64_t ay = in.fy[0][k], by = in.fy[1][k], cy = in.fy[2][k];
    const int64_t area = wide_mul(bx - ax, cy - ay) - wide_mul(by - ay, cx - ax);
    const bool swap = area < 0;  // two-sided: either winding, oriented here
    const int64_t x1 = swap ? cx : bx, x2 = swap ? bx : cx;
    const int64_t y1 = swap ? cy : by, y2 = swap ? by : cy;
    x[0][k] = ax, x[1][k] = x1, x[2][k] = x2;
    y[0][k] = ay, y[1][k] = y1, y[2][k] = y2;
    swapped[k] = swap;
    const int64_t min_x = ax < x1 ? (ax < x2 ? ax : x2) : (x1 < x2 ? x1 : x2);
    const int64_t max_x = ax > x1 ? (ax > x2 ? ax : x2) : (x1 > x2 ? x1 : x2);
    const int64_t min_y = ay < y1 ? (ay < y2 ? ay : y2) : (y1 < y2 ? y1 : y2);
    const int64_t max_y = ay > y1 ? (ay > y2 ? ay : y2) : (y1 > y2 ? y1 : y2);
    // emit's first_centre / last_centre in 32 bits (guard-band coordinates fit).
    const int32_t fx0 = (int32_t(min_x) + int32_t(kSub / 2 - 1)) >> kSubBits;
    const int32_t fy0 = (int32_t(min_y) + int32_t(kSub / 2 - 1)) >> kSubBits;
    const int32_t lx1 = (int32_t(max_x) - int32_t(kSub / 2)) >> kSubBits;
    const int32_t ly1 = (int32_t(max_y) - int32_t(kSub / 2)) >> kSubBits;
    bx0[k] = fx0 > 0 ? fx0 : 0;
    by0[k] = fy0 > 0 ? fy0 : 0;
    bx1[k] = lx1 < width - 1 ? lx1 : width - 1;
    by1[k] = ly1 < height - 1 ? ly1 : height - 1;
    live[k] = area != 0 && bx0[k] <= bx1[k] && by0[k] <= by1[k];
  }
  // Top-left edges, and a box of at most four centres tested with the rasterizer's own edge
  // functions (candidate c at column a, row b of the box: 1xN, 2x1, 2x2, Nx1 boxes).
  for (int k = 0; k < n; ++k) {
    int64_t edx[3], edy[3], bias[3];
    for (int i = 0; i < 3; ++i) {
      const int nx = i == 2 ? 0 : i + 1;
      edx[i] = x[nx][k] - x[i][k];
      edy[i] = y[nx][k] - y[i][k];
      const bool tl = (edy[i] == 0 && edx[i] > 0) || edy[i] < 0;
      top_left[i][k] = tl;
      bias[i] = tl ? 0 : 1;
    }
    const int32_t wx = bx1[k] - bx0[k] + 1, wy = by1[k] - by0[k] + 1;
    const int32_t box = wx * wy;
    bool covers = false;
    for (int32_t c = 0; c < 4; ++c) {
      const int32_t a = wx == 1 ? 0 : (wx == 2 ? (c & 1) : c);
      const int32_t b = wx == 1 ? c : (wx == 2 ? (c >> 1) : 0);
      const int64_t px = int64_t(bx0[k] + a) * kSub + kSub / 2;
      const int64_t py = int64_t(by0[k] + b) * kSub + kSub / 2;
      bool inside = c < box;
      for (int i = 0; i < 3; ++i)
        inside &= wide_mul(edx[i], py - y[i][k]) - wide_mul(edy[i], px - x[i][k]) - bias[i] >= 0;
      covers |= inside;
    }
    live[k] &= box > 4 || covers;
  }
  // The survivors, in order, gathered for the double-precision part: screen positions in emit's
  // vertex order, f[v][j] = (barycentric j of vertex v) / w_v = (v is vertex j) ? 1/w : 0.
  alignas(64) int index[B];
  int m = 0;
  for (int k = 0; k < n; ++k) {
    index[m] = k;
    m += int(live[k] != 0);
  }
  alignas(64) double sx[3][B], sy[3][B], f[3][3][B], w_min[B];
  for (int r = 0; r < m; ++r) {
    const int k = index[r];
    const int order[3] = {0, swapped[k] ? 2 : 1, swapped[k] ? 1 : 2};
    for (int v = 0; v < 3; ++v) {
      sx[v][r] = in.sx[order[v]][k];
      sy[v][r] = in.sy[order[v]][k];
      for (int j = 0; j < 3; ++j) f[v][j][r] = order[v] == j ? in.inv_w[j][k] : 0.0;
    }
    // std::min({w0, w1, w2}) in emit's (input) order.
    double wm = in.w[0][k];
    if (in.w[1][k] < wm) wm = in.w[1][k];
    if (in.w[2][k] < wm) wm = in.w[2][k];
    w_min[r] = wm;
  }
  alignas(64) double qa[3][B], qb[3][B], min_depth[B];
  alignas(64) int64_t ok[B];
  for (int r = 0; r < m; ++r) {
    const double dx1 = sx[1][r] - sx[0][r], dy1 = sy[1][r] - sy[0][r];
    const double dx2 = sx[2][r] - sx[0][r], dy2 = sy[2][r] - sy[0][r];
    const double det = dx1 * dy2 - dx2 * dy1;
    const double abs_det = std::fabs(det);
    // emit drops !(|det| > 0) || !isfinite(det) (bitwise &: no branch in the vector loop).
    ok[r] = int64_t(abs_det > 0.0) & int64_t(abs_det <= DBL_MAX);
#define RVR_PLANES(j)                                               \
  {                                                                 \
    const double f0 = f[0][j][r], f1 = f[1][j][r], f2 = f[2][j][r]; \
    qa[j][r] = ((f1 - f0) * dy2 - (f2 - f0) * dy1) / det;           \
    qb[j][r] = ((f2 - f0) * dx1 - (f1 - f0) * dx2) / det;           \
  }
    RVR_PLANES(0)
    RVR_PLANES(1)
    RVR_PLANES(2)
#undef RVR_PLANES
    // std::max(longest2, e) over the edges, from 0.
    const double e0 = (sx[1][r] - sx[0][r]) * (sx[1][r] - sx[0][r]) +
                      (sy[1][r] - sy[0][r]) * (sy[1][r] - sy[0][r]);
    const double e1 = (sx[2][r] - sx[1][r]) * (sx[2][r] - sx[1][r]) +
                      (sy[2][r] - sy[1][r]) * (sy[2][r] - sy[1][r]);
    const double e2 = (sx[0][r] - sx[2][r]) * (sx[0][r] - sx[2][r]) +
                      (sy[0][r] - sy[2][r]) * (sy[0][r] - sy[2][r]);
    double longest2 = 0.0 < e0 ? e0 : 0.0;
    longest2 = longest2 < e1 ? e1 : longest2;
    longest2 = longest2 < e2 ? e2 : longest2;
    const double altitude = abs_det / std::sqrt(longest2);
    const double bound = w_min[r] / (1.0 + 4.0 * kSnapDistance / altitude);
    min_depth[r] = altitude > 0 ? bound : 0.0;
  }
  int written = 0;
  for (int r = 0; r < m; ++r) {
    if (!ok[r]) continue;
    const int k = index[r];
    SetupTriangle& t = out[written++];
    for (int i = 0; i < 3; ++i) {
      t.x[i] = int32_t(x[i][k]);
      t.y[i] = int32_t(y[i][k]);
      t.top_left[i] = top_left[i][k] != 0;
      t.q0[i] = f[0][i][r];
      t.qa[i] = qa[i][r];
      t.qb[i] = qb[i][r];
    }
    t.ox = sx[0][r];
    t.oy = sy[0][r];
    t.x0 = bx0[k];
    t.y0 = by0[k];
    t.x1 = bx1[k];
    t.y1 = by1[k];
    t.min_depth = min_depth[r];
    t.object = in.object[k];
    t.primitive = in.primitive[k];
  }
  return written;
}

}  // namespace
}  // namespace RVR_KERNEL_NS
}  // namespace rvr::soft
