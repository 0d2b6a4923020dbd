// softraster's per-pixel loop for AVX-512 (included by fill_kernels.inl in the avx512 unit): 8
// pixels a group, so an 8x8 block's row is one group, and the depth test, fragment counts and
// writes as masked loads and stores instead of a scalar loop over the group's lanes. AVX-512's
// masks make the uncovered lanes and a row's ragged end free (AVX2's masked stores were
// measured slower than the scalar loop). Per lane the same double operations as the narrower
// kernels, in the same order, so the bytes do not depend on the kernel.
#include <immintrin.h>

#include <cstdint>

#include "soft/fill_kernel.h"

namespace rvr::soft {
namespace RVR_KERNEL_NS {
namespace {

constexpr int kLanes = 8;

// Each bit of an 8-lane mask three times: the mask of those lanes' interleaved barycentrics.
inline uint32_t triple_bits(uint32_t m) {
  return _pdep_u32(m, 0x249249u) | _pdep_u32(m, 0x492492u) | _pdep_u32(m, 0x924924u);
}

// Through the zero-masking forms with every lane set: the plain intrinsics pass gcc 12 an
// undefined vector that it warns about (-Wmaybe-uninitialized); instruction and bits are the same.
inline __m512d max_pd(__m512d a, __m512d b) {
  return _mm512_maskz_max_pd(__mmask8(0xFF), a, b);
}
inline __m256 to_float(__m512d v) {
  return _mm512_maskz_cvtpd_ps(__mmask8(0xFF), v);
}

// Float p of 3 x 8 interleaved barycentrics (lane p / 3, coordinate p % 3) taken from
// [b0 | b1] (indices 0-15) and b2 (16-23): the first 16 floats, then the last 8.
constexpr int interleaved_source(int p) {
  return (p % 3) * kLanes + p / 3;
}

void fill(const FillTriangle& t, const FillTarget& target, int x0, int y0, int x1, int y1,
          bool full, FillResult& result) {
  const __m512i lane_index = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7);
  __m512i lane_edge[3], group_step[3];
  __m512d q0[3], qa[3], qb[3];
  for (int i = 0; i < 3; ++i) {
    // k steps to the right: step_x * k, exact in 64-bit integers as the scalar formula.
    lane_edge[i] = _mm512_mullo_epi64(_mm512_set1_epi64(t.step_x[i]), lane_index);
    group_step[i] = _mm512_set1_epi64(t.step_x[i] * kLanes);
    q0[i] = _mm512_set1_pd(t.q0[i]);
    qa[i] = _mm512_set1_pd(t.qa[i]);
    qb[i] = _mm512_set1_pd(t.qb[i]);
  }
  const __m512d ox = _mm512_set1_pd(t.ox);
  const __m512d lane_offsets = _mm512_setr_pd(0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0);
  const __m512d half = _mm512_set1_pd(0.5), one = _mm512_set1_pd(1.0);
  const __m512d zero = _mm512_setzero_pd(), infinity = _mm512_set1_pd(__builtin_inf());
  const __m512d near_plane = _mm512_set1_pd(target.near_plane);
  const __m512d far_plane = _mm512_set1_pd(target.far_plane);
  const __m256i object = _mm256_set1_epi32(int32_t(t.object));
  const __m256i primitive = _mm256_set1_epi32(int32_t(t.primitive));
  const __m256i one_fragment = _mm256_set1_epi32(1);
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
    __m512i e[3];
    for (int i = 0; i < 3; ++i) e[i] = _mm512_add_epi64(_mm512_set1_epi64(row[i]), lane_edge[i]);
    const __m512d dy = _mm512_set1_pd(double(y) + 0.5 - t.oy);  // (py - oy), as the scalar formula
    const size_t row_start = size_t(y) * size_t(target.width);
    for (int x = x0; x <= x1; x += kLanes) {
      const int n = x1 - x + 1 < kLanes ? x1 - x + 1 : kLanes;
      __mmask8 mask = __mmask8((1u << n) - 1);
      // A negative edge function (sign bit set) puts the centre outside.
      if (!full)
        mask &= __mmask8(~_mm512_movepi64_mask(_mm512_or_si512(_mm512_or_si512(e[0], e[1]), e[2])));
      if (mask) {
        // px = x + k + 0.5, then the perspective planes, as the scalar formula.
        const __m512d dx =
            _mm512_add_pd(_mm512_add_pd(_mm512_set1_pd(double(x)), lane_offsets), half);
        const __m512d rel = _mm512_sub_pd(dx, ox);
        __m512d q[3];
        for (int j = 0; j < 3; ++j)
          q[j] = max_pd(  // max(v, 0) as std::max(0.0, v): NaN and -0 give +0
              _mm512_add_pd(_mm512_add_pd(q0[j], _mm512_mul_pd(qa[j], rel)),
                            _mm512_mul_pd(qb[j], dy)),
              zero);
        const __m512d s = _mm512_add_pd(_mm512_add_pd(q[0], q[1]), q[2]);
        const __m512d depth = _mm512_div_pd(one, s);
        result.generated += unsigned(__builtin_popcount(mask));
        const size_t i = row_start + size_t(x);
        if (!target.depth_only) {
          uint32_t* fragments = target.fragments + i;
          _mm256_mask_storeu_epi32(
              fragments, mask,
              _mm256_add_epi32(_mm256_maskz_loadu_epi32(mask, fragments), one_fragment));
        }
        // The depth test; the depth range clips what lies beyond far (and rounding just
        // inside near). Ordered compares: a NaN depth fails, as in the scalar test.
        const __m512d stored = _mm512_maskz_loadu_pd(mask, target.depth + i);
        __mmask8 passed = _mm512_mask_cmp_pd_mask(mask, depth, stored, _CMP_LT_OQ);
        passed = _mm512_mask_cmp_pd_mask(passed, depth, near_plane, _CMP_GE_OQ);
        passed = _mm512_mask_cmp_pd_mask(passed, depth, far_plane, _CMP_LE_OQ);
        if (passed) {
          result.drawn = true;
          // Pixels drawn for the first time leave their 8x8 block's count of empty pixels: the
          // group's lanes lie in block x / 8 and, from lane 8 - x % 8 on, in the next one.
          if (const unsigned first =
                  _mm512_mask_cmp_pd_mask(passed, stored, infinity, _CMP_EQ_OQ)) {
            const int in_first_block = kLanes - (x & 7);
            uint16_t* empty =
                target.block_empty + size_t(y >> 3) * size_t(target.blocks_x) + size_t(x >> 3);
            empty[0] =
                uint16_t(empty[0] - __builtin_popcount(first & ((1u << in_first_block) - 1)));
            if (const unsigned next = first >> in_first_block)
              empty[1] = uint16_t(empty[1] - __builtin_popcount(next));
          }
          _mm512_mask_storeu_pd(target.depth + i, passed, depth);
          if (!target.depth_only) {
            _mm256_mask_storeu_epi32(target.object + i, passed, object);
            _mm256_mask_storeu_epi32(target.primitive + i, passed, primitive);
            // The barycentrics (q / s, rounded to float as the scalar cast does), interleaved.
            const __m256 b0 = to_float(_mm512_div_pd(q[0], s));
            const __m256 b1 = to_float(_mm512_div_pd(q[1], s));
            const __m256 b2 = to_float(_mm512_div_pd(q[2], s));
            const __m512 b01 = _mm512_insertf32x8(_mm512_castps256_ps512(b0), b1, 1);
            const __m512 b2x = _mm512_castps256_ps512(b2);
            const uint32_t lanes = triple_bits(passed);
            float* bary = target.bary + 3 * i;
            _mm512_mask_storeu_ps(bary, __mmask16(lanes & 0xFFFFu),
                                  _mm512_permutex2var_ps(b01, interleave_lo, b2x));
            _mm512_mask_storeu_ps(bary + 16, __mmask16(lanes >> 16),
                                  _mm512_permutex2var_ps(b01, interleave_hi, b2x));
          }
        }
      }
      for (int i = 0; i < 3; ++i) e[i] = _mm512_add_epi64(e[i], group_step[i]);
    }
    for (int i = 0; i < 3; ++i) row[i] += t.step_y[i];
  }
}

}  // namespace
}  // namespace RVR_KERNEL_NS
}  // namespace rvr::soft
