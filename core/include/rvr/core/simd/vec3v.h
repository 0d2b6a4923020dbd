// Three-vectors of SIMD vectors (as Embree's Vec3vf<M>): lane k of a Vec3v<vfloat8> is the
// 3-vector (x[k], y[k], z[k]), so a kernel writes its geometry as vector algebra, P =
// cross(D, E2), det = dot(E1, P), over 4, 8 or 16 lanes at once. One definition for every
// vector type of the SIMD layer, and for float itself (Vec3v<float>: one scalar 3-vector, for
// values a kernel shares between its lanes before splatting them).
//
// Each function is the scalar operation of glm's vec3 with its rounding and operand order,
// lane by lane, so results are bit for bit those of the scalar code the kernels mirror
// (shading.h, intersect_triangle_mt):
//   dot(a, b)   = (a.x * b.x + a.y * b.y) + a.z * b.z
//   cross(a, b) = (a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y)
//   normalize   = v * (1 / sqrt(dot(v, v)))
//   a * s, a / s: each component times (divided by) s, the component first
// A sum's association and a difference's order change the bits; a product's operand order
// cannot, but follows glm all the same. Nothing here fuses a multiply and an add (the kernel
// units build with -ffp-contract=off), so the bits are the same in every ISA.
//
// Only kernel translation units (which define RVR_KERNEL_NS) may include this; like the rest of
// the layer it has internal linkage (see simd.h).
#pragma once

#include <cstddef>

#include "rvr/core/simd/simd.h"

namespace rvr::simd {
namespace {

template <class V>
struct Vec3v {
  V x, y, z;

  static Vec3v splat(float x, float y, float z) { return {V::splat(x), V::splat(y), V::splat(z)}; }
  static Vec3v splat(const float (&p)[3]) { return splat(p[0], p[1], p[2]); }
  static Vec3v splat(const Vec3v<float>& p) { return splat(p.x, p.y, p.z); }
  // Lanes [i, i + lanes) of three rows of a structure of arrays (aligned).
  template <std::size_t N>
  static Vec3v load(const float (&rows)[3][N], int i = 0) {
    return {V::load(rows[0] + i), V::load(rows[1] + i), V::load(rows[2] + i)};
  }

  // Component `axis` (0, 1, 2), for loops over the axes.
  V& operator[](int axis) { return axis == 0 ? x : (axis == 1 ? y : z); }
  const V& operator[](int axis) const { return axis == 0 ? x : (axis == 1 ? y : z); }
};

// Entry j of each of three rows: one column of a structure of arrays.
template <std::size_t N>
inline Vec3v<float> column(const float (&rows)[3][N], int j) {
  return {rows[0][j], rows[1][j], rows[2][j]};
}
inline Vec3v<float> column(const float* const (&rows)[3], int j) {
  return {rows[0][j], rows[1][j], rows[2][j]};
}

template <std::size_t N, class V>
inline void store(float (&rows)[3][N], int i, const Vec3v<V>& a) {
  store(rows[0] + i, a.x);
  store(rows[1] + i, a.y);
  store(rows[2] + i, a.z);
}

template <class V>
inline Vec3v<V> operator+(const Vec3v<V>& a, const Vec3v<V>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class V>
inline Vec3v<V> operator-(const Vec3v<V>& a, const Vec3v<V>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
// The sign bits flipped (exact).
template <class V>
inline Vec3v<V> operator-(const Vec3v<V>& a) {
  return {-a.x, -a.y, -a.z};
}
// Component by component.
template <class V>
inline Vec3v<V> operator*(const Vec3v<V>& a, const Vec3v<V>& b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
template <class V>
inline Vec3v<V> operator*(const Vec3v<V>& a, V s) {
  return {a.x * s, a.y * s, a.z * s};
}
// Three divisions, as glm's vec3 / scalar (no reciprocal).
template <class V>
inline Vec3v<V> operator/(const Vec3v<V>& a, V s) {
  return {a.x / s, a.y / s, a.z / s};
}

template <class V>
inline V dot(const Vec3v<V>& a, const Vec3v<V>& b) {
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}
template <class V>
inline V length_squared(const Vec3v<V>& a) {
  return dot(a, a);
}
template <class V>
inline Vec3v<V> cross(const Vec3v<V>& a, const Vec3v<V>& b) {
  return {a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y};
}
template <class V>
inline Vec3v<V> normalize(const Vec3v<V>& a) {
  return a * (V::splat(1.0f) / sqrt(length_squared(a)));
}

// m ? a : b, lane by lane.
template <class M, class V>
inline Vec3v<V> select(M m, const Vec3v<V>& a, const Vec3v<V>& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}

using Vec3vf4 = Vec3v<vfloat4>;
using Vec3vf8 = Vec3v<vfloat8>;
using Vec3vfx = Vec3v<vfloatx>;  // the native width

}  // namespace
}  // namespace rvr::simd
