// Vec3v (rvr/core/simd/vec3v.h) compiled in one unit per instruction set, like the kernels, so
// that test_vec3v can hold every operation of every ISA and vector width to the scalar
// computation: each unit evaluates the operations on sixteen lanes of inputs. With them, the
// lane operations of the vectors themselves that the packet kernels use (abs, sign bits, masks
// and their bits, the largest lane), and the int vectors' unsigned comparison and masked gather.
#pragma once

#include <cstdint>

namespace rvr {

constexpr int kProbeLanes = 16;
constexpr uint32_t kProbeTable = 64;

struct Vec3vProbeInput {
  alignas(64) float a[3][kProbeLanes];
  alignas(64) float b[3][kProbeLanes];
  alignas(64) float s[kProbeLanes];  // the scalar factor and divisor
  // The int vectors' lookups: i and j compared unsigned, and table entries gathered.
  uint32_t i[kProbeLanes], j[kProbeLanes];
  uint32_t table[kProbeTable];
};

// Lane k of every result from lane k of the inputs; select takes a where a.x < b.x.
struct Vec3vProbeOutput {
  alignas(64) float sum[3][kProbeLanes];
  alignas(64) float difference[3][kProbeLanes];
  alignas(64) float negated[3][kProbeLanes];
  alignas(64) float product[3][kProbeLanes];
  alignas(64) float scaled[3][kProbeLanes];
  alignas(64) float quotient[3][kProbeLanes];
  alignas(64) float cross[3][kProbeLanes];
  alignas(64) float normalized[3][kProbeLanes];
  alignas(64) float selected[3][kProbeLanes];
  alignas(64) float dot[kProbeLanes];
  alignas(64) float length_squared[kProbeLanes];
  // Vector widths only: abs(a.x); a.x ^ signbits(b.x); masked(from_bits(movemask(a.x < b.x)),
  // a.x); bit k of less_bits is lane k of a.x < b.x.
  alignas(64) float abs_x[kProbeLanes];
  alignas(64) float sign_flipped_x[kProbeLanes];
  alignas(64) float masked_x[kProbeLanes];
  unsigned less_bits;
  float max_x;  // 16 lanes only: reduce_max(a.x)
  // Vector widths only: bit k of below_bits is lane k of less_unsigned(i, j); gathered[k] is
  // table[i[k]] + i[k] where i[k] < kProbeTable (gather's mask), else i[k] (gather's 0 + i).
  unsigned below_bits;
  uint32_t gathered[kProbeLanes];
};

// The vector types Vec3v is instantiated with: float (one lane at a time; no normalize or
// select, which the kernels use on vectors only), vfloat4, vfloat8, vfloat16 (the packets'
// width, in every ISA) and the ISA's native vfloatx.
enum class ProbeWidth { Scalar, Four, Eight, Sixteen, Native };
inline constexpr ProbeWidth kAllProbeWidths[] = {ProbeWidth::Scalar, ProbeWidth::Four,
                                                 ProbeWidth::Eight, ProbeWidth::Sixteen,
                                                 ProbeWidth::Native};

struct Vec3vProbe {
  const char* isa;
  void (*run)(ProbeWidth width, const Vec3vProbeInput& in, Vec3vProbeOutput& out);
};

namespace isa_sse {
extern const Vec3vProbe kVec3vProbe;
}
namespace isa_avx2 {
extern const Vec3vProbe kVec3vProbe;
}
namespace isa_avx512 {
extern const Vec3vProbe kVec3vProbe;
}

}  // namespace rvr
