// Vectors of twice a layer's width as two halves (lanes [0, n) and [n, 2n) of a vector of n
// lanes), with the operations and the lane order of the native vectors of that width, so a kernel
// written for a width compiles for every ISA and does the same operations in each:
//   SSE units:  vfloat8, vboolf8, vint8 as two 4-lane halves; vfloat16, vboolf16, vint16 as two
//               of those;
//   AVX2 units: vfloat16, vboolf16, vint16 as two native 8-lane halves.
// AVX-512 units have native 8- and 16-lane vectors and do not include this. Included through
// rvr/core/simd/simd.h only; see there for the rules.
#pragma once

#include <cstdint>

#include "rvr/core/simd/simd_sse.h"

#if defined(__AVX512F__)
#error "simd_halves.h is for SSE and AVX2 units; AVX-512 ones have native 8- and 16-lane vectors"
#endif
#if defined(__AVX2__)
#include "rvr/core/simd/simd_avx2.h"
#endif

namespace rvr::simd {
namespace {

template <class B>
struct vbool_halves {
  B lo, hi;
  static constexpr int kHalf = int(sizeof(B) / sizeof(float));  // lanes of a half
  static vbool_halves from_bits(unsigned m) {                   // lane k set when bit k of m is
    constexpr unsigned half_mask = (1u << kHalf) - 1u;
    return {B::from_bits(m & half_mask), B::from_bits((m >> kHalf) & half_mask)};
  }
};

template <class F>
struct vfloat_halves {
  F lo, hi;
  static constexpr int kHalf = int(sizeof(F) / sizeof(float));
  static vfloat_halves load(const float* p) { return {F::load(p), F::load(p + kHalf)}; }
  static vfloat_halves loadu(const float* p) { return {F::loadu(p), F::loadu(p + kHalf)}; }
  static vfloat_halves splat(float x) { return {F::splat(x), F::splat(x)}; }
  static vfloat_halves zero() { return {F::zero(), F::zero()}; }
};

template <class I>
struct vint_halves {
  I lo, hi;
  static constexpr int kHalf = int(sizeof(I) / sizeof(int32_t));
  static vint_halves splat(int32_t x) { return {I::splat(x), I::splat(x)}; }
  static vint_halves load(const uint32_t* p) { return {I::load(p), I::load(p + kHalf)}; }
};

#if defined(__AVX2__)
using vboolf16 = vbool_halves<vboolf8>;
using vfloat16 = vfloat_halves<vfloat8>;
using vint16 = vint_halves<vint8>;
#else
using vboolf8 = vbool_halves<vboolf4>;
using vfloat8 = vfloat_halves<vfloat4>;
using vint8 = vint_halves<vint4>;
using vboolf16 = vbool_halves<vboolf8>;
using vfloat16 = vfloat_halves<vfloat8>;
using vint16 = vint_halves<vint8>;
#endif

// The mask type of two halves of F.
template <class F>
using mask_of = vbool_halves<decltype(F{} < F{})>;

template <class F>
inline void store(float* p, vfloat_halves<F> a) {
  store(p, a.lo);
  store(p + vfloat_halves<F>::kHalf, a.hi);
}
template <class F>
inline void storeu(float* p, vfloat_halves<F> a) {
  storeu(p, a.lo);
  storeu(p + vfloat_halves<F>::kHalf, a.hi);
}

template <class F>
inline vfloat_halves<F> operator+(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo + b.lo, a.hi + b.hi};
}
template <class F>
inline vfloat_halves<F> operator-(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo - b.lo, a.hi - b.hi};
}
template <class F>
inline vfloat_halves<F> operator*(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo * b.lo, a.hi * b.hi};
}
template <class F>
inline vfloat_halves<F> operator/(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo / b.lo, a.hi / b.hi};
}
template <class F>
inline vfloat_halves<F> sqrt(vfloat_halves<F> a) {
  return {sqrt(a.lo), sqrt(a.hi)};
}
template <class F>
inline vfloat_halves<F> min(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {min(a.lo, b.lo), min(a.hi, b.hi)};
}
template <class F>
inline vfloat_halves<F> max(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {max(a.lo, b.lo), max(a.hi, b.hi)};
}
template <class F>
inline vfloat_halves<F> operator&(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo & b.lo, a.hi & b.hi};
}
template <class F>
inline vfloat_halves<F> operator|(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo | b.lo, a.hi | b.hi};
}
template <class F>
inline vfloat_halves<F> operator^(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo ^ b.lo, a.hi ^ b.hi};
}
template <class F>
inline vfloat_halves<F> andnot(vfloat_halves<F> a, vfloat_halves<F> b) {  // ~a & b
  return {andnot(a.lo, b.lo), andnot(a.hi, b.hi)};
}
template <class F>
inline vfloat_halves<F> operator-(vfloat_halves<F> a) {
  return {-a.lo, -a.hi};
}
template <class F>
inline vfloat_halves<F> signbits(vfloat_halves<F> a) {
  return {signbits(a.lo), signbits(a.hi)};
}
template <class F>
inline vfloat_halves<F> abs(vfloat_halves<F> a) {
  return {abs(a.lo), abs(a.hi)};
}

template <class F>
inline mask_of<F> operator<(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo < b.lo, a.hi < b.hi};
}
template <class F>
inline mask_of<F> operator<=(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo <= b.lo, a.hi <= b.hi};
}
template <class F>
inline mask_of<F> operator>(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo > b.lo, a.hi > b.hi};
}
template <class F>
inline mask_of<F> operator>=(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo >= b.lo, a.hi >= b.hi};
}
template <class F>
inline mask_of<F> operator==(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo == b.lo, a.hi == b.hi};
}
template <class F>
inline mask_of<F> operator!=(vfloat_halves<F> a, vfloat_halves<F> b) {
  return {a.lo != b.lo, a.hi != b.hi};
}

template <class B>
inline vbool_halves<B> operator&(vbool_halves<B> a, vbool_halves<B> b) {
  return {a.lo & b.lo, a.hi & b.hi};
}
template <class B>
inline vbool_halves<B> operator|(vbool_halves<B> a, vbool_halves<B> b) {
  return {a.lo | b.lo, a.hi | b.hi};
}
template <class B>
inline unsigned movemask(vbool_halves<B> m) {
  return movemask(m.lo) | movemask(m.hi) << vbool_halves<B>::kHalf;
}
template <class F>
inline unsigned le_bits(vfloat_halves<F> a, vfloat_halves<F> b) {  // movemask(a <= b)
  return movemask(a <= b);
}
template <class B, class F>
inline vfloat_halves<F> select(vbool_halves<B> m, vfloat_halves<F> a, vfloat_halves<F> b) {
  return {select(m.lo, a.lo, b.lo), select(m.hi, a.hi, b.hi)};  // m ? a : b
}
template <class B>
inline vbool_halves<B> select(vbool_halves<B> m, vbool_halves<B> a, vbool_halves<B> b) {
  return {select(m.lo, a.lo, b.lo), select(m.hi, a.hi, b.hi)};
}
template <class B, class F>
inline vfloat_halves<F> masked(vbool_halves<B> m, vfloat_halves<F> a) {  // a in m, else +0
  return {masked(m.lo, a.lo), masked(m.hi, a.hi)};
}

// Lane k takes lane k ^ J (J a power of two below the width): the halves swap when J is a
// half's width, and each half swaps its own lanes below it.
template <int J, class F>
inline vfloat_halves<F> swap_lanes(vfloat_halves<F> a) {
  static_assert(J >= 1 && J <= vfloat_halves<F>::kHalf && (J & (J - 1)) == 0);
  if constexpr (J == vfloat_halves<F>::kHalf)
    return {a.hi, a.lo};
  else
    return {swap_lanes<J>(a.lo), swap_lanes<J>(a.hi)};
}
// The largest lane of a, when no lane is NaN.
template <class F>
inline float reduce_max(vfloat_halves<F> a) {
  return reduce_max(max(a.lo, a.hi));
}

template <class I>
inline void store(uint32_t* p, vint_halves<I> a) {
  store(p, a.lo);
  store(p + vint_halves<I>::kHalf, a.hi);
}
template <class I>
inline void storeu(uint32_t* p, vint_halves<I> a) {
  storeu(p, a.lo);
  storeu(p + vint_halves<I>::kHalf, a.hi);
}
template <class I>
inline vbool_halves<decltype(I{} < I{})> operator<(vint_halves<I> a, vint_halves<I> b) {
  return {a.lo < b.lo, a.hi < b.hi};  // signed
}
template <class B, class I>
inline vint_halves<I> select(vbool_halves<B> m, vint_halves<I> a, vint_halves<I> b) {
  return {select(m.lo, a.lo, b.lo), select(m.hi, a.hi, b.hi)};  // m ? a : b
}
template <int J, class I>
inline vint_halves<I> swap_lanes(vint_halves<I> a) {
  static_assert(J >= 1 && J <= vint_halves<I>::kHalf && (J & (J - 1)) == 0);
  if constexpr (J == vint_halves<I>::kHalf)
    return {a.hi, a.lo};
  else
    return {swap_lanes<J>(a.lo), swap_lanes<J>(a.hi)};
}

}  // namespace
}  // namespace rvr::simd
