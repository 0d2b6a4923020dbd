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

// project_vertices' tests and viewport for n clip-space positions (restrict parameters: the
// outputs alias nothing, so the loop vectorizes).
void project_block(const double* __restrict clip_x, const double* __restrict clip_y,
                   const double* __restrict clip_z, const double* __restrict clip_w, size_t n,
                   double width, double height, double gx, double gy, uint8_t* __restrict reject,
                   uint8_t* __restrict clip, int32_t* __restrict fx, int32_t* __restrict fy,
                   double* __restrict sx_out, double* __restrict sy_out, double* __restrict w_out,
                   double* __restrict inv_w_out) {
  for (size_t i = 0; i < n; ++i) {
    const double cx = clip_x[i], cy = clip_y[i], cz = clip_z[i], cw = clip_w[i];
    reject[i] = uint8_t(int(cx + cw < 0) | int(-cx + cw < 0) << 1 | int(cy + cw < 0) << 2 |
                        int(-cy + cw < 0) << 3 | int(cz + cw < 0) << 4 | int(-cz + cw < 0) << 5);
    const int planes = int(cz + cw < 0) | int(cx + gx * cw < 0) << 1 | int(-cx + gx * cw < 0) << 2 |
                       int(cy + gy * cw < 0) << 3 | int(-cy + gy * cw < 0) << 4;
    const double sx = (cx / cw * 0.5 + 0.5) * width;
    const double sy = (0.5 - cy / cw * 0.5) * height;
    const double ux = sx * double(kSub), uy = sy * double(kSub);
    // round_half_away in 32 bits where it is exact: |u| < 2^29 (guard-band coordinates are);
    // anything else (NaN, infinities) is flagged for the scalar path, and not converted.
    constexpr double kLimit = double(1 << 29);
    const bool fits = (std::fabs(ux) < kLimit) & (std::fabs(uy) < kLimit);
    const double vx = fits ? ux : 0.0, vy = fits ? uy : 0.0;
    int32_t ix = int32_t(vx), iy = int32_t(vy);
    const double rx = vx - double(ix), ry = vy - double(iy);
    ix += int32_t(rx >= 0.5) - int32_t(rx <= -0.5);
    iy += int32_t(ry >= 0.5) - int32_t(ry <= -0.5);
    clip[i] = uint8_t(planes | (planes == 0 && !fits ? kScalarOnly : 0));
    fx[i] = ix;
    fy[i] = iy;
    sx_out[i] = sx;
    sy_out[i] = sy;
    w_out[i] = cw;
    inv_w_out[i] = 1.0 / cw;
  }
}

// TriangleSetup::project for xyz[0 .. count) (float triples), its operations in its order:
// glm's dmat4 * dvec4 is (m0 x + m1 y) + (m2 z + m3 w), and m3 * 1.0 is m3 exactly.
void project_vertices(const ProjectionParams& p, const float* xyz, size_t count,
                      const ProjectedRun& out) {
  // A local copy: stores through the outputs cannot change it, so the loop vectorizes.
  double m[4][4];
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m[c][r] = p.m[c][r];
  const double width = p.width, height = p.height, gx = p.gx, gy = p.gy;
  const VertexArrays& o = out.vertices;
  // Blocks of clip-space positions first (a loop of its own: the vectorizer takes the float
  // triples' strided loads there), then the tests and the viewport over them in SoA.
  constexpr size_t kBlock = 256;
  alignas(64) double clip_x[kBlock], clip_y[kBlock], clip_z[kBlock], clip_w[kBlock];
  for (size_t first = 0; first < count; first += kBlock) {
    const size_t n = count - first < kBlock ? count - first : kBlock;
    const float* block = xyz + 3 * first;
    for (size_t i = 0; i < n; ++i) {
      const double px = block[3 * i], py = block[3 * i + 1], pz = block[3 * i + 2];
      clip_x[i] = (m[0][0] * px + m[1][0] * py) + (m[2][0] * pz + m[3][0]);
      clip_y[i] = (m[0][1] * px + m[1][1] * py) + (m[2][1] * pz + m[3][1]);
      clip_z[i] = (m[0][2] * px + m[1][2] * py) + (m[2][2] * pz + m[3][2]);
      clip_w[i] = (m[0][3] * px + m[1][3] * py) + (m[2][3] * pz + m[3][3]);
    }
    project_block(clip_x, clip_y, clip_z, clip_w, n, width, height, gx, gy, out.reject + first,
                  out.clip + first, o.fx + first, o.fy + first, o.sx + first, o.sy + first,
                  o.w + first, o.inv_w + first);
  }
}

// A batch's triangles in SoA, lane k for triangle k of the batch (the fixed-point part) and lane
// r for survivor r (the double-precision part). Fixed point in 32 bits: guard-band coordinates
// and their differences fit (setup_triangle.h).
struct BatchLanes {
  static constexpr int B = kSetupBatch;
  // Vertices in emit's order (1 and 2 swapped for negative area), pixel boxes, top-left edges.
  alignas(64) int32_t x[3][B], y[3][B];
  alignas(64) int32_t swapped[B], live[B];
  alignas(64) int32_t bx0[B], by0[B], bx1[B], by1[B];
  alignas(64) int32_t top_left[3][B];
  // The survivors, in order: their lane k, screen positions in emit's vertex order,
  // f[v][j] = (barycentric j of vertex v) / w_v = (v is vertex j) ? 1/w : 0, the smallest w.
  alignas(64) int index[B];
  alignas(64) double sx[3][B], sy[3][B], f[3][3][B], w_min[B];
  // Their perspective planes, hi-z bound and whether emit keeps them.
  alignas(64) double q0[3][B], qa[3][B], qb[3][B], min_depth[B];
  alignas(64) int64_t ok[B];
};

// Each triangle oriented (two-sided: either winding), with its pixel box (emit's first_centre /
// last_centre, clamped to the viewport); live if it has area and the box is not empty.
void orient_and_box(const SetupBatch& in, int width, int height, BatchLanes& l) {
  const VertexArrays& vs = in.vertices;
  const int n = in.count;
  for (int k = 0; k < n; ++k) {
    const uint32_t a = in.vertex[0][k], b = in.vertex[1][k], c = in.vertex[2][k];
    const int32_t ax = vs.fx[a], bx = vs.fx[b], cx = vs.fx[c];
    const int32_t ay = vs.fy[a], by = vs.fy[b], cy = vs.fy[c];
    const int64_t area = int64_t(bx - ax) * int64_t(cy - ay) - int64_t(by - ay) * int64_t(cx - ax);
    const bool swap = area < 0;
    const int32_t x1 = swap ? cx : bx, x2 = swap ? bx : cx;
    const int32_t y1 = swap ? cy : by, y2 = swap ? by : cy;
    l.x[0][k] = ax, l.x[1][k] = x1, l.x[2][k] = x2;
    l.y[0][k] = ay, l.y[1][k] = y1, l.y[2][k] = y2;
    l.swapped[k] = swap;
    const int32_t min_x = ax < x1 ? (ax < x2 ? ax : x2) : (x1 < x2 ? x1 : x2);
    const int32_t max_x = ax > x1 ? (ax > x2 ? ax : x2) : (x1 > x2 ? x1 : x2);
    const int32_t min_y = ay < y1 ? (ay < y2 ? ay : y2) : (y1 < y2 ? y1 : y2);
    const int32_t max_y = ay > y1 ? (ay > y2 ? ay : y2) : (y1 > y2 ? y1 : y2);
    const int32_t fx0 = (min_x + int32_t(kSub / 2 - 1)) >> kSubBits;
    const int32_t fy0 = (min_y + int32_t(kSub / 2 - 1)) >> kSubBits;
    const int32_t lx1 = (max_x - int32_t(kSub / 2)) >> kSubBits;
    const int32_t ly1 = (max_y - int32_t(kSub / 2)) >> kSubBits;
    l.bx0[k] = fx0 > 0 ? fx0 : 0;
    l.by0[k] = fy0 > 0 ? fy0 : 0;
    l.bx1[k] = lx1 < width - 1 ? lx1 : width - 1;
    l.by1[k] = ly1 < height - 1 ? ly1 : height - 1;
    l.live[k] = area != 0 && l.bx0[k] <= l.bx1[k] && l.by0[k] <= l.by1[k];
  }
}

// Top-left edges, and a box of at most four centres tested with the rasterizer's own edge
// functions (candidate c at column a, row b of the box: 1xN, 2x1, 2x2, Nx1 boxes): a small box
// holding no centre is not live.
void edges_and_small_boxes(int n, BatchLanes& l) {
  for (int k = 0; k < n; ++k) {
    int32_t edx[3], edy[3];
    int64_t bias[3];
    for (int i = 0; i < 3; ++i) {
      const int nx = i == 2 ? 0 : i + 1;
      edx[i] = l.x[nx][k] - l.x[i][k];
      edy[i] = l.y[nx][k] - l.y[i][k];
      const bool tl = (edy[i] == 0 && edx[i] > 0) || edy[i] < 0;
      l.top_left[i][k] = tl;
      bias[i] = tl ? 0 : 1;
    }
    const int32_t wx = l.bx1[k] - l.bx0[k] + 1, wy = l.by1[k] - l.by0[k] + 1;
    const int32_t box = wx * wy;
    bool covers = false;
    for (int32_t c = 0; c < 4; ++c) {
      const int32_t a = wx == 1 ? 0 : (wx == 2 ? (c & 1) : c);
      const int32_t b = wx == 1 ? c : (wx == 2 ? (c >> 1) : 0);
      const int32_t px = (l.bx0[k] + a) * int32_t(kSub) + int32_t(kSub / 2);
      const int32_t py = (l.by0[k] + b) * int32_t(kSub) + int32_t(kSub / 2);
      bool inside = c < box;
      for (int i = 0; i < 3; ++i)
        inside &= int64_t(edx[i]) * int64_t(py - l.y[i][k]) -
                      int64_t(edy[i]) * int64_t(px - l.x[i][k]) - bias[i] >=
                  0;
      covers |= inside;
    }
    l.live[k] &= box > 4 || covers;
  }
}

// The live triangles, in order, gathered for the double-precision part. Returns their count.
int gather_survivors(const SetupBatch& in, BatchLanes& l) {
  const VertexArrays& vs = in.vertices;
  const int n = in.count;
  int m = 0;
  for (int k = 0; k < n; ++k) {
    l.index[m] = k;
    m += int(l.live[k] != 0);
  }
  for (int r = 0; r < m; ++r) {
    const int k = l.index[r];
    const uint32_t vertex[3] = {in.vertex[0][k], in.vertex[1][k], in.vertex[2][k]};
    const int order[3] = {0, l.swapped[k] ? 2 : 1, l.swapped[k] ? 1 : 2};
    for (int v = 0; v < 3; ++v) {
      l.sx[v][r] = vs.sx[vertex[order[v]]];
      l.sy[v][r] = vs.sy[vertex[order[v]]];
      for (int j = 0; j < 3; ++j) l.f[v][j][r] = order[v] == j ? vs.inv_w[vertex[j]] : 0.0;
    }
    // std::min({w0, w1, w2}) in emit's (input) order.
    const double w0 = vs.w[vertex[0]], w1 = vs.w[vertex[1]], w2 = vs.w[vertex[2]];
    double wm = w0;
    if (w1 < wm) wm = w1;
    if (w2 < wm) wm = w2;
    l.w_min[r] = wm;
  }
  return m;
}

// Survivors' perspective planes (the barycentrics over w as planes in screen space, their values
// taken at the snapped vertex 0) and hi-z bound; ok: emit keeps them.
void planes_and_depth_bound(int m, BatchLanes& l) {
  for (int r = 0; r < m; ++r) {
    const int32_t x0 = l.x[0][l.index[r]], y0 = l.y[0][l.index[r]];  // the planes' origin
    const double dx1 = l.sx[1][r] - l.sx[0][r], dy1 = l.sy[1][r] - l.sy[0][r];
    const double dx2 = l.sx[2][r] - l.sx[0][r], dy2 = l.sy[2][r] - l.sy[0][r];
    const double det = dx1 * dy2 - dx2 * dy1;
    const double abs_det = std::fabs(det);
    // emit drops !(|det| > 0) || !isfinite(det) (bitwise &: no branch in the vector loop).
    l.ok[r] = int64_t(abs_det > 0.0) & int64_t(abs_det <= DBL_MAX);
#define RVR_PLANES(j)                                                                        \
  {                                                                                          \
    const double f0 = l.f[0][j][r], f1 = l.f[1][j][r], f2 = l.f[2][j][r];                    \
    l.qa[j][r] = ((f1 - f0) * dy2 - (f2 - f0) * dy1) / det;                                  \
    l.qb[j][r] = ((f2 - f0) * dx1 - (f1 - f0) * dx2) / det;                                  \
    l.q0[j][r] =                                                                             \
        plane_at_snapped_origin(f0, l.qa[j][r], l.qb[j][r], l.sx[0][r], l.sy[0][r], x0, y0); \
  }
    RVR_PLANES(0)
    RVR_PLANES(1)
    RVR_PLANES(2)
#undef RVR_PLANES
    // std::max(longest2, e) over the edges, from 0.
    const double e0 = (l.sx[1][r] - l.sx[0][r]) * (l.sx[1][r] - l.sx[0][r]) +
                      (l.sy[1][r] - l.sy[0][r]) * (l.sy[1][r] - l.sy[0][r]);
    const double e1 = (l.sx[2][r] - l.sx[1][r]) * (l.sx[2][r] - l.sx[1][r]) +
                      (l.sy[2][r] - l.sy[1][r]) * (l.sy[2][r] - l.sy[1][r]);
    const double e2 = (l.sx[0][r] - l.sx[2][r]) * (l.sx[0][r] - l.sx[2][r]) +
                      (l.sy[0][r] - l.sy[2][r]) * (l.sy[0][r] - l.sy[2][r]);
    double longest2 = 0.0 < e0 ? e0 : 0.0;
    longest2 = longest2 < e1 ? e1 : longest2;
    longest2 = longest2 < e2 ? e2 : longest2;
    const double altitude = abs_det / std::sqrt(longest2);
    const double bound = l.w_min[r] / (1.0 + 4.0 * kSnapDistance / altitude);
    l.min_depth[r] = altitude > 0 ? bound : 0.0;
  }
}

// The kept survivors written out in order. Returns how many.
int write_survivors(const SetupBatch& in, int m, const BatchLanes& l, SetupTriangle* out) {
  int written = 0;
  for (int r = 0; r < m; ++r) {
    if (!l.ok[r]) continue;
    const int k = l.index[r];
    SetupTriangle& t = out[written++];
    for (int i = 0; i < 3; ++i) {
      t.x[i] = l.x[i][k];
      t.y[i] = l.y[i][k];
      t.top_left[i] = l.top_left[i][k] != 0;
      t.q0[i] = l.q0[i][r];
      t.qa[i] = l.qa[i][r];
      t.qb[i] = l.qb[i][r];
    }
    t.x0 = l.bx0[k];
    t.y0 = l.by0[k];
    t.x1 = l.bx1[k];
    t.y1 = l.by1[k];
    t.min_depth = l.min_depth[r];
    t.object = in.object[k];
    t.primitive = in.primitive[k];
  }
  return written;
}

int setup_batch(const SetupBatch& in, int width, int height, SetupTriangle* out) {
  BatchLanes lanes;
  orient_and_box(in, width, height, lanes);
  edges_and_small_boxes(in.count, lanes);
  const int survivors = gather_survivors(in, lanes);
  planes_and_depth_bound(survivors, lanes);
  return write_survivors(in, survivors, lanes, out);
}

}  // namespace
}  // namespace RVR_KERNEL_NS
}  // namespace rvr::soft
