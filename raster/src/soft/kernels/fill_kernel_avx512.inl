// softraster's per-pixel loop for AVX-512 (included by fill_kernels.inl in the avx512 unit): 8
// pixels a group, so an 8x8 block's row is one group, and the depth test, fragment counts and
// writes as masked loads and stores instead of a scalar loop over the group's lanes. AVX-512's
// masks make the uncovered lanes and a row's ragged end free (the AVX2 kernel keeps the scalar
// loop over the group's lanes: its masked stores do not pay off). Per lane the same double
// operations as the narrower kernels, in the same order, so the bytes do not depend on the kernel.
#include <immintrin.h>

#include <cstdint>

#include "rvr/core/simd/simd.h"
#include "soft/fill_kernel.h"

namespace rvr::soft {
namespace RVR_KERNEL_NS {
namespace {

using namespace simd;
#include "depth_key.inl"
constexpr int kLanes = 8;

// Each bit of an 8-lane mask three times: the mask of those lanes' interleaved barycentrics.
inline uint32_t triple_bits(uint32_t m) {
  return _pdep_u32(m, 0x249249u) | _pdep_u32(m, 0x492492u) | _pdep_u32(m, 0x924924u);
}

// Float p of 3 x 8 interleaved barycentrics (lane p / 3, coordinate p % 3) taken from
// [b0 | b1] (indices 0-15) and b2 (16-23): the first 16 floats, then the last 8.
constexpr int interleaved_source(int p) {
  return (p % 3) * kLanes + p / 3;
}

void fill(const FillTriangle& t, const FillTarget& target, int x0, int y0, int x1, int y1,
          bool full, FillResult& result) {
  const vllong8 lane_index = vllong8::iota();
  vllong8 lane_edge[3], group_step[3];
  vdouble8 q0[3], qa[3], qb[3];
  for (int i = 0; i < 3; ++i) {
    // k steps to the right: step_x * k, exact in 64-bit integers as the scalar formula.
    lane_edge[i] = vllong8::splat(t.step_x[i]) * lane_index;
    group_step[i] = vllong8::splat(t.step_x[i] * kLanes);
    q0[i] = vdouble8::splat(t.q0[i]);
    qa[i] = vdouble8::splat(t.qa[i]);
    qb[i] = vdouble8::splat(t.qb[i]);
  }
  const vdouble8 ox = vdouble8::splat(t.ox);
  const vdouble8 lane_offsets = vdouble8::iota();
  const vdouble8 half = vdouble8::splat(0.5), one = vdouble8::splat(1.0);
  const vdouble8 zero = vdouble8::zero(), infinity = vdouble8::splat(__builtin_inf());
  const vdouble8 near_plane = vdouble8::splat(target.near_plane);
  const vdouble8 far_plane = vdouble8::splat(target.far_plane);
  const vint8 object = vint8::splat(int32_t(t.object));
  const vint8 primitive = vint8::splat(int32_t(t.primitive));
  const vint8 one_fragment = vint8::splat(1);
  const __m512i interleave_lo = _mm512_setr_epi32(
      interleaved_source(0), interleaved_source(1), interleaved_source(2), interleaved_source(3),
      interleaved_source(4), interleaved_source(5), interleaved_source(6), interleaved_source(7),
      interleaved_source(8), interleaved_source(9), interleaved_source(10), interleaved_source(11),
      interleaved_source(12), interleaved_source(13), interleaved_source(14),
      interleaved_source(15));
  const __m512i interleave_hi =
      _mm512_setr_epi32(interleaved_source(16), interleaved_source(17), interleaved_source(18),
                        interleaved_source(19), interleaved_source(20), interleaved_source(21),
                        interleaved_source(22), interleaved_source(23), 0, 0, 0, 0, 0, 0, 0, 0);

  int64_t row[3] = {t.row0[0], t.row0[1], t.row0[2]};
  for (int y = y0; y <= y1; ++y) {
    vllong8 e[3];
    for (int i = 0; i < 3; ++i) e[i] = vllong8::splat(row[i]) + lane_edge[i];
    const vdouble8 dy =
        vdouble8::splat(double(y) + 0.5 - t.oy);  // (py - oy), as the scalar formula
    const size_t row_start = size_t(y) * size_t(target.width);
    for (int x = x0; x <= x1; x += kLanes) {
      const int n = x1 - x + 1 < kLanes ? x1 - x + 1 : kLanes;
      vboold8 mask = vboold8::from_bits((1u << n) - 1);
      // A negative edge function (sign bit set) puts the centre outside.
      if (!full) mask = mask & ~sign_bits((e[0] | e[1]) | e[2]);
      if (movemask(mask)) {
        // px = x + k + 0.5, then the perspective planes, as the scalar formula.
        const vdouble8 dx = (vdouble8::splat(double(x)) + lane_offsets) + half;
        const vdouble8 rel = dx - ox;
        vdouble8 q[3];
        // max(v, 0) as std::max(0.0, v): NaN and -0 give +0.
        for (int j = 0; j < 3; ++j) q[j] = max((q0[j] + qa[j] * rel) + qb[j] * dy, zero);
        const vdouble8 s = (q[0] + q[1]) + q[2];
        const vdouble8 depth = one / s;
        result.generated += unsigned(__builtin_popcount(movemask(mask)));
        const size_t i = row_start + size_t(x);
        if (target.count_fragments) {
          uint32_t* fragments = target.fragments + i;
          storeu(mask, fragments, loadu(mask, fragments) + one_fragment);
        }
        // The depth test; the depth range clips what lies beyond far (and rounding just
        // inside near). Ordered compares: a NaN depth fails, as in the scalar test.
        const vdouble8 stored = vdouble8::loadu(mask, target.depth + i);
        vboold8 passed = less(mask, depth, stored);
        if (target.depth_format != kDepthExact) {
          // A z-buffer format's test, lane by lane (depth_key.inl).
          alignas(64) double depth_lane[kLanes], stored_lane[kLanes];
          _mm512_store_pd(depth_lane, depth.v);
          _mm512_store_pd(stored_lane, stored.v);
          unsigned bits = 0;
          for (unsigned m = movemask(mask); m; m &= m - 1) {
            const int k = __builtin_ctz(m);
            if (passes_depth_test(depth_lane[k], stored_lane[k], target)) bits |= 1u << k;
          }
          passed = vboold8::from_bits(bits);
        }
        passed = greater_equal(passed, depth, near_plane);
        passed = less_equal(passed, depth, far_plane);
        if (movemask(passed)) {
          result.drawn = true;
          // Pixels drawn for the first time leave their 8x8 block's count of empty pixels: the
          // group's lanes lie in block x / 8 and, from lane 8 - x % 8 on, in the next one.
          if (const unsigned first = movemask(equal(passed, stored, infinity))) {
            const int in_first_block = kLanes - (x & 7);
            uint16_t* empty =
                target.block_empty + size_t(y >> 3) * size_t(target.blocks_x) + size_t(x >> 3);
            empty[0] =
                uint16_t(empty[0] - __builtin_popcount(first & ((1u << in_first_block) - 1)));
            if (const unsigned next = first >> in_first_block)
              empty[1] = uint16_t(empty[1] - __builtin_popcount(next));
          }
          storeu(passed, target.depth + i, depth);
          if (!target.depth_only) {
            storeu(passed, target.object + i, object);
            storeu(passed, target.primitive + i, primitive);
          }
          if (target.keep_barycentrics) {
            // The barycentrics (q / s, rounded to float as the scalar cast does), interleaved
            // with AVX-512's two-source permutes and 16-lane masked stores.
            const vfloat8 b0 = to_float(q[0] / s);
            const vfloat8 b1 = to_float(q[1] / s);
            const vfloat8 b2 = to_float(q[2] / s);
            const __m512 b01 = _mm512_insertf32x8(_mm512_castps256_ps512(b0.v), b1.v, 1);
            const __m512 b2x = _mm512_castps256_ps512(b2.v);
            const uint32_t lanes = triple_bits(movemask(passed));
            float* bary = target.bary + 3 * i;
            _mm512_mask_storeu_ps(bary, __mmask16(lanes & 0xFFFFu),
                                  _mm512_permutex2var_ps(b01, interleave_lo, b2x));
            _mm512_mask_storeu_ps(bary + 16, __mmask16(lanes >> 16),
                                  _mm512_permutex2var_ps(b01, interleave_hi, b2x));
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
