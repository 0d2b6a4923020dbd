// The SIMD layer of the kernels: one set of vector types and operations per instruction set,
// chosen by the compiler's target macros of the translation unit that includes it (as Embree's
// common/simd), so a kernel is written once and compiled per ISA by rvr_add_simd_kernels (the
// top-level CMakeLists.txt, which lists the ISAs in RVR_SIMD_ISAS):
//
//   simd_sse.h     vfloat4, vboolf4, vint4, vdouble2, vllong2            (every ISA)
//   simd_avx2.h    vfloat8, vboolf8, vint8, vdouble4, vllong4             (AVX2, AVX-512)
//   simd_avx512.h  vfloat16, vboolf16, vint16, vdouble8, vboold8, vllong8, masked loads and
//                  stores
//   simd_halves.h  the wider float, mask and int vectors as two halves:   (SSE, AVX2)
//                  8 and 16 lanes in SSE units, 16 in AVX2 ones
//
// and the native widths below (vfloatx: 4, 8 or 16 floats; vdoublex: 2, 4 or 8 doubles). On top
// of them, for every ISA, vec3v.h: Vec3v<V>, 3-vectors of these vectors (dot, cross, ...).
// Operators and functions are the IEEE operations of their scalar forms, lane by lane: + - * /
// and sqrt round as the scalar ones do, min / max return their second operand when either is
// NaN (MINPS / MAXPS), comparisons are ordered but != (unordered), and nothing fuses a multiply
// and an add (the kernel units build with -ffp-contract=off and no operation here is an FMA).
// So a kernel does the same operations in every ISA and its bytes do not depend on the ISA.
//
// Only kernel translation units (which define RVR_KERNEL_NS) may include this. Everything here
// has internal linkage (an anonymous namespace): a kernel object must export no code, or the
// linker could pick its AVX-512 copy of an inline function for baseline code too
// (tests/check_kernel_symbols.sh).
#pragma once

#ifndef RVR_KERNEL_NS
#error "rvr/core/simd/simd.h is for SIMD kernel translation units only (docs/design.md)"
#endif

#if defined(__AVX512F__)
#include "rvr/core/simd/simd_avx512.h"
#else
#include "rvr/core/simd/simd_halves.h"
#endif

namespace rvr::simd {
namespace {

#if defined(__AVX512F__)
using vfloatx = vfloat16;
using vboolfx = vboolf16;
using vdoublex = vdouble8;
using vllongx = vllong8;
#elif defined(__AVX2__)
using vfloatx = vfloat8;
using vboolfx = vboolf8;
using vdoublex = vdouble4;
using vllongx = vllong4;
#else
using vfloatx = vfloat4;
using vboolfx = vboolf4;
using vdoublex = vdouble2;
using vllongx = vllong2;
#endif
// Lanes of the native vectors.
constexpr int kFloatLanes = int(sizeof(vfloatx) / sizeof(float));
constexpr int kDoubleLanes = int(sizeof(vdoublex) / sizeof(double));

}  // namespace
}  // namespace rvr::simd
