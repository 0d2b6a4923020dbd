// The local term of docs/design.md's shading equation as SIMD kernels, shared by every loop
// order: softraster's deferred pass shades its visible pixels with them, the tracer and the
// hybrid their primary hits. Compiled once per instruction set (core/src/kernels/shade_*.cpp)
// and chosen at run time like every kernel: 4 (SSE), 8 (AVX2) or 16 (AVX-512) pixels at once.
// Each lane does the float operations of rvr::shade_local and the glm calls it makes, in the
// same order (no FMA: -ffp-contract=off), and x^shininess with the C library's powf, so every
// kernel, and the scalar shade_local, give the same bits. Plain data only: a kernel translation
// unit must not instantiate inline code that baseline code also uses.
#pragma once

#include <cstdint>

#include "rvr/core/isa.h"

namespace rvr {

// Lanes of the widest kernel: batches are padded to a multiple of it.
constexpr int kShadeMaxLanes = 16;

// The material terms the kernel reads, of one object.
struct ShadeMaterial {
  float diffuse[3], specular[3], base[3];  // base: shade_base, emission + ambient * diffuse
  float shininess;
};

// Up to kShadeBatch pixels in structure-of-arrays form: [i] is the i-th pixel. What every batch
// has: the materials and the outputs.
constexpr int kShadeBatch = 128;
struct ShadeLanes {
  int count = 0;  // pixels filled; lanes [count, padded count) repeat the last pixel
  // Not null: every pixel has this material (a batch of one object, the common case), and the
  // per-pixel material arrays below are not read. The same floats, so the same bits.
  const ShadeMaterial* material = nullptr;
  // Per pixel, when material is null:
  alignas(64) float diffuse[3][kShadeBatch];
  alignas(64) float specular[3][kShadeBatch];
  alignas(64) float shininess[kShadeBatch];
  alignas(64) float base[3][kShadeBatch];  // shade_base: emission + ambient * diffuse
  // Outputs: the shading normal facing the viewer, and base plus the light samples.
  alignas(64) float shading_normal[3][kShadeBatch];
  alignas(64) float colour[3][kShadeBatch];
};

// A z-buffer's visible pixels: the surface point and normals are interpolated from the
// triangle's corners with the pixel's barycentrics, the viewer is the eye.
struct ShadeBatch : ShadeLanes {
  alignas(64) float bary[3][kShadeBatch];
  alignas(64) float vertex[3][3][kShadeBatch];  // [corner][axis]: the triangle's positions
  // [corner][axis]: its vertex normals if smooth; not read (may be anything) where flat.
  alignas(64) float normal[3][3][kShadeBatch];
  alignas(64) uint32_t smooth[kShadeBatch];  // ~0u: interpolate normals, 0: flat
};

// A tracer's hits. The kernel computes the surface as the tracer's scalar code does: the point
// origin + t direction; for a triangle the geometric normal normalize(cross(edge1, edge2)) and,
// where smooth, the vertex normals weighted by (1 - u - v, u, v) and divided by their length
// (kept geometric where that length is 0); where `given`, the normals below (other shapes). The
// viewer lies along the ray: V = -normalize(direction).
struct SurfaceBatch : ShadeLanes {
  float origin[3];  // every lane's ray starts here (primary rays)
  alignas(64) float t[kShadeBatch];
  alignas(64) float direction[3][kShadeBatch];
  alignas(64) float u[kShadeBatch];
  alignas(64) float v[kShadeBatch];
  alignas(64) float edge1[3][kShadeBatch];
  alignas(64) float edge2[3][kShadeBatch];
  // [corner][axis]: the triangle's vertex normals if smooth; not read (may be anything) where
  // flat or given.
  alignas(64) float vertex_normal[3][3][kShadeBatch];
  alignas(64) uint32_t smooth[kShadeBatch];     // ~0u: interpolate vertex normals, 0: flat
  alignas(64) uint32_t given[kShadeBatch];      // ~0u: the normals are geometric and shading
  alignas(64) float geometric[3][kShadeBatch];  // unit, as modelled; read where given
  alignas(64) float shading[3][kShadeBatch];    // unit; read where given
  // Output of light_needs: the surface point o + t d.
  alignas(64) float position[3][kShadeBatch];
};

// At most this many light samples per batch when their visibility is given (full mode's shadow
// rays): the visibility of each sample at each pixel, and which samples need it.
constexpr int kShadeVisibleLights = 16;
// bits[l]: bit i (of the 128, two words) set where light sample l adds a term at pixel i (its
// distance above 0 and its brdf not 0, as add_light_samples skips the others): where
// shade_local would call its visibility.
struct LightNeeds {
  uint64_t bits[kShadeVisibleLights][2];
  bool at(int l, int i) const { return (bits[l][i / 64] >> (i % 64) & 1) != 0; }
};
// vis[l][i]: vis_l at pixel i (used where the light sample's bit in LightNeeds is set).
struct LightVisibility {
  alignas(64) float vis[kShadeVisibleLights][kShadeBatch];
};

// The light samples, structure of arrays, in the order they are summed.
struct ShadeLights {
  const float* position[3];
  const float* intensity[3];
  int count;
};

struct ShadeKernels {
  const char* isa;
  // Fill batch.shading_normal and batch.colour for pixels [0, count) (and the padding).
  void (*shade)(ShadeBatch& batch, const float eye[3], const ShadeLights& lights);
  // Each light sample's visibility 1 when `visibility` is null (local mode), else
  // visibility->vis[l][i] (lights.count <= kShadeVisibleLights).
  void (*shade_surfaces)(SurfaceBatch& batch, const ShadeLights& lights,
                         const LightVisibility* visibility);
  // Fill batch.position, batch.shading_normal and `needs` (cleared first) for pixels [0, count),
  // lights.count <= kShadeVisibleLights: the points and normals a tracer's shadow rays leave from,
  // and which it traces, before shade_surfaces takes their visibility.
  void (*light_needs)(SurfaceBatch& batch, const ShadeLights& lights, LightNeeds& needs);
};

// The kernels of one instruction set; the caller must have checked cpu_supports(isa).
const ShadeKernels& shade_kernels(Isa isa);

namespace isa_sse {
extern const ShadeKernels kShadeKernels;
}
namespace isa_avx2 {
extern const ShadeKernels kShadeKernels;
}
namespace isa_avx512 {
extern const ShadeKernels kShadeKernels;
}

}  // namespace rvr
