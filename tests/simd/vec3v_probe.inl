// The Vec3v probe for one instruction set (vec3v_probe.h); included once per unit, which
// defines RVR_KERNEL_NS and RVR_KERNEL_NAME.
#include <type_traits>

#include "simd/vec3v_probe.h"

#ifndef RVR_KERNEL_NS
#error "define RVR_KERNEL_NS before including this file"
#endif

#include "rvr/core/simd/simd.h"
#include "rvr/core/simd/vec3v.h"

namespace rvr {
namespace RVR_KERNEL_NS {
namespace {

using namespace simd;

// Lanes [i, i + lanes of V) of the probe's rows; float, which has no load or store, one lane.
template <class V>
Vec3v<V> load3(const float (&rows)[3][kProbeLanes], int i) {
  if constexpr (std::is_same_v<V, float>)
    return column(rows, i);
  else
    return Vec3v<V>::load(rows, i);
}
template <class V>
V load1(const float (&row)[kProbeLanes], int i) {
  if constexpr (std::is_same_v<V, float>)
    return row[i];
  else
    return V::load(row + i);
}
template <class V>
void store3(float (&rows)[3][kProbeLanes], int i, const Vec3v<V>& a) {
  if constexpr (std::is_same_v<V, float>) {
    rows[0][i] = a.x;
    rows[1][i] = a.y;
    rows[2][i] = a.z;
  } else {
    store(rows, i, a);
  }
}
template <class V>
void store1(float (&row)[kProbeLanes], int i, V a) {
  if constexpr (std::is_same_v<V, float>)
    row[i] = a;
  else
    store(row + i, a);
}

// The int vector of V's width.
template <class V>
struct IntOf;
template <>
struct IntOf<vfloat4> {
  using type = vint4;
};
template <>
struct IntOf<vfloat8> {
  using type = vint8;
};
template <>
struct IntOf<vfloat16> {
  using type = vint16;
};

template <class V>
void run_ints(const Vec3vProbeInput& in, Vec3vProbeOutput& out) {
  using I = typename IntOf<V>::type;
  constexpr int kLanes = int(sizeof(V) / sizeof(float));
  out.below_bits = 0;
  for (int k = 0; k < kProbeLanes; k += kLanes) {
    const I i = I::loadu(in.i + k), j = I::loadu(in.j + k);
    out.below_bits |= movemask(less_unsigned(i, j)) << k;
    const auto in_table = less_unsigned(i, I::splat(int32_t(kProbeTable)));
    storeu(out.gathered + k, gather(in.table, i, in_table) + i);
  }
}

template <class V>
void run_width(const Vec3vProbeInput& in, Vec3vProbeOutput& out) {
  constexpr int kLanes = int(sizeof(V) / sizeof(float));
  out.less_bits = 0;
  for (int i = 0; i < kProbeLanes; i += kLanes) {
    const Vec3v<V> a = load3<V>(in.a, i), b = load3<V>(in.b, i);
    const V s = load1<V>(in.s, i);
    store3(out.sum, i, a + b);
    store3(out.difference, i, a - b);
    store3(out.negated, i, -a);
    store3(out.product, i, a * b);
    store3(out.scaled, i, a * s);
    store3(out.quotient, i, a / s);
    store3(out.cross, i, cross(a, b));
    if constexpr (!std::is_same_v<V, float>) {  // vector operations only
      store3(out.normalized, i, normalize(a));
      store3(out.selected, i, select(a.x < b.x, a, b));
      using M = decltype(a.x < b.x);
      const unsigned less = movemask(a.x < b.x);
      out.less_bits |= less << i;
      store(out.abs_x + i, abs(a.x));
      store(out.sign_flipped_x + i, a.x ^ signbits(b.x));
      store(out.masked_x + i, masked(M::from_bits(less), a.x));
    }
    if constexpr (std::is_same_v<V, vfloat16>) out.max_x = reduce_max(a.x);
    if constexpr (!std::is_same_v<V, float>) {
      if (i == 0) run_ints<V>(in, out);
    }
    store1(out.dot, i, dot(a, b));
    store1(out.length_squared, i, length_squared(a));
  }
}

void run(ProbeWidth width, const Vec3vProbeInput& in, Vec3vProbeOutput& out) {
  switch (width) {
    case ProbeWidth::Scalar:
      return run_width<float>(in, out);
    case ProbeWidth::Four:
      return run_width<vfloat4>(in, out);
    case ProbeWidth::Eight:
      return run_width<vfloat8>(in, out);
    case ProbeWidth::Sixteen:
      return run_width<vfloat16>(in, out);
    case ProbeWidth::Native:
      return run_width<vfloatx>(in, out);
  }
}

}  // namespace

extern const Vec3vProbe kVec3vProbe = {RVR_KERNEL_NAME, run};

}  // namespace RVR_KERNEL_NS
}  // namespace rvr
