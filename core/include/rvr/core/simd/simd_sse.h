// The SIMD layer's 128-bit vectors (SSE2, baseline x86-64), in every instruction set's layer:
// the AVX2 and AVX-512 kernels use them too (their compilers give the same operations VEX
// encodings). Included through rvr/core/simd/simd.h only; see there for the rules.
#pragma once

#include <immintrin.h>

#include <cstdint>

namespace rvr::simd {
namespace {

// ------------------------------------------------------------------- 4 floats, 4-lane masks

// A lane mask: every bit of a lane set or clear, as SSE's compares give it.
struct vboolf4 {
  __m128 v;
  // Lanes of ~0u (set) or 0 (clear), 16-byte aligned.
  static vboolf4 load(const uint32_t* p) {
    return {_mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(p)))};
  }
  static vboolf4 from_bits(unsigned m) {  // lane k set when bit k of m is
    const __m128i bits = _mm_setr_epi32(1, 2, 4, 8);
    return {_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(int(m)), bits), bits))};
  }
};

struct vfloat4 {
  __m128 v;
  static vfloat4 load(const float* p) { return {_mm_load_ps(p)}; }  // 16-byte aligned
  static vfloat4 loadu(const float* p) { return {_mm_loadu_ps(p)}; }
  static vfloat4 splat(float x) { return {_mm_set1_ps(x)}; }
  static vfloat4 zero() { return {_mm_setzero_ps()}; }
};

inline void store(float* p, vfloat4 a) {
  _mm_store_ps(p, a.v);
}
inline void storeu(float* p, vfloat4 a) {
  _mm_storeu_ps(p, a.v);
}

inline vfloat4 operator+(vfloat4 a, vfloat4 b) {
  return {_mm_add_ps(a.v, b.v)};
}
inline vfloat4 operator-(vfloat4 a, vfloat4 b) {
  return {_mm_sub_ps(a.v, b.v)};
}
inline vfloat4 operator*(vfloat4 a, vfloat4 b) {
  return {_mm_mul_ps(a.v, b.v)};
}
inline vfloat4 operator/(vfloat4 a, vfloat4 b) {
  return {_mm_div_ps(a.v, b.v)};
}
inline vfloat4 sqrt(vfloat4 a) {
  return {_mm_sqrt_ps(a.v)};
}
// MINPS / MAXPS: the second operand when either is NaN (and for -0 against +0).
inline vfloat4 min(vfloat4 a, vfloat4 b) {
  return {_mm_min_ps(a.v, b.v)};
}
inline vfloat4 max(vfloat4 a, vfloat4 b) {
  return {_mm_max_ps(a.v, b.v)};
}
// Bitwise operations on the floats' bits.
inline vfloat4 operator&(vfloat4 a, vfloat4 b) {
  return {_mm_and_ps(a.v, b.v)};
}
inline vfloat4 operator|(vfloat4 a, vfloat4 b) {
  return {_mm_or_ps(a.v, b.v)};
}
inline vfloat4 operator^(vfloat4 a, vfloat4 b) {
  return {_mm_xor_ps(a.v, b.v)};
}
inline vfloat4 andnot(vfloat4 a, vfloat4 b) {
  return {_mm_andnot_ps(a.v, b.v)};
}  // ~a & b
// The sign bit flipped (exact: no rounding, NaNs keep their payload).
inline vfloat4 operator-(vfloat4 a) {
  return a ^ vfloat4::splat(-0.0f);
}
inline vfloat4 signbits(vfloat4 a) {
  return a & vfloat4::splat(-0.0f);
}  // +0 or -0
inline vfloat4 abs(vfloat4 a) {
  return andnot(vfloat4::splat(-0.0f), a);
}

// Comparisons: ordered (false with a NaN) but != (true with a NaN).
inline vboolf4 operator<(vfloat4 a, vfloat4 b) {
  return {_mm_cmplt_ps(a.v, b.v)};
}
inline vboolf4 operator<=(vfloat4 a, vfloat4 b) {
  return {_mm_cmple_ps(a.v, b.v)};
}
inline vboolf4 operator>(vfloat4 a, vfloat4 b) {
  return {_mm_cmpgt_ps(a.v, b.v)};
}
inline vboolf4 operator>=(vfloat4 a, vfloat4 b) {
  return {_mm_cmpge_ps(a.v, b.v)};
}
inline vboolf4 operator==(vfloat4 a, vfloat4 b) {
  return {_mm_cmpeq_ps(a.v, b.v)};
}
inline vboolf4 operator!=(vfloat4 a, vfloat4 b) {
  return {_mm_cmpneq_ps(a.v, b.v)};
}

inline vboolf4 operator&(vboolf4 a, vboolf4 b) {
  return {_mm_and_ps(a.v, b.v)};
}
inline vboolf4 operator|(vboolf4 a, vboolf4 b) {
  return {_mm_or_ps(a.v, b.v)};
}
// Bit k set when lane k is.
inline unsigned movemask(vboolf4 m) {
  return unsigned(_mm_movemask_ps(m.v));
}
// m ? a : b, lane by lane. Baseline SSE has no blendv: and / andnot / or, the same choice.
inline vfloat4 select(vboolf4 m, vfloat4 a, vfloat4 b) {
#if defined(__SSE4_1__)
  return {_mm_blendv_ps(b.v, a.v, m.v)};
#else
  return {_mm_or_ps(_mm_and_ps(m.v, a.v), _mm_andnot_ps(m.v, b.v))};
#endif
}
inline vboolf4 select(vboolf4 m, vboolf4 a, vboolf4 b) {  // m ? a : b, lane by lane
  return {select(m, vfloat4{a.v}, vfloat4{b.v}).v};
}
// a in the lanes of m, +0 in the others (a bitwise and).
inline vfloat4 masked(vboolf4 m, vfloat4 a) {
  return {_mm_and_ps(m.v, a.v)};
}

// ------------------------------------------------- 4 int32 (lanes of floats' bits or indices)

struct vint4 {
  __m128i v;
  static vint4 splat(int32_t x) { return {_mm_set1_epi32(x)}; }
  static vint4 setr(int32_t a, int32_t b, int32_t c, int32_t d) {
    return {_mm_setr_epi32(a, b, c, d)};
  }
  static vint4 load(const uint32_t* p) {  // 16-byte aligned
    return {_mm_load_si128(reinterpret_cast<const __m128i*>(p))};
  }
  static vint4 loadu(const uint32_t* p) {
    return {_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))};
  }
};

inline void store(uint32_t* p, vint4 a) {  // 16-byte aligned
  _mm_store_si128(reinterpret_cast<__m128i*>(p), a.v);
}
inline void storeu(uint32_t* p, vint4 a) {
  _mm_storeu_si128(reinterpret_cast<__m128i*>(p), a.v);
}

inline vint4 operator&(vint4 a, vint4 b) {
  return {_mm_and_si128(a.v, b.v)};
}
// Signed comparisons, as masks of float lanes.
inline vboolf4 operator<(vint4 a, vint4 b) {
  return {_mm_castsi128_ps(_mm_cmpgt_epi32(b.v, a.v))};
}
inline vboolf4 operator==(vint4 a, vint4 b) {
  return {_mm_castsi128_ps(_mm_cmpeq_epi32(a.v, b.v))};
}
// m ? a : b, lane by lane, through the float select (the same bits).
inline vint4 select(vboolf4 m, vint4 a, vint4 b) {
  return {_mm_castps_si128(
      select(m, vfloat4{_mm_castsi128_ps(a.v)}, vfloat4{_mm_castsi128_ps(b.v)}).v)};
}
inline vint4 operator+(vint4 a, vint4 b) {
  return {_mm_add_epi32(a.v, b.v)};
}
// Unsigned a < b: the signed comparison with both sign bits flipped.
inline vboolf4 less_unsigned(vint4 a, vint4 b) {
  const __m128i sign = _mm_set1_epi32(INT32_MIN);
  return {_mm_castsi128_ps(_mm_cmpgt_epi32(_mm_xor_si128(b.v, sign), _mm_xor_si128(a.v, sign)))};
}
// base[index] in the lanes of m, 0 in the others (whose index is not read); lane by lane, as
// SSE has no gather.
inline vint4 gather(const uint32_t* base, vint4 index, vboolf4 m) {
  alignas(16) uint32_t i[4], out[4];
  store(i, index);
  const unsigned bits = unsigned(_mm_movemask_ps(m.v));
  for (int l = 0; l < 4; ++l) out[l] = (bits >> l) & 1u ? base[i[l]] : 0u;
  return vint4::load(out);
}

// Lane k takes lane k ^ J (J = 1 or 2).
template <int J>
inline vfloat4 swap_lanes(vfloat4 a) {
  static_assert(J == 1 || J == 2);
  if constexpr (J == 1) return {_mm_shuffle_ps(a.v, a.v, 0xB1)};
  if constexpr (J == 2) return {_mm_shuffle_ps(a.v, a.v, 0x4E)};
}
template <int J>
inline vint4 swap_lanes(vint4 a) {
  return {_mm_castps_si128(swap_lanes<J>(vfloat4{_mm_castsi128_ps(a.v)}).v)};
}
// The largest lane of a, when no lane is NaN.
inline float reduce_max(vfloat4 a) {
  a = max(a, swap_lanes<2>(a));
  a = max(a, swap_lanes<1>(a));
  return _mm_cvtss_f32(a.v);
}

// ------------------------------------------------------------- 2 doubles, 2 int64

struct vdouble2 {
  __m128d v;
  static vdouble2 splat(double x) { return {_mm_set1_pd(x)}; }
  static vdouble2 zero() { return {_mm_setzero_pd()}; }
  static vdouble2 iota() { return {_mm_setr_pd(0.0, 1.0)}; }  // lane k holds k
};

inline void storeu(double* p, vdouble2 a) {
  _mm_storeu_pd(p, a.v);
}
inline vdouble2 operator+(vdouble2 a, vdouble2 b) {
  return {_mm_add_pd(a.v, b.v)};
}
inline vdouble2 operator-(vdouble2 a, vdouble2 b) {
  return {_mm_sub_pd(a.v, b.v)};
}
inline vdouble2 operator*(vdouble2 a, vdouble2 b) {
  return {_mm_mul_pd(a.v, b.v)};
}
inline vdouble2 operator/(vdouble2 a, vdouble2 b) {
  return {_mm_div_pd(a.v, b.v)};
}
// MAXPD: the second operand when either is NaN.
inline vdouble2 max(vdouble2 a, vdouble2 b) {
  return {_mm_max_pd(a.v, b.v)};
}

struct vllong2 {
  __m128i v;
  static vllong2 splat(int64_t x) { return {_mm_set1_epi64x(x)}; }
  static vllong2 loadu(const int64_t* p) {
    return {_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))};
  }
};

inline vllong2 operator+(vllong2 a, vllong2 b) {
  return {_mm_add_epi64(a.v, b.v)};
}
inline vllong2 operator|(vllong2 a, vllong2 b) {
  return {_mm_or_si128(a.v, b.v)};
}
// Bit k set when lane k is negative.
inline unsigned sign_bits(vllong2 a) {
  return unsigned(_mm_movemask_pd(_mm_castsi128_pd(a.v)));
}

}  // namespace
}  // namespace rvr::simd
