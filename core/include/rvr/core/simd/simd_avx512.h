// The SIMD layer's 512-bit vectors (AVX-512 F, VL, DQ, BW), with the 128- and 256-bit ones
// (simd_sse.h, simd_avx2.h). Masks of 512-bit vectors are mask registers (one bit a lane), and
// masked loads and stores take them. Included through rvr/core/simd/simd.h only; see there
// for the rules.
#pragma once

#include <immintrin.h>

#include <cstdint>

#include "rvr/core/simd/simd_avx2.h"

#if !defined(__AVX512F__) || !defined(__AVX512VL__) || !defined(__AVX512DQ__)
#error "simd_avx512.h needs an AVX-512 (F, VL, DQ) translation unit"
#endif

// Some operations go through the zero-masking forms with every lane kept: the plain intrinsics
// start from an "undefined" vector that gcc 12 warns about (-Wmaybe-uninitialized); the
// instruction and the bits are the same.

namespace rvr::simd {
namespace {

// ------------------------------------------------------------------ 16 floats, 16-bit masks

struct vboolf16 {
  __mmask16 v;
  static vboolf16 from_bits(unsigned m) { return {__mmask16(m)}; }
  // Lanes of ~0u (set) or 0 (clear), 64-byte aligned.
  static vboolf16 load(const uint32_t* p) {
    return {_mm512_test_epi32_mask(_mm512_load_si512(p), _mm512_set1_epi32(-1))};
  }
};

struct vfloat16 {
  __m512 v;
  static vfloat16 load(const float* p) { return {_mm512_load_ps(p)}; }  // 64-byte aligned
  static vfloat16 loadu(const float* p) { return {_mm512_loadu_ps(p)}; }
  static vfloat16 splat(float x) { return {_mm512_set1_ps(x)}; }
  static vfloat16 zero() { return {_mm512_setzero_ps()}; }
};

inline void store(float* p, vfloat16 a) {
  _mm512_store_ps(p, a.v);
}

inline vfloat16 operator+(vfloat16 a, vfloat16 b) {
  return {_mm512_add_ps(a.v, b.v)};
}
inline vfloat16 operator-(vfloat16 a, vfloat16 b) {
  return {_mm512_sub_ps(a.v, b.v)};
}
inline vfloat16 operator*(vfloat16 a, vfloat16 b) {
  return {_mm512_mul_ps(a.v, b.v)};
}
inline vfloat16 operator/(vfloat16 a, vfloat16 b) {
  return {_mm512_div_ps(a.v, b.v)};
}
inline vfloat16 sqrt(vfloat16 a) {
  return {_mm512_maskz_sqrt_ps(__mmask16(0xFFFF), a.v)};
}
// MINPS / MAXPS: the second operand when either is NaN (and for -0 against +0).
inline vfloat16 min(vfloat16 a, vfloat16 b) {
  return {_mm512_maskz_min_ps(__mmask16(0xFFFF), a.v, b.v)};
}
inline vfloat16 max(vfloat16 a, vfloat16 b) {
  return {_mm512_maskz_max_ps(__mmask16(0xFFFF), a.v, b.v)};
}
inline vfloat16 operator-(vfloat16 a) {  // the sign bit flipped
  return {_mm512_castsi512_ps(
      _mm512_xor_si512(_mm512_castps_si512(a.v), _mm512_set1_epi32(int(0x80000000u))))};
}

inline vboolf16 operator<(vfloat16 a, vfloat16 b) {
  return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_LT_OQ)};
}
inline vboolf16 operator<=(vfloat16 a, vfloat16 b) {
  return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_LE_OQ)};
}
inline vboolf16 operator>(vfloat16 a, vfloat16 b) {
  return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_GT_OQ)};
}
inline vboolf16 operator>=(vfloat16 a, vfloat16 b) {
  return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_GE_OQ)};
}
inline vboolf16 operator==(vfloat16 a, vfloat16 b) {
  return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_EQ_OQ)};
}
inline vboolf16 operator!=(vfloat16 a, vfloat16 b) {
  return {_mm512_cmp_ps_mask(a.v, b.v, _CMP_NEQ_UQ)};
}

inline vboolf16 operator&(vboolf16 a, vboolf16 b) {
  return {__mmask16(a.v & b.v)};
}
inline vboolf16 operator|(vboolf16 a, vboolf16 b) {
  return {__mmask16(a.v | b.v)};
}
inline unsigned movemask(vboolf16 m) {
  return unsigned(m.v);
}
inline vfloat16 select(vboolf16 m, vfloat16 a, vfloat16 b) {  // m ? a : b
  return {_mm512_mask_blend_ps(m.v, b.v, a.v)};
}
// a in the lanes of m, +0 in the others.
inline vfloat16 masked(vboolf16 m, vfloat16 a) {
  return {_mm512_maskz_mov_ps(m.v, a.v)};
}
// Bitwise operations (AVX-512 DQ).
inline vfloat16 operator&(vfloat16 a, vfloat16 b) {
  return {_mm512_and_ps(a.v, b.v)};
}
inline vfloat16 operator|(vfloat16 a, vfloat16 b) {
  return {_mm512_or_ps(a.v, b.v)};
}
inline vfloat16 operator^(vfloat16 a, vfloat16 b) {
  return {_mm512_xor_ps(a.v, b.v)};
}
inline vfloat16 signbits(vfloat16 a) {
  return a & vfloat16::splat(-0.0f);
}
inline vfloat16 abs(vfloat16 a) {
  return {_mm512_andnot_ps(vfloat16::splat(-0.0f).v, a.v)};
}

// The largest lane of a, when no lane is NaN.
inline float reduce_max(vfloat16 a) {
  const vfloat8 m = max(vfloat8{_mm512_maskz_extractf32x8_ps(__mmask8(0xFF), a.v, 0)},
                        vfloat8{_mm512_maskz_extractf32x8_ps(__mmask8(0xFF), a.v, 1)});
  return reduce_max(m);
}

// ------------------------------------------------ 16 int32 (lanes of floats' bits or indices)

struct vint16 {
  __m512i v;
  static vint16 splat(int32_t x) { return {_mm512_set1_epi32(x)}; }
  static vint16 load(const uint32_t* p) { return {_mm512_load_si512(p)}; }  // 64-byte aligned
  static vint16 loadu(const uint32_t* p) { return {_mm512_loadu_si512(p)}; }
};

inline void store(uint32_t* p, vint16 a) {  // 64-byte aligned
  _mm512_store_si512(p, a.v);
}
inline void storeu(uint32_t* p, vint16 a) {
  _mm512_storeu_si512(p, a.v);
}
// Signed comparison.
inline vboolf16 operator<(vint16 a, vint16 b) {
  return {_mm512_cmplt_epi32_mask(a.v, b.v)};
}
inline vint16 select(vboolf16 m, vint16 a, vint16 b) {  // m ? a : b
  return {_mm512_mask_blend_epi32(m.v, b.v, a.v)};
}
inline vint16 operator+(vint16 a, vint16 b) {
  return {_mm512_add_epi32(a.v, b.v)};
}
inline vboolf16 less_unsigned(vint16 a, vint16 b) {
  return {_mm512_cmplt_epu32_mask(a.v, b.v)};
}
// base[index] in the lanes of m, 0 in the others (whose index is not read).
inline vint16 gather(const uint32_t* base, vint16 index, vboolf16 m) {
  return {_mm512_mask_i32gather_epi32(_mm512_setzero_si512(), m.v, index.v, base, 4)};
}

// ------------------------------------------------- 8 doubles, 8 int64, 8-bit masks

// The mask of 8 doubles or int64; also masks 8-lane int32 loads and stores.
struct vboold8 {
  __mmask8 v;
  static vboold8 from_bits(unsigned m) { return {__mmask8(m)}; }
};

inline vboold8 operator&(vboold8 a, vboold8 b) {
  return {__mmask8(a.v & b.v)};
}
inline vboold8 operator|(vboold8 a, vboold8 b) {
  return {__mmask8(a.v | b.v)};
}
inline vboold8 operator~(vboold8 a) {
  return {__mmask8(~a.v)};
}
inline unsigned movemask(vboold8 m) {
  return unsigned(m.v);
}

struct vdouble8 {
  __m512d v;
  static vdouble8 splat(double x) { return {_mm512_set1_pd(x)}; }
  static vdouble8 zero() { return {_mm512_setzero_pd()}; }
  static vdouble8 iota() {  // lane k holds k
    return {_mm512_setr_pd(0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0)};
  }
  // The lanes of m from p, +0 in the others (which are not read).
  static vdouble8 loadu(vboold8 m, const double* p) { return {_mm512_maskz_loadu_pd(m.v, p)}; }
};

inline void storeu(vboold8 m, double* p, vdouble8 a) {
  _mm512_mask_storeu_pd(p, m.v, a.v);
}
inline vdouble8 operator+(vdouble8 a, vdouble8 b) {
  return {_mm512_add_pd(a.v, b.v)};
}
inline vdouble8 operator-(vdouble8 a, vdouble8 b) {
  return {_mm512_sub_pd(a.v, b.v)};
}
inline vdouble8 operator*(vdouble8 a, vdouble8 b) {
  return {_mm512_mul_pd(a.v, b.v)};
}
inline vdouble8 operator/(vdouble8 a, vdouble8 b) {
  return {_mm512_div_pd(a.v, b.v)};
}
inline vdouble8 max(vdouble8 a, vdouble8 b) {  // MAXPD: the second operand when either is NaN
  return {_mm512_maskz_max_pd(__mmask8(0xFF), a.v, b.v)};
}
// Rounded to float, as the scalar cast.
inline vfloat8 to_float(vdouble8 a) {
  return {_mm512_maskz_cvtpd_ps(__mmask8(0xFF), a.v)};
}

inline vboold8 operator<(vdouble8 a, vdouble8 b) {
  return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_LT_OQ)};
}
inline vboold8 operator<=(vdouble8 a, vdouble8 b) {
  return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_LE_OQ)};
}
inline vboold8 operator>=(vdouble8 a, vdouble8 b) {
  return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_GE_OQ)};
}
inline vboold8 operator==(vdouble8 a, vdouble8 b) {
  return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_EQ_OQ)};
}
// m & (a < b) etc. in one masked compare.
inline vboold8 less(vboold8 m, vdouble8 a, vdouble8 b) {
  return {_mm512_mask_cmp_pd_mask(m.v, a.v, b.v, _CMP_LT_OQ)};
}
inline vboold8 less_equal(vboold8 m, vdouble8 a, vdouble8 b) {
  return {_mm512_mask_cmp_pd_mask(m.v, a.v, b.v, _CMP_LE_OQ)};
}
inline vboold8 greater_equal(vboold8 m, vdouble8 a, vdouble8 b) {
  return {_mm512_mask_cmp_pd_mask(m.v, a.v, b.v, _CMP_GE_OQ)};
}
inline vboold8 equal(vboold8 m, vdouble8 a, vdouble8 b) {
  return {_mm512_mask_cmp_pd_mask(m.v, a.v, b.v, _CMP_EQ_OQ)};
}

struct vllong8 {
  __m512i v;
  static vllong8 splat(int64_t x) { return {_mm512_set1_epi64(x)}; }
  static vllong8 iota() { return {_mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7)}; }  // lane k: k
};

inline vllong8 operator+(vllong8 a, vllong8 b) {
  return {_mm512_add_epi64(a.v, b.v)};
}
inline vllong8 operator*(vllong8 a, vllong8 b) {
  return {_mm512_mullo_epi64(a.v, b.v)};
}
inline vllong8 operator|(vllong8 a, vllong8 b) {
  return {_mm512_or_si512(a.v, b.v)};
}
inline vboold8 sign_bits(vllong8 a) {
  return {_mm512_movepi64_mask(a.v)};
}  // negative lanes

// Masked 8 x int32 (AVX-512VL): the lanes of m from p, 0 in the others (not read); stores of
// the lanes of m.
inline vint8 loadu(vboold8 m, const uint32_t* p) {
  return {_mm256_maskz_loadu_epi32(m.v, p)};
}
inline void storeu(vboold8 m, uint32_t* p, vint8 a) {
  _mm256_mask_storeu_epi32(p, m.v, a.v);
}

}  // namespace
}  // namespace rvr::simd
