// softraster's per-pixel loop for one instruction set; included once per kernel translation
// unit, which defines RVR_KERNEL_NS. Lane k of a group handles pixel x + k of a row: its edge
// functions are the row's plus k steps (integer adds, exact), its depth the scalar formula of
// SetupTriangle::inv_w in the same order of double operations (no FMA: these units build with
// -ffp-contract=off), so the bytes do not depend on the kernel. AVX-512 has its own loop, 8
// pixels wide with masked loads and stores (fill_kernel_avx512.inl).
#ifndef RVR_KERNEL_NS
#error "define RVR_KERNEL_NS before including this file"
#endif

#if defined(__AVX512F__)
#include "fill_kernel_avx512.inl"
#else
#include <cstdint>

#include "rvr/core/simd/simd.h"
#include "soft/fill_kernel.h"

namespace rvr::soft {
namespace RVR_KERNEL_NS {
namespace {

using namespace simd;
#include "depth_key.inl"
// 2 (SSE) or 4 (AVX2) pixels a group.
using VD = vdoublex;
using VI = vllongx;
constexpr int kLanes = kDoubleLanes;

inline VD splat(double x) {
  return VD::splat(x);
}
// max(v, 0) = v > 0 ? v : +0, as std::max(0.0, v) (NaN and -0 give +0).
inline VD clamp0(VD v) {
  return max(v, VD::zero());
}

inline unsigned lowest_bit(unsigned m) {
  return unsigned(__builtin_ctz(m));
}
// Set bits of a 4-bit mask (no popcnt instruction in the baseline kernel).
constexpr uint8_t kBits[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};

void fill(const FillTriangle& t, const FillTarget& target, int x0, int y0, int x1, int y1,
          bool full, FillResult& result) {
  // Edge function offsets of the lanes: k steps to the right.
  int64_t offsets[3][kLanes];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < kLanes; ++k) offsets[i][k] = t.step_x[i] * k;
  const VI lane_edge[3] = {VI::loadu(offsets[0]), VI::loadu(offsets[1]), VI::loadu(offsets[2])};
  const VI group_step[3] = {VI::splat(t.step_x[0] * kLanes), VI::splat(t.step_x[1] * kLanes),
                            VI::splat(t.step_x[2] * kLanes)};
  const VD q0[3] = {splat(t.q0[0]), splat(t.q0[1]), splat(t.q0[2])};
  const VD qa[3] = {splat(t.qa[0]), splat(t.qa[1]), splat(t.qa[2])};
  const VD qb[3] = {splat(t.qb[0]), splat(t.qb[1]), splat(t.qb[2])};
  const VD ox = splat(t.ox);
  int64_t row[3] = {t.row0[0], t.row0[1], t.row0[2]};
  alignas(32) double depth_lane[kLanes], q_lane[3][kLanes];
  for (int y = y0; y <= y1; ++y) {
    VI e[3] = {VI::splat(row[0]) + lane_edge[0], VI::splat(row[1]) + lane_edge[1],
               VI::splat(row[2]) + lane_edge[2]};
    const VD dy = splat(double(y) + 0.5 - t.oy);  // (py - oy), as the scalar formula
    for (int x = x0; x <= x1; x += kLanes) {
      const int n = x1 - x + 1 < kLanes ? x1 - x + 1 : kLanes;
      unsigned mask = (1u << n) - 1;
      if (!full) mask &= ~sign_bits((e[0] | e[1]) | e[2]);
      if (mask) {
        const VD dx = (splat(double(x)) + VD::iota()) + splat(0.5);  // px = x + k + 0.5
        const VD rel = dx - ox;
        VD q[3], s;
        for (int j = 0; j < 3; ++j) q[j] = clamp0((q0[j] + qa[j] * rel) + qb[j] * dy);
        s = (q[0] + q[1]) + q[2];
        storeu(depth_lane, splat(1.0) / s);
        result.generated += kBits[mask];  // mask < 16
        // The depth test first: the barycentrics' divisions only for groups that pass it.
        unsigned passed = 0;
        for (unsigned m = mask; m; m &= m - 1) {
          const int k = int(lowest_bit(m));
          const size_t i = size_t(y) * size_t(target.width) + size_t(x + k);
          if (target.count_fragments) ++target.fragments[i];
          const double depth = depth_lane[k];
          // The depth range clips what lies beyond far (and rounding just inside near).
          if (passes_depth_test(depth, target.depth[i], target) && depth >= target.near_plane &&
              depth <= target.far_plane)
            passed |= 1u << k;
        }
        if (passed) {
          result.drawn = true;
          if (target.keep_barycentrics)
            for (int j = 0; j < 3; ++j) storeu(q_lane[j], q[j] / s);
        }
        for (; passed; passed &= passed - 1) {
          const int k = int(lowest_bit(passed));
          const int px = x + k;
          const size_t i = size_t(y) * size_t(target.width) + size_t(px);
          if (target.depth[i] == __builtin_inf())
            --target.block_empty[size_t(y >> 3) * size_t(target.blocks_x) + size_t(px >> 3)];
          target.depth[i] = depth_lane[k];
          if (!target.depth_only) {
            target.object[i] = t.object;
            target.primitive[i] = t.primitive;
            if (target.keep_barycentrics)
              for (int j = 0; j < 3; ++j) target.bary[3 * i + size_t(j)] = float(q_lane[j][k]);
          }
        }
      }
      for (int i = 0; i < 3; ++i) e[i] = e[i] + group_step[i];
    }
    for (int i = 0; i < 3; ++i) row[i] += t.step_y[i];
  }
}

}  // namespace
}  // namespace RVR_KERNEL_NS
}  // namespace rvr::soft
#endif  // !__AVX512F__
