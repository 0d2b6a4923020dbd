// The SIMD layer's 256-bit vectors (AVX2), in the AVX2 and AVX-512 layers, with the 128-bit
// ones (simd_sse.h). Included through rvr/core/simd/simd.h only; see there for the rules.
#pragma once

#include <immintrin.h>

#include <cstdint>

#include "rvr/core/simd/simd_sse.h"

#if !defined(__AVX2__)
#error "simd_avx2.h needs an AVX2 translation unit"
#endif

namespace rvr::simd {
namespace {

// ------------------------------------------------------------------- 8 floats, 8-lane masks

// A lane mask: every bit of a lane set or clear, as AVX's compares give it (also in AVX-512
// units, where 8-float compares that end in a bit mask go straight to one: le_bits).
struct vboolf8 {
  __m256 v;
  // Lane k set when bit k of m is.
  static vboolf8 from_bits(unsigned m) {
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return {_mm256_castsi256_ps(
        _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(int(m)), bit), bit))};
  }
  // Lanes of ~0u (set) or 0 (clear), 32-byte aligned.
  static vboolf8 load(const uint32_t* p) {
    return {_mm256_castsi256_ps(_mm256_load_si256(reinterpret_cast<const __m256i*>(p)))};
  }
};

struct vfloat8 {
  __m256 v;
  static vfloat8 load(const float* p) { return {_mm256_load_ps(p)}; }  // 32-byte aligned
  static vfloat8 loadu(const float* p) { return {_mm256_loadu_ps(p)}; }
  static vfloat8 splat(float x) { return {_mm256_set1_ps(x)}; }
  static vfloat8 zero() { return {_mm256_setzero_ps()}; }
};

inline void store(float* p, vfloat8 a) {
  _mm256_store_ps(p, a.v);
}
inline void storeu(float* p, vfloat8 a) {
  _mm256_storeu_ps(p, a.v);
}

inline vfloat8 operator+(vfloat8 a, vfloat8 b) {
  return {_mm256_add_ps(a.v, b.v)};
}
inline vfloat8 operator-(vfloat8 a, vfloat8 b) {
  return {_mm256_sub_ps(a.v, b.v)};
}
inline vfloat8 operator*(vfloat8 a, vfloat8 b) {
  return {_mm256_mul_ps(a.v, b.v)};
}
inline vfloat8 operator/(vfloat8 a, vfloat8 b) {
  return {_mm256_div_ps(a.v, b.v)};
}
inline vfloat8 sqrt(vfloat8 a) {
  return {_mm256_sqrt_ps(a.v)};
}
// MINPS / MAXPS: the second operand when either is NaN (and for -0 against +0).
inline vfloat8 min(vfloat8 a, vfloat8 b) {
  return {_mm256_min_ps(a.v, b.v)};
}
inline vfloat8 max(vfloat8 a, vfloat8 b) {
  return {_mm256_max_ps(a.v, b.v)};
}
inline vfloat8 operator&(vfloat8 a, vfloat8 b) {
  return {_mm256_and_ps(a.v, b.v)};
}
inline vfloat8 operator|(vfloat8 a, vfloat8 b) {
  return {_mm256_or_ps(a.v, b.v)};
}
inline vfloat8 operator^(vfloat8 a, vfloat8 b) {
  return {_mm256_xor_ps(a.v, b.v)};
}
inline vfloat8 andnot(vfloat8 a, vfloat8 b) {
  return {_mm256_andnot_ps(a.v, b.v)};
}  // ~a & b
inline vfloat8 operator-(vfloat8 a) {
  return a ^ vfloat8::splat(-0.0f);
}  // sign bit flipped
inline vfloat8 signbits(vfloat8 a) {
  return a & vfloat8::splat(-0.0f);
}
inline vfloat8 abs(vfloat8 a) {
  return andnot(vfloat8::splat(-0.0f), a);
}

inline vboolf8 operator<(vfloat8 a, vfloat8 b) {
  return {_mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ)};
}
inline vboolf8 operator<=(vfloat8 a, vfloat8 b) {
  return {_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)};
}
inline vboolf8 operator>(vfloat8 a, vfloat8 b) {
  return {_mm256_cmp_ps(a.v, b.v, _CMP_GT_OQ)};
}
inline vboolf8 operator>=(vfloat8 a, vfloat8 b) {
  return {_mm256_cmp_ps(a.v, b.v, _CMP_GE_OQ)};
}
inline vboolf8 operator==(vfloat8 a, vfloat8 b) {
  return {_mm256_cmp_ps(a.v, b.v, _CMP_EQ_OQ)};
}
inline vboolf8 operator!=(vfloat8 a, vfloat8 b) {
  return {_mm256_cmp_ps(a.v, b.v, _CMP_NEQ_UQ)};
}

inline vboolf8 operator&(vboolf8 a, vboolf8 b) {
  return {_mm256_and_ps(a.v, b.v)};
}
inline vboolf8 operator|(vboolf8 a, vboolf8 b) {
  return {_mm256_or_ps(a.v, b.v)};
}
inline unsigned movemask(vboolf8 m) {
  return unsigned(_mm256_movemask_ps(m.v));
}
// movemask(a <= b); with AVX-512VL one compare into a mask register.
inline unsigned le_bits(vfloat8 a, vfloat8 b) {
#if defined(__AVX512VL__)
  return unsigned(_mm256_cmp_ps_mask(a.v, b.v, _CMP_LE_OQ));
#else
  return movemask(a <= b);
#endif
}
inline vfloat8 select(vboolf8 m, vfloat8 a, vfloat8 b) {  // m ? a : b
  return {_mm256_blendv_ps(b.v, a.v, m.v)};
}
inline vboolf8 select(vboolf8 m, vboolf8 a, vboolf8 b) {  // m ? a : b
  return {_mm256_blendv_ps(b.v, a.v, m.v)};
}
// a in the lanes of m, +0 in the others (a bitwise and).
inline vfloat8 masked(vboolf8 m, vfloat8 a) {
  return {_mm256_and_ps(m.v, a.v)};
}

// Lane k takes lane k ^ J (J = 1, 2 or 4).
template <int J>
inline vfloat8 swap_lanes(vfloat8 a) {
  static_assert(J == 1 || J == 2 || J == 4);
  if constexpr (J == 1) return {_mm256_permute_ps(a.v, 0xB1)};
  if constexpr (J == 2) return {_mm256_permute_ps(a.v, 0x4E)};
  if constexpr (J == 4) return {_mm256_permute2f128_ps(a.v, a.v, 1)};
}

// The largest lane of a, when no lane is NaN.
inline float reduce_max(vfloat8 a) {
  a = max(a, swap_lanes<4>(a));
  a = max(a, swap_lanes<2>(a));
  a = max(a, swap_lanes<1>(a));
  return _mm256_cvtss_f32(a.v);
}

// ------------------------------------------------- 8 int32 (lanes of floats' bits or indices)

struct vint8 {
  __m256i v;
  static vint8 splat(int32_t x) { return {_mm256_set1_epi32(x)}; }
  static vint8 load(const uint32_t* p) {  // 32-byte aligned
    return {_mm256_castps_si256(_mm256_load_ps(reinterpret_cast<const float*>(p)))};
  }
  static vint8 loadu(const uint32_t* p) {
    return {_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p))};
  }
};

inline void store(uint32_t* p, vint8 a) {  // 32-byte aligned
  _mm256_store_ps(reinterpret_cast<float*>(p), _mm256_castsi256_ps(a.v));
}
inline void storeu(uint32_t* p, vint8 a) {
  _mm256_storeu_ps(reinterpret_cast<float*>(p), _mm256_castsi256_ps(a.v));
}
inline vint8 operator+(vint8 a, vint8 b) {
  return {_mm256_add_epi32(a.v, b.v)};
}
// Signed comparison, as a mask of float lanes.
inline vboolf8 operator<(vint8 a, vint8 b) {
  return {_mm256_castsi256_ps(_mm256_cmpgt_epi32(b.v, a.v))};
}
inline vint8 select(vboolf8 m, vint8 a, vint8 b) {  // m ? a : b, through the float blend
  return {_mm256_castps_si256(
      _mm256_blendv_ps(_mm256_castsi256_ps(b.v), _mm256_castsi256_ps(a.v), m.v))};
}
// Unsigned a < b: the signed comparison with both sign bits flipped.
inline vboolf8 less_unsigned(vint8 a, vint8 b) {
  const __m256i sign = _mm256_set1_epi32(INT32_MIN);
  return {_mm256_castsi256_ps(
      _mm256_cmpgt_epi32(_mm256_xor_si256(b.v, sign), _mm256_xor_si256(a.v, sign)))};
}
// base[index] in the lanes of m, 0 in the others (whose index is not read).
inline vint8 gather(const uint32_t* base, vint8 index, vboolf8 m) {
  return {_mm256_mask_i32gather_epi32(_mm256_setzero_si256(), reinterpret_cast<const int*>(base),
                                      index.v, _mm256_castps_si256(m.v), 4)};
}
template <int J>
inline vint8 swap_lanes(vint8 a) {
  return {_mm256_castps_si256(swap_lanes<J>(vfloat8{_mm256_castsi256_ps(a.v)}).v)};
}

// ------------------------------------------------------------- 4 doubles, 4 int64

struct vdouble4 {
  __m256d v;
  static vdouble4 splat(double x) { return {_mm256_set1_pd(x)}; }
  static vdouble4 zero() { return {_mm256_setzero_pd()}; }
  static vdouble4 iota() { return {_mm256_setr_pd(0.0, 1.0, 2.0, 3.0)}; }  // lane k holds k
};

inline void storeu(double* p, vdouble4 a) {
  _mm256_storeu_pd(p, a.v);
}
inline vdouble4 operator+(vdouble4 a, vdouble4 b) {
  return {_mm256_add_pd(a.v, b.v)};
}
inline vdouble4 operator-(vdouble4 a, vdouble4 b) {
  return {_mm256_sub_pd(a.v, b.v)};
}
inline vdouble4 operator*(vdouble4 a, vdouble4 b) {
  return {_mm256_mul_pd(a.v, b.v)};
}
inline vdouble4 operator/(vdouble4 a, vdouble4 b) {
  return {_mm256_div_pd(a.v, b.v)};
}
inline vdouble4 max(vdouble4 a, vdouble4 b) {
  return {_mm256_max_pd(a.v, b.v)};
}

struct vllong4 {
  __m256i v;
  static vllong4 splat(int64_t x) { return {_mm256_set1_epi64x(x)}; }
  static vllong4 loadu(const int64_t* p) {
    return {_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p))};
  }
};

inline vllong4 operator+(vllong4 a, vllong4 b) {
  return {_mm256_add_epi64(a.v, b.v)};
}
inline vllong4 operator|(vllong4 a, vllong4 b) {
  return {_mm256_or_si256(a.v, b.v)};
}
inline unsigned sign_bits(vllong4 a) {  // bit k set when lane k is negative
  return unsigned(_mm256_movemask_pd(_mm256_castsi256_pd(a.v)));
}

}  // namespace
}  // namespace rvr::simd
