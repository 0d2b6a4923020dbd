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
#include "rvr/core/simd/vec3v.h"

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

using V3 = Vec3vfx;
// b.x * c0 + b.y * c1 + b.z * c2, as glm evaluates the vec3 expression.
inline V3 interpolate(const VF (&b)[3], const float (&c)[3][3][kShadeBatch], int i) {
  return (V3::load(c[0], i) * b[0] + V3::load(c[1], i) * b[1]) + V3::load(c[2], i) * b[2];
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
  const V3 diffuse = m ? V3::splat(m->diffuse) : V3::load(batch.diffuse, i);
  const V3 specular = m ? V3::splat(m->specular) : V3::load(batch.specular, i);
  const VF shininess = m ? splat(m->shininess) : load(batch.shininess + i);
  V3 colour = m ? V3::splat(m->base) : V3::load(batch.base, i);
  for (int l = 0; l < lights.count; ++l) {
    const V3 position = V3::splat(column(lights.position, l));
    const V3 intensity = V3::splat(column(lights.intensity, l));
    const V3 to_light = position - P;
    const VF dist2 = length_squared(to_light);
    M lit = dist2 > zero;  // !(dist2 > 0): the sample adds nothing
    if (movemask(lit) == 0) continue;
    const V3 Ld = to_light / sqrt(dist2);
    const VF n_dot_l = clamp0(dot(N, Ld));
    const V3 H = normalize(Ld + V);
    const VF n_dot_h = clamp0(dot(N, H));
    const VF power = specular_power(n_dot_h, shininess);
    const V3 brdf = diffuse * n_dot_l + specular * power;
    // brdf == vec3(0) skips the sample (its term could be NaN: 0 * inf).
    lit = lit & (((brdf.x != zero) | (brdf.y != zero)) | (brdf.z != zero));
    // vis * brdf * I / dist2 with vis = 1: 1 * brdf is brdf, bit for bit.
    const V3 term = (brdf * intensity) / dist2;
    colour = select(lit, colour + term, colour);
  }
  return colour;
}

// face_viewer: dot(geometric, V) < 0 turns the shading normal.
inline V3 face_viewer(const V3& shading, const V3& geometric, const V3& V) {
  const M back = dot(geometric, V) < splat(0.0f);
  return select(back, -shading, shading);
}

void shade(ShadeBatch& batch, const float eye_position[3], const ShadeLights& lights) {
  const V3 eye = V3::splat(eye_position[0], eye_position[1], eye_position[2]);
  for (int i = 0; i < batch.count; i += kLanes) {
    // surface_at (soft_rasterizer.cpp): position, geometric and shading normals, viewer.
    const VF b[3] = {load(batch.bary[0] + i), load(batch.bary[1] + i), load(batch.bary[2] + i)};
    const V3 P = interpolate(b, batch.vertex, i);
    const V3 p0 = V3::load(batch.vertex[0], i);
    const V3 geometric =
        normalize(cross(V3::load(batch.vertex[1], i) - p0, V3::load(batch.vertex[2], i) - p0));
    // Flat lanes take the geometric normal whatever their vertex normals hold: a group with no
    // smooth lane skips the interpolation (the selection would discard it).
    const M smooth = M::load(batch.smooth + i);
    const V3 shading = movemask(smooth) == 0
                           ? geometric
                           : select(smooth, normalize(interpolate(b, batch.normal, i)), geometric);
    const V3 V = normalize(eye - P);
    const V3 N = face_viewer(shading, geometric, V);
    store(batch.shading_normal, i, N);
    store(batch.colour, i, add_lights(batch, i, P, N, V, lights));
  }
}

void shade_surfaces(SurfaceBatch& batch, const ShadeLights& lights) {
  const V3 origin = V3::splat(batch.origin);
  for (int i = 0; i < batch.count; i += kLanes) {
    // TraceGeometry::surface: P = o + t d, then the triangle's normals.
    const V3 direction = V3::load(batch.direction, i);
    const V3 P = origin + direction * load(batch.t + i);
    const M given = M::load(batch.given + i);
    const M smooth = M::load(batch.smooth + i);
    V3 geometric = V3::load(batch.geometric, i), shading = V3::load(batch.shading, i);
    if (movemask(given) != kAllLanes) {
      const V3 triangle = normalize(cross(V3::load(batch.edge1, i), V3::load(batch.edge2, i)));
      V3 interpolated = triangle;
      if (movemask(smooth) != 0) {
        const VF u = load(batch.u + i), v = load(batch.v + i);
        const VF w[3] = {splat(1.0f) - u - v, u, v};
        const V3 n = interpolate(w, batch.vertex_normal, i);
        const VF length = sqrt(length_squared(n));
        interpolated = select(smooth & (length > splat(0.0f)), n / length, triangle);
      }
      geometric = select(given, geometric, triangle);
      shading = select(given, shading, interpolated);
    }
    // -normalize(direction): the negation is exact.
    const V3 unit = normalize(direction);
    const V3 V = -unit;
    const V3 N = face_viewer(shading, geometric, V);
    store(batch.shading_normal, i, N);
    store(batch.colour, i, add_lights(batch, i, P, N, V, lights));
  }
}

}  // namespace
}  // namespace RVR_KERNEL_NS
}  // namespace rvr
