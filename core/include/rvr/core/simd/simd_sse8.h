// The SSE layer's 8-lane vectors: two 128-bit halves (lanes 0-3, 4-7), with the operations and
// the lane order of the AVX2 layer's vfloat8, vboolf8 and vint8, so kernels written for 8 lanes
// compile for SSE too. Included through rvr/core/simd/simd.h only; see there for the rules.
#pragma once

#include <immintrin.h>

#include <cstdint>

#include "rvr/core/simd/simd_sse.h"

#if defined(__AVX2__)
#error "simd_sse8.h is the SSE layer's; AVX2 units have native 8-lane vectors (simd_avx2.h)"
#endif

namespace rvr::simd {
namespace {

struct vboolf8 {
  vboolf4 lo, hi;
  static vboolf8 from_bits(unsigned m) {  // lane k set when bit k of m is
    return {vboolf4::from_bits(m & 0xFu), vboolf4::from_bits((m >> 4) & 0xFu)};
  }
};

struct vfloat8 {
  vfloat4 lo, hi;
  static vfloat8 load(const float* p) { return {vfloat4::load(p), vfloat4::load(p + 4)}; }
  static vfloat8 loadu(const float* p) { return {vfloat4::loadu(p), vfloat4::loadu(p + 4)}; }
  static vfloat8 splat(float x) { return {vfloat4::splat(x), vfloat4::splat(x)}; }
  static vfloat8 zero() { return {vfloat4::zero(), vfloat4::zero()}; }
};

inline void store(float* p, vfloat8 a) {
  store(p, a.lo);
  store(p + 4, a.hi);
}
inline void storeu(float* p, vfloat8 a) {
  storeu(p, a.lo);
  storeu(p + 4, a.hi);
}

inline vfloat8 operator+(vfloat8 a, vfloat8 b) {
  return {a.lo + b.lo, a.hi + b.hi};
}
inline vfloat8 operator-(vfloat8 a, vfloat8 b) {
  return {a.lo - b.lo, a.hi - b.hi};
}
inline vfloat8 operator*(vfloat8 a, vfloat8 b) {
  return {a.lo * b.lo, a.hi * b.hi};
}
inline vfloat8 operator/(vfloat8 a, vfloat8 b) {
  return {a.lo / b.lo, a.hi / b.hi};
}
inline vfloat8 sqrt(vfloat8 a) {
  return {sqrt(a.lo), sqrt(a.hi)};
}
inline vfloat8 min(vfloat8 a, vfloat8 b) {
  return {min(a.lo, b.lo), min(a.hi, b.hi)};
}
inline vfloat8 max(vfloat8 a, vfloat8 b) {
  return {max(a.lo, b.lo), max(a.hi, b.hi)};
}
inline vfloat8 operator&(vfloat8 a, vfloat8 b) {
  return {a.lo & b.lo, a.hi & b.hi};
}
inline vfloat8 operator|(vfloat8 a, vfloat8 b) {
  return {a.lo | b.lo, a.hi | b.hi};
}
inline vfloat8 operator^(vfloat8 a, vfloat8 b) {
  return {a.lo ^ b.lo, a.hi ^ b.hi};
}
inline vfloat8 andnot(vfloat8 a, vfloat8 b) {
  return {andnot(a.lo, b.lo), andnot(a.hi, b.hi)};
}
inline vfloat8 operator-(vfloat8 a) {
  return {-a.lo, -a.hi};
}
inline vfloat8 signbits(vfloat8 a) {
  return {signbits(a.lo), signbits(a.hi)};
}
inline vfloat8 abs(vfloat8 a) {
  return {abs(a.lo), abs(a.hi)};
}

inline vboolf8 operator<(vfloat8 a, vfloat8 b) {
  return {a.lo < b.lo, a.hi < b.hi};
}
inline vboolf8 operator<=(vfloat8 a, vfloat8 b) {
  return {a.lo <= b.lo, a.hi <= b.hi};
}
inline vboolf8 operator>(vfloat8 a, vfloat8 b) {
  return {a.lo > b.lo, a.hi > b.hi};
}
inline vboolf8 operator>=(vfloat8 a, vfloat8 b) {
  return {a.lo >= b.lo, a.hi >= b.hi};
}
inline vboolf8 operator==(vfloat8 a, vfloat8 b) {
  return {a.lo == b.lo, a.hi == b.hi};
}
inline vboolf8 operator!=(vfloat8 a, vfloat8 b) {
  return {a.lo != b.lo, a.hi != b.hi};
}

inline vboolf8 operator&(vboolf8 a, vboolf8 b) {
  return {a.lo & b.lo, a.hi & b.hi};
}
inline vboolf8 operator|(vboolf8 a, vboolf8 b) {
  return {a.lo | b.lo, a.hi | b.hi};
}
inline unsigned movemask(vboolf8 m) {
  return movemask(m.lo) | movemask(m.hi) << 4;
}
inline unsigned le_bits(vfloat8 a, vfloat8 b) {
  return movemask(a <= b);
}
inline vfloat8 select(vboolf8 m, vfloat8 a, vfloat8 b) {  // m ? a : b
  return {select(m.lo, a.lo, b.lo), select(m.hi, a.hi, b.hi)};
}
inline vboolf8 select(vboolf8 m, vboolf8 a, vboolf8 b) {
  return {select(m.lo, a.lo, b.lo), select(m.hi, a.hi, b.hi)};
}
inline vfloat8 masked(vboolf8 m, vfloat8 a) {
  return {masked(m.lo, a.lo), masked(m.hi, a.hi)};
}

template <int J>  // lane k takes lane k ^ J (J = 1, 2 or 4)
inline vfloat8 swap_lanes(vfloat8 a) {
  static_assert(J == 1 || J == 2 || J == 4);
  if constexpr (J == 1)
    return {{_mm_shuffle_ps(a.lo.v, a.lo.v, 0xB1)}, {_mm_shuffle_ps(a.hi.v, a.hi.v, 0xB1)}};
  if constexpr (J == 2)
    return {{_mm_shuffle_ps(a.lo.v, a.lo.v, 0x4E)}, {_mm_shuffle_ps(a.hi.v, a.hi.v, 0x4E)}};
  if constexpr (J == 4) return {a.hi, a.lo};
}

struct vint8 {
  vint4 lo, hi;
  static vint8 splat(int32_t x) { return {vint4::splat(x), vint4::splat(x)}; }
  static vint8 load(const uint32_t* p) {  // 16-byte aligned
    const float* f = reinterpret_cast<const float*>(p);
    return {{_mm_castps_si128(_mm_load_ps(f))}, {_mm_castps_si128(_mm_load_ps(f + 4))}};
  }
};

inline void store(uint32_t* p, vint8 a) {  // 16-byte aligned
  float* f = reinterpret_cast<float*>(p);
  _mm_store_ps(f, _mm_castsi128_ps(a.lo.v));
  _mm_store_ps(f + 4, _mm_castsi128_ps(a.hi.v));
}
inline void storeu(uint32_t* p, vint8 a) {
  float* f = reinterpret_cast<float*>(p);
  _mm_storeu_ps(f, _mm_castsi128_ps(a.lo.v));
  _mm_storeu_ps(f + 4, _mm_castsi128_ps(a.hi.v));
}
inline vboolf8 operator<(vint8 a, vint8 b) {
  return {a.lo < b.lo, a.hi < b.hi};
}
inline vint8 select(vboolf8 m, vint8 a, vint8 b) {
  return {select(m.lo, a.lo, b.lo), select(m.hi, a.hi, b.hi)};
}
template <int J>
inline vint8 swap_lanes(vint8 a) {
  const vfloat8 f = swap_lanes<J>(vfloat8{{_mm_castsi128_ps(a.lo.v)}, {_mm_castsi128_ps(a.hi.v)}});
  return {{_mm_castps_si128(f.lo.v)}, {_mm_castps_si128(f.hi.v)}};
}

}  // namespace
}  // namespace rvr::simd
