// 16-lane vectors for the AVX2 and SSE layers: two 8-lane halves (lanes 0-7, 8-15) with the
// operations and the lane order of the AVX-512 layer's vfloat16, vboolf16 and vint16, so a kernel
// written for 16 lanes compiles for every ISA and does the same operations in each. Built on
// the layer's vfloat8, vboolf8 and vint8 (native in AVX2 units, two halves in SSE ones).
// Included through rvr/core/simd/simd.h only; see there for the rules.
#pragma once

#include <cstdint>

#if defined(__AVX512F__)
#error "simd_pair16.h is for AVX2 and SSE units; AVX-512 ones have native 16-lane vectors"
#endif

#if defined(__AVX2__)
#include "rvr/core/simd/simd_avx2.h"
#else
#include "rvr/core/simd/simd_sse8.h"
#endif

namespace rvr::simd {
namespace {

struct vboolf16 {
  vboolf8 lo, hi;
  static vboolf16 from_bits(unsigned m) {  // lane k set when bit k of m is
    return {vboolf8::from_bits(m & 0xFFu), vboolf8::from_bits((m >> 8) & 0xFFu)};
  }
};

struct vfloat16 {
  vfloat8 lo, hi;
  static vfloat16 load(const float* p) { return {vfloat8::load(p), vfloat8::load(p + 8)}; }
  static vfloat16 splat(float x) { return {vfloat8::splat(x), vfloat8::splat(x)}; }
  static vfloat16 zero() { return {vfloat8::zero(), vfloat8::zero()}; }
};

inline void store(float* p, vfloat16 a) {
  store(p, a.lo);
  store(p + 8, a.hi);
}

inline vfloat16 operator+(vfloat16 a, vfloat16 b) {
  return {a.lo + b.lo, a.hi + b.hi};
}
inline vfloat16 operator-(vfloat16 a, vfloat16 b) {
  return {a.lo - b.lo, a.hi - b.hi};
}
inline vfloat16 operator*(vfloat16 a, vfloat16 b) {
  return {a.lo * b.lo, a.hi * b.hi};
}
inline vfloat16 operator/(vfloat16 a, vfloat16 b) {
  return {a.lo / b.lo, a.hi / b.hi};
}
inline vfloat16 sqrt(vfloat16 a) {
  return {sqrt(a.lo), sqrt(a.hi)};
}
inline vfloat16 min(vfloat16 a, vfloat16 b) {
  return {min(a.lo, b.lo), min(a.hi, b.hi)};
}
inline vfloat16 max(vfloat16 a, vfloat16 b) {
  return {max(a.lo, b.lo), max(a.hi, b.hi)};
}
inline vfloat16 operator&(vfloat16 a, vfloat16 b) {
  return {a.lo & b.lo, a.hi & b.hi};
}
inline vfloat16 operator|(vfloat16 a, vfloat16 b) {
  return {a.lo | b.lo, a.hi | b.hi};
}
inline vfloat16 operator^(vfloat16 a, vfloat16 b) {
  return {a.lo ^ b.lo, a.hi ^ b.hi};
}
inline vfloat16 operator-(vfloat16 a) {
  return {-a.lo, -a.hi};
}
inline vfloat16 signbits(vfloat16 a) {
  return {signbits(a.lo), signbits(a.hi)};
}
inline vfloat16 abs(vfloat16 a) {
  return {abs(a.lo), abs(a.hi)};
}

inline vboolf16 operator<(vfloat16 a, vfloat16 b) {
  return {a.lo < b.lo, a.hi < b.hi};
}
inline vboolf16 operator<=(vfloat16 a, vfloat16 b) {
  return {a.lo <= b.lo, a.hi <= b.hi};
}
inline vboolf16 operator>(vfloat16 a, vfloat16 b) {
  return {a.lo > b.lo, a.hi > b.hi};
}
inline vboolf16 operator>=(vfloat16 a, vfloat16 b) {
  return {a.lo >= b.lo, a.hi >= b.hi};
}
inline vboolf16 operator==(vfloat16 a, vfloat16 b) {
  return {a.lo == b.lo, a.hi == b.hi};
}
inline vboolf16 operator!=(vfloat16 a, vfloat16 b) {
  return {a.lo != b.lo, a.hi != b.hi};
}

inline vboolf16 operator&(vboolf16 a, vboolf16 b) {
  return {a.lo & b.lo, a.hi & b.hi};
}
inline vboolf16 operator|(vboolf16 a, vboolf16 b) {
  return {a.lo | b.lo, a.hi | b.hi};
}
inline unsigned movemask(vboolf16 m) {
  return movemask(m.lo) | movemask(m.hi) << 8;
}
inline vfloat16 select(vboolf16 m, vfloat16 a, vfloat16 b) {  // m ? a : b
  return {select(m.lo, a.lo, b.lo), select(m.hi, a.hi, b.hi)};
}
inline vfloat16 masked(vboolf16 m, vfloat16 a) {  // a in the lanes of m, +0 in the others
  return {masked(m.lo, a.lo), masked(m.hi, a.hi)};
}

// The largest lane of a, when no lane is NaN.
inline float reduce_max(vfloat16 a) {
  vfloat8 m = max(a.lo, a.hi);
  m = max(m, swap_lanes<4>(m));
  m = max(m, swap_lanes<2>(m));
  m = max(m, swap_lanes<1>(m));
  alignas(32) float x[8];
  store(x, m);
  return x[0];
}

struct vint16 {
  vint8 lo, hi;
  static vint16 splat(int32_t x) { return {vint8::splat(x), vint8::splat(x)}; }
  static vint16 load(const uint32_t* p) { return {vint8::load(p), vint8::load(p + 8)}; }
};

inline void store(uint32_t* p, vint16 a) {
  store(p, a.lo);
  store(p + 8, a.hi);
}
inline vboolf16 operator<(vint16 a, vint16 b) {  // signed
  return {a.lo < b.lo, a.hi < b.hi};
}
inline vint16 select(vboolf16 m, vint16 a, vint16 b) {  // m ? a : b
  return {select(m.lo, a.lo, b.lo), select(m.hi, a.hi, b.hi)};
}

}  // namespace
}  // namespace rvr::simd
