// softraster's deferred shading of visible pixels (the local term of docs/design.md's shading
// equation), as SIMD kernels compiled once per instruction set (src/soft/kernels/shade_*.cpp)
// and chosen at run time like the fill kernels: 4 (SSE), 8 (AVX2) or 16 (AVX-512) pixels at
// once. Each lane does the float operations of rvr::shade_local and the glm calls it makes, in
// the same order (no FMA: -ffp-contract=off), and x^shininess with the C library's powf, so
// every kernel, and the scalar shade_local, give the same bits. Plain data only: a kernel
// translation unit must not instantiate inline code that baseline code also uses.
#pragma once

#include <cstdint>

namespace rvr::soft {

// Lanes of the widest kernel: batches are padded to a multiple of it.
constexpr int kShadeMaxLanes = 16;

// The material terms the kernel reads, of one object.
struct ShadeMaterial {
  float diffuse[3], specular[3], base[3];  // base: shade_base, emission + ambient * diffuse
  float shininess;
};

// Up to kShadeBatch visible pixels in structure-of-arrays form: [i] is the i-th pixel.
constexpr int kShadeBatch = 128;
struct ShadeBatch {
  int count = 0;  // pixels filled; lanes [count, padded count) repeat the last pixel
  // Not null: every pixel has this material (a batch of one object, the common case), and the
  // per-pixel material arrays below are not read. The same floats, so the same bits.
  const ShadeMaterial* material = nullptr;
  alignas(64) float bary[3][kShadeBatch];
  alignas(64) float vertex[3][3][kShadeBatch];  // [corner][axis]: the triangle's positions
  // [corner][axis]: its vertex normals if smooth; not read (may be anything) where flat.
  alignas(64) float normal[3][3][kShadeBatch];
  alignas(64) uint32_t smooth[kShadeBatch];  // ~0u: interpolate normals, 0: flat
  // Per pixel, when material is null:
  alignas(64) float diffuse[3][kShadeBatch];
  alignas(64) float specular[3][kShadeBatch];
  alignas(64) float shininess[kShadeBatch];
  alignas(64) float base[3][kShadeBatch];  // shade_base: emission + ambient * diffuse
  // Outputs: the shading normal facing the viewer, and base plus the light samples.
  alignas(64) float shading_normal[3][kShadeBatch];
  alignas(64) float colour[3][kShadeBatch];
};

// The light samples, structure of arrays, in the order they are summed.
struct ShadeLights {
  const float* position[3];
  const float* intensity[3];
  int count;
};

struct ShadeKernels {
  const char* isa;
  // Fills batch.shading_normal and batch.colour for pixels [0, count) (and the padding).
  void (*shade)(ShadeBatch& batch, const float eye[3], const ShadeLights& lights);
};

namespace isa_sse {
extern const ShadeKernels kShadeKernels;
}
namespace isa_avx2 {
extern const ShadeKernels kShadeKernels;
}
namespace isa_avx512 {
extern const ShadeKernels kShadeKernels;
}

}  // namespace rvr::soft
