// The shading kernels for one instruction set; included once per kernel translation unit,
// which defines RVR_KERNEL_NS. Lane k shades pixel k of a group with the float operations
// of shade_local (core/include/rvr/core/shading.h) and of the glm functions it calls
// (dot = (x*x' + y*y') + z*z', normalize = v * (1 / sqrt(dot(v, v))), cross), in their order;
// sqrt and division round as their scalar forms do and these units build with
// -ffp-contract=off, so the bits do not depend on the kernel.
#include <math.h>

#include <cstdint>

#include "rvr/core/shade_kernel.h"

#ifndef RVR_KERNEL_NS
#error "define RVR_KERNEL_NS before including this file"
#endif

#include "rvr/core/simd/simd.h"

namespace rvr {
namespace RVR_KERNEL_NS {
namespace {

using namespace simd;
using VF = vfloatx;
using M = vboolfx;
constexpr int kLanes = kFloatLanes;

inline VF splat(float x) {
  return VF::splat(x);
}
inline VF load(const float* p) {
  return VF::load(p);
}
// max(v, 0) = v > 0 ? v : +0, as std::max(0.0f, v) (NaN and -0 give +0).
inline VF clamp0(VF v) {
  return max(v, VF::zero());
}

// movemask() of a mask with every lane set.
constexpr unsigned kAllLanes = (1u << kLanes) - 1u;

struct V3 {
  VF x, y, z;
};
inline V3 load3(const float (&p)[3][kShadeBatch], int i) {
  return {load(p[0] + i), load(p[1] + i), load(p[2] + i)};
}
inline V3 splat3(const float (&p)[3]) {
  return {splat(p[0]), splat(p[1]), splat(p[2])};
}
inline void store3(float (&p)[3][kShadeBatch], int i, const V3& v) {
  store(p[0] + i, v.x);
  store(p[1] + i, v.y);
  store(p[2] + i, v.z);
}
inline V3 add3(const V3& a, const V3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline V3 sub3(const V3& a, const V3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline V3 mul3(const V3& a, const V3& b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
inline V3 scale(const V3& a, VF s) {
  return {a.x * s, a.y * s, a.z * s};
}
// glm's vec3 / scalar divides each component (no reciprocal).
inline V3 divide3(const V3& a, VF s) {
  return {a.x / s, a.y / s, a.z / s};
}
inline VF dot(const V3& a, const V3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y};
}
inline V3 normalize(const V3& v) {
  return scale(v, splat(1.0f) / sqrt(dot(v, v)));
}
inline V3 select3(M m, const V3& a, const V3& b) {
  return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}
// b.x * c0 + b.y * c1 + b.z * c2, as glm evaluates the vec3 expression.
inline V3 interpolate(const VF (&b)[3], const float (&c)[3][3][kShadeBatch], int i) {
  V3 c0 = load3(c[0], i), c1 = load3(c[1], i), c2 = load3(c[2], i);
  return add3(add3(scale(c0, b[0]), scale(c1, b[1])), scale(c2, b[2]));
}

// specular_power (shading.h) lane by lane: the C library's powf, as the scalar code calls it.
inline VF specular_power(VF x, VF s) {
  alignas(64) float xs[kLanes], ss[kLanes], r[kLanes];
  store(xs, x);
  store(ss, s);
  for (int k = 0; k < kLanes; ++k)
    r[k] = xs[k] <= 0.0f ? (ss[k] == 0.0f ? 1.0f : 0.0f) : powf(xs[k], ss[k]);
  return load(r);
}

// shade_local from the base colour on: each light sample in order.
V3 add_lights(const ShadeLanes& batch, int i, const V3& P, const V3& N, const V3& V,
              const ShadeLights& lights) {
  const VF zero = splat(0.0f);
  const ShadeMaterial* m = batch.material;
  const V3 diffuse = m ? splat3(m->diffuse) : load3(batch.diffuse, i);
  const V3 specular = m ? splat3(m->specular) : load3(batch.specular, i);
  const VF shininess = m ? splat(m->shininess) : load(batch.shininess + i);
  V3 colour = m ? splat3(m->base) : load3(batch.base, i);
  for (int l = 0; l < lights.count; ++l) {
    const V3 position = {splat(lights.position[0][l]), splat(lights.position[1][l]),
                         splat(lights.position[2][l])};
    const V3 intensity = {splat(lights.intensity[0][l]), splat(lights.intensity[1][l]),
                          splat(lights.intensity[2][l])};
    const V3 to_light = sub3(position, P);
    const VF dist2 = dot(to_light, to_light);
    M lit = dist2 > zero;  // !(dist2 > 0): the sample adds nothing
    if (movemask(lit) == 0) continue;
    const V3 Ld = divide3(to_light, sqrt(dist2));
    const VF n_dot_l = clamp0(dot(N, Ld));
    const V3 H = normalize(add3(Ld, V));
    const VF n_dot_h = clamp0(dot(N, H));
    const VF power = specular_power(n_dot_h, shininess);
    const V3 brdf = add3(scale(diffuse, n_dot_l), scale(specular, power));
    // brdf == vec3(0) skips the sample (its term could be NaN: 0 * inf).
    lit = lit & (((brdf.x != zero) | (brdf.y != zero)) | (brdf.z != zero));
    // vis * brdf * I / dist2 with vis = 1: 1 * brdf is brdf, bit for bit.
    const V3 term = divide3(mul3(brdf, intensity), dist2);
    colour = select3(lit, add3(colour, term), colour);
  }
  return colour;
}

// face_viewer: dot(geometric, V) < 0 turns the shading normal.
inline V3 face_viewer(const V3& shading, const V3& geometric, const V3& V) {
  const M back = dot(geometric, V) < splat(0.0f);
  return select3(back, {-shading.x, -shading.y, -shading.z}, shading);
}

void shade(ShadeBatch& batch, const float eye_position[3], const ShadeLights& lights) {
  const V3 eye = {splat(eye_position[0]), splat(eye_position[1]), splat(eye_position[2])};
  for (int i = 0; i < batch.count; i += kLanes) {
    // surface_at (soft_rasterizer.cpp): position, geometric and shading normals, viewer.
    const VF b[3] = {load(batch.bary[0] + i), load(batch.bary[1] + i), load(batch.bary[2] + i)};
    const V3 P = interpolate(b, batch.vertex, i);
    const V3 p0 = load3(batch.vertex[0], i);
    const V3 geometric =
        normalize(cross(sub3(load3(batch.vertex[1], i), p0), sub3(load3(batch.vertex[2], i), p0)));
    // Flat lanes take the geometric normal whatever their vertex normals hold: a group with no
    // smooth lane skips the interpolation (the selection would discard it).
    const M smooth = M::load(batch.smooth + i);
    const V3 shading = movemask(smooth) == 0
                           ? geometric
                           : select3(smooth, normalize(interpolate(b, batch.normal, i)), geometric);
    const V3 V = normalize(sub3(eye, P));
    const V3 N = face_viewer(shading, geometric, V);
    store3(batch.shading_normal, i, N);
    store3(batch.colour, i, add_lights(batch, i, P, N, V, lights));
  }
}

void shade_surfaces(SurfaceBatch& batch, const ShadeLights& lights) {
  const V3 origin = splat3(batch.origin);
  for (int i = 0; i < batch.count; i += kLanes) {
    // TraceGeometry::surface: P = o + t d, then the triangle's normals.
    const V3 direction = load3(batch.direction, i);
    const V3 P = add3(origin, scale(direction, load(batch.t + i)));
    const M given = M::load(batch.given + i);
    const M smooth = M::load(batch.smooth + i);
    V3 geometric = load3(batch.geometric, i), shading = load3(batch.shading, i);
    if (movemask(given) != kAllLanes) {
      const V3 triangle = normalize(cross(load3(batch.edge1, i), load3(batch.edge2, i)));
      V3 interpolated = triangle;
      if (movemask(smooth) != 0) {
        const VF u = load(batch.u + i), v = load(batch.v + i);
        const VF w[3] = {splat(1.0f) - u - v, u, v};
        const V3 n = interpolate(w, batch.vertex_normal, i);
        const VF length = sqrt(dot(n, n));
        interpolated = select3(smooth & (length > splat(0.0f)), divide3(n, length), triangle);
      }
      geometric = select3(given, geometric, triangle);
      shading = select3(given, shading, interpolated);
    }
    // -normalize(direction): the negation is exact.
    const V3 unit = normalize(direction);
    const V3 V = {-unit.x, -unit.y, -unit.z};
    const V3 N = face_viewer(shading, geometric, V);
    store3(batch.shading_normal, i, N);
    store3(batch.colour, i, add_lights(batch, i, P, N, V, lights));
  }
}

}  // namespace
}  // namespace RVR_KERNEL_NS
}  // namespace rvr
