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

// The material terms of lanes [i, i + kLanes): the batch's one material, or each pixel's.
struct MaterialLanes {
  V3 diffuse, specular, base;
  VF shininess;
};
inline MaterialLanes material_lanes(const ShadeLanes& batch, int i) {
  const ShadeMaterial* m = batch.material;
  if (m)
    return {V3::splat(m->diffuse), V3::splat(m->specular), V3::splat(m->base), splat(m->shininess)};
  return {V3::load(batch.diffuse, i), V3::load(batch.specular, i), V3::load(batch.base, i),
          load(batch.shininess + i)};
}

// Light sample l at the lanes' points: its brdf and squared distance, and where it adds a term
// (add_light_samples skips a sample at distance 0 and one whose brdf is 0: 0 * inf could be
// NaN). Returns false, the rest unset, where no lane has the light at a distance above 0.
struct LightSampleLanes {
  M lit;
  V3 brdf;
  VF dist2;
};
inline bool light_sample(const MaterialLanes& m, const V3& P, const V3& N, const V3& V,
                         const ShadeLights& lights, int l, LightSampleLanes& out) {
  const VF zero = splat(0.0f);
  const V3 to_light = V3::splat(column(lights.position, l)) - P;
  const VF dist2 = length_squared(to_light);
  const M far = dist2 > zero;  // !(dist2 > 0): the sample adds nothing
  if (movemask(far) == 0) return false;
  const V3 Ld = to_light / sqrt(dist2);
  const VF n_dot_l = clamp0(dot(N, Ld));
  const V3 H = normalize(Ld + V);
  const VF n_dot_h = clamp0(dot(N, H));
  const VF power = specular_power(n_dot_h, m.shininess);
  out.brdf = m.diffuse * n_dot_l + m.specular * power;
  out.lit = far & (((out.brdf.x != zero) | (out.brdf.y != zero)) | (out.brdf.z != zero));
  out.dist2 = dist2;
  return true;
}

// shade_local from the base colour on: each light sample in order, vis * brdf * I / dist2 with
// vis from `visibility` (null: 1, and 1 * brdf is brdf, bit for bit).
V3 add_lights(const ShadeLanes& batch, int i, const V3& P, const V3& N, const V3& V,
              const ShadeLights& lights, const LightVisibility* visibility) {
  const MaterialLanes m = material_lanes(batch, i);
  V3 colour = m.base;
  for (int l = 0; l < lights.count; ++l) {
    LightSampleLanes sample;
    if (!light_sample(m, P, N, V, lights, l, sample)) continue;
    const V3 intensity = V3::splat(column(lights.intensity, l));
    const V3 brdf = visibility ? sample.brdf * load(visibility->vis[l] + i) : sample.brdf;
    const V3 term = (brdf * intensity) / sample.dist2;
    colour = select(sample.lit, colour + term, colour);
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
    store(batch.colour, i, add_lights(batch, i, P, N, V, lights, nullptr));
  }
}

// TraceGeometry::surface at lanes [i, i + kLanes): P = o + t d, then the triangle's normals;
// the shading normal facing the viewer V = -normalize(d).
struct SurfaceLanes {
  V3 P, N, V;
};
inline SurfaceLanes surface_lanes(const SurfaceBatch& batch, const V3& origin, int i) {
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
  const V3 V = -normalize(direction);
  return {P, face_viewer(shading, geometric, V), V};
}

void shade_surfaces(SurfaceBatch& batch, const ShadeLights& lights,
                    const LightVisibility* visibility) {
  const V3 origin = V3::splat(batch.origin);
  for (int i = 0; i < batch.count; i += kLanes) {
    const SurfaceLanes s = surface_lanes(batch, origin, i);
    store(batch.shading_normal, i, s.N);
    store(batch.colour, i, add_lights(batch, i, s.P, s.N, s.V, lights, visibility));
  }
}

void light_needs(SurfaceBatch& batch, const ShadeLights& lights, LightNeeds& needs) {
  static_assert(64 % kLanes == 0 && 2 * 64 == kShadeBatch, "a group's bits lie in one word");
  for (int l = 0; l < lights.count; ++l) needs.bits[l][0] = needs.bits[l][1] = 0;
  const V3 origin = V3::splat(batch.origin);
  for (int i = 0; i < batch.count; i += kLanes) {
    const SurfaceLanes s = surface_lanes(batch, origin, i);
    store(batch.position, i, s.P);
    store(batch.shading_normal, i, s.N);
    const MaterialLanes m = material_lanes(batch, i);
    for (int l = 0; l < lights.count; ++l) {
      LightSampleLanes sample;
      if (!light_sample(m, s.P, s.N, s.V, lights, l, sample)) continue;
      needs.bits[l][i / 64] |= uint64_t(movemask(sample.lit)) << (i % 64);
    }
  }
}

}  // namespace
}  // namespace RVR_KERNEL_NS
}  // namespace rvr
