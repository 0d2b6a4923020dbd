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

// Two halves of V: a float, mask or int vector of twice V's lanes. The operations below are
// templates over V, so each exists for the halves of the vectors that have it (arithmetic for
// floats, from_bits and movemask for masks, ...).
template <class V>
struct vhalves {
  V lo, hi;
  static constexpr int kHalf = int(sizeof(V) / sizeof(float));  // lanes of a half
  template <class T>
  static vhalves load(const T* p) {  // aligned as V::load needs
    return {V::load(p), V::load(p + kHalf)};
  }
  template <class T>
  static vhalves loadu(const T* p) {
    return {V::loadu(p), V::loadu(p + kHalf)};
  }
  template <class T>
  static vhalves splat(T x) {
    return {V::splat(x), V::splat(x)};
  }
  static vhalves zero() { return {V::zero(), V::zero()}; }
  static vhalves from_bits(unsigned m) {  // masks: lane k set when bit k of m is
    constexpr unsigned half_mask = (1u << kHalf) - 1u;
    return {V::from_bits(m & half_mask), V::from_bits((m >> kHalf) & half_mask)};
  }
};

#if defined(__AVX2__)
using vboolf16 = vhalves<vboolf8>;
using vfloat16 = vhalves<vfloat8>;
using vint16 = vhalves<vint8>;
#else
using vboolf8 = vhalves<vboolf4>;
using vfloat8 = vhalves<vfloat4>;
using vint8 = vhalves<vint4>;
using vboolf16 = vhalves<vboolf8>;
using vfloat16 = vhalves<vfloat8>;
using vint16 = vhalves<vint8>;
#endif

template <class T, class V>
inline void store(T* p, vhalves<V> a) {
  store(p, a.lo);
  store(p + vhalves<V>::kHalf, a.hi);
}
template <class T, class V>
inline void storeu(T* p, vhalves<V> a) {
  storeu(p, a.lo);
  storeu(p + vhalves<V>::kHalf, a.hi);
}

template <class V>
inline vhalves<V> operator+(vhalves<V> a, vhalves<V> b) {
  return {a.lo + b.lo, a.hi + b.hi};
}
template <class V>
inline vhalves<V> operator-(vhalves<V> a, vhalves<V> b) {
  return {a.lo - b.lo, a.hi - b.hi};
}
template <class V>
inline vhalves<V> operator*(vhalves<V> a, vhalves<V> b) {
  return {a.lo * b.lo, a.hi * b.hi};
}
template <class V>
inline vhalves<V> operator/(vhalves<V> a, vhalves<V> b) {
  return {a.lo / b.lo, a.hi / b.hi};
}
template <class V>
inline vhalves<V> sqrt(vhalves<V> a) {
  return {sqrt(a.lo), sqrt(a.hi)};
}
template <class V>
inline vhalves<V> min(vhalves<V> a, vhalves<V> b) {
  return {min(a.lo, b.lo), min(a.hi, b.hi)};
}
template <class V>
inline vhalves<V> max(vhalves<V> a, vhalves<V> b) {
  return {max(a.lo, b.lo), max(a.hi, b.hi)};
}
template <class V>
inline vhalves<V> operator&(vhalves<V> a, vhalves<V> b) {
  return {a.lo & b.lo, a.hi & b.hi};
}
template <class V>
inline vhalves<V> operator|(vhalves<V> a, vhalves<V> b) {
  return {a.lo | b.lo, a.hi | b.hi};
}
template <class V>
inline vhalves<V> operator^(vhalves<V> a, vhalves<V> b) {
  return {a.lo ^ b.lo, a.hi ^ b.hi};
}
template <class V>
inline vhalves<V> andnot(vhalves<V> a, vhalves<V> b) {  // ~a & b
  return {andnot(a.lo, b.lo), andnot(a.hi, b.hi)};
}
template <class V>
inline vhalves<V> operator-(vhalves<V> a) {
  return {-a.lo, -a.hi};
}
template <class V>
inline vhalves<V> signbits(vhalves<V> a) {
  return {signbits(a.lo), signbits(a.hi)};
}
template <class V>
inline vhalves<V> abs(vhalves<V> a) {
  return {abs(a.lo), abs(a.hi)};
}

// Comparisons give the halves of the half's mask type (signed for ints).
template <class V>
using mask_of = vhalves<decltype(V{} < V{})>;
template <class V>
inline mask_of<V> operator<(vhalves<V> a, vhalves<V> b) {
  return {a.lo < b.lo, a.hi < b.hi};
}
template <class V>
inline mask_of<V> operator<=(vhalves<V> a, vhalves<V> b) {
  return {a.lo <= b.lo, a.hi <= b.hi};
}
template <class V>
inline mask_of<V> operator>(vhalves<V> a, vhalves<V> b) {
  return {a.lo > b.lo, a.hi > b.hi};
}
template <class V>
inline mask_of<V> operator>=(vhalves<V> a, vhalves<V> b) {
  return {a.lo >= b.lo, a.hi >= b.hi};
}
template <class V>
inline mask_of<V> operator==(vhalves<V> a, vhalves<V> b) {
  return {a.lo == b.lo, a.hi == b.hi};
}
template <class V>
inline mask_of<V> operator!=(vhalves<V> a, vhalves<V> b) {
  return {a.lo != b.lo, a.hi != b.hi};
}

template <class V>
inline auto less_unsigned(vhalves<V> a, vhalves<V> b) {  // ints
  return vhalves<decltype(less_unsigned(a.lo, b.lo))>{less_unsigned(a.lo, b.lo),
                                                      less_unsigned(a.hi, b.hi)};
}
template <class V, class B>
inline vhalves<V> gather(const uint32_t* base, vhalves<V> index, vhalves<B> m) {
  return {gather(base, index.lo, m.lo), gather(base, index.hi, m.hi)};
}

template <class B>
inline unsigned movemask(vhalves<B> m) {
  return movemask(m.lo) | movemask(m.hi) << vhalves<B>::kHalf;
}
template <class V>
inline unsigned le_bits(vhalves<V> a, vhalves<V> b) {  // movemask(a <= b)
  return movemask(a <= b);
}
template <class B, class V>
inline vhalves<V> select(vhalves<B> m, vhalves<V> a, vhalves<V> b) {  // m ? a : b
  return {select(m.lo, a.lo, b.lo), select(m.hi, a.hi, b.hi)};
}
template <class B, class V>
inline vhalves<V> masked(vhalves<B> m, vhalves<V> a) {  // a in the lanes of m, +0 in the others
  return {masked(m.lo, a.lo), masked(m.hi, a.hi)};
}

// Lane k takes lane k ^ J (J a power of two below the width): the halves swap when J is a
// half's width, and each half swaps its own lanes below it.
template <int J, class V>
inline vhalves<V> swap_lanes(vhalves<V> a) {
  static_assert(J >= 1 && J <= vhalves<V>::kHalf && (J & (J - 1)) == 0);
  if constexpr (J == vhalves<V>::kHalf)
    return {a.hi, a.lo};
  else
    return {swap_lanes<J>(a.lo), swap_lanes<J>(a.hi)};
}
// The largest lane of a, when no lane is NaN.
template <class V>
inline float reduce_max(vhalves<V> a) {
  return reduce_max(max(a.lo, a.hi));
}

}  // namespace
}  // namespace rvr::simd
