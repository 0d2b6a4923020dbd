// Vec3v, the SIMD layer's 3-vectors of vectors (rvr/core/simd/vec3v.h), in every instruction set
// this CPU runs and at every vector width the kernels use, against glm's vec3, the scalar code
// the kernels mirror (and the vectors' own lane operations against their scalar forms): every
// lane of every operation bit for bit, on random vectors whose
// components span many magnitudes (so that a different association of a sum or a different
// order of a difference changes the bits).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#include <ios>
#include <random>
#include <string>

#include "rvr/core/expected.h"
#include "rvr/core/isa.h"
#include "simd/vec3v_probe.h"

using namespace rvr;

namespace {

const char* to_string(ProbeWidth width) {
  switch (width) {
    case ProbeWidth::Scalar:
      return "float";
    case ProbeWidth::Four:
      return "vfloat4";
    case ProbeWidth::Eight:
      return "vfloat8";
    case ProbeWidth::Sixteen:
      return "vfloat16";
    case ProbeWidth::Native:
      return "vfloatx";
  }
  return "?";
}

uint32_t bits(float x) {
  uint32_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

glm::vec3 lane(const float (&rows)[3][kProbeLanes], int k) {
  return {rows[0][k], rows[1][k], rows[2][k]};
}

// Components from 2^-12 to 2^12 in size, either sign; lane 0 of a is the zero vector and lane 1
// of s is zero (normalize and the quotient then give NaN and infinities).
Vec3vProbeInput random_input(std::mt19937& rng) {
  std::uniform_real_distribution<float> mantissa(-1.0f, 1.0f);
  std::uniform_int_distribution<int> exponent(-12, 12);
  auto draw = [&] { return std::ldexp(mantissa(rng), exponent(rng)); };
  Vec3vProbeInput in;
  // Ints on both sides of 2^31 (where a signed comparison errs) and of the table's end.
  std::uniform_int_distribution<uint32_t> any;
  auto draw_int = [&]() -> uint32_t {
    switch (any(rng) % 4) {
      case 0:
        return any(rng) % kProbeTable;
      case 1:
        return kProbeTable + any(rng) % 4;
      case 2:
        return 0x80000000u + any(rng) % 4;
      default:
        return any(rng);
    }
  };
  for (uint32_t t = 0; t < kProbeTable; ++t) in.table[t] = any(rng);
  for (int k = 0; k < kProbeLanes; ++k) {
    in.i[k] = draw_int();
    in.j[k] = k % 5 == 0 ? in.i[k] : draw_int();
  }
  for (int k = 0; k < kProbeLanes; ++k) {
    for (int a = 0; a < 3; ++a) {
      in.a[a][k] = k == 0 ? 0.0f : draw();
      in.b[a][k] = draw();
    }
    in.s[k] = k == 1 ? 0.0f : draw();
  }
  return in;
}

struct Checker {
  std::string where;
  int failures = 0;
  void same(const char* what, int k, float got, float want) {
    if (bits(got) == bits(want) || ++failures > 10) return;
    ADD_FAILURE() << where << " lane " << k << " " << what << ": " << got << " (0x" << std::hex
                  << bits(got) << "), scalar " << want << " (0x" << bits(want) << std::dec << ")";
  }
  void same(const char* what, int k, const float (&rows)[3][kProbeLanes], glm::vec3 want) {
    for (int a = 0; a < 3; ++a) same(what, k, rows[a][k], want[a]);
  }
};

TEST(Vec3v, EveryLaneIsTheScalarOperationInEveryIsaAndWidth) {
  int tested = 0;
  for (Isa isa : kAllIsas) {
    if (!cpu_supports(isa)) continue;
    const Vec3vProbe& probe =
        dispatch_isa(isa, isa_sse::kVec3vProbe, isa_avx2::kVec3vProbe, isa_avx512::kVec3vProbe);
    ASSERT_EQ(std::string(probe.isa), to_string(isa));
    for (ProbeWidth width : kAllProbeWidths) {
      std::mt19937 rng(35);
      Checker check{std::string(to_string(isa)) + " " + to_string(width)};
      for (int trial = 0; trial < 64; ++trial) {
        const Vec3vProbeInput in = random_input(rng);
        Vec3vProbeOutput out{};
        probe.run(width, in, out);
        float max_x = in.a[0][0];
        unsigned less_bits = 0;
        for (int k = 0; k < kProbeLanes; ++k) {
          max_x = std::max(max_x, in.a[0][k]);
          less_bits |= unsigned(in.a[0][k] < in.b[0][k]) << k;
        }
        if (width != ProbeWidth::Scalar) {
          EXPECT_EQ(out.less_bits, less_bits) << check.where;
          unsigned below_bits = 0;
          for (int k = 0; k < kProbeLanes; ++k) {
            below_bits |= unsigned(in.i[k] < in.j[k]) << k;
            const uint32_t i = in.i[k];
            EXPECT_EQ(out.gathered[k], i < kProbeTable ? in.table[i] + i : i)
                << check.where << " lane " << k << " gather";
          }
          EXPECT_EQ(out.below_bits, below_bits) << check.where;
        }
        if (width == ProbeWidth::Sixteen) check.same("reduce_max", 0, out.max_x, max_x);
        for (int k = 0; k < kProbeLanes; ++k) {
          const glm::vec3 a = lane(in.a, k), b = lane(in.b, k);
          const float s = in.s[k];
          check.same("a + b", k, out.sum, a + b);
          check.same("a - b", k, out.difference, a - b);
          check.same("-a", k, out.negated, -a);
          check.same("a * b", k, out.product, a * b);
          check.same("a * s", k, out.scaled, a * s);
          check.same("a / s", k, out.quotient, a / s);
          check.same("cross", k, out.cross, glm::cross(a, b));
          check.same("dot", k, out.dot[k], glm::dot(a, b));
          check.same("length_squared", k, out.length_squared[k], glm::dot(a, a));
          if (width == ProbeWidth::Scalar) continue;  // vector operations only
          check.same("normalize", k, out.normalized, glm::normalize(a));
          check.same("select", k, out.selected, a.x < b.x ? a : b);
          check.same("abs", k, out.abs_x[k], std::fabs(a.x));
          check.same("a ^ signbits(b)", k, out.sign_flipped_x[k], std::signbit(b.x) ? -a.x : a.x);
          check.same("masked", k, out.masked_x[k], a.x < b.x ? a.x : 0.0f);
        }
      }
      ++tested;
    }
  }
  EXPECT_GE(tested, 5);  // SSE runs on every x86-64
}

}  // namespace
