// srgb8's table against the sRGB formula itself, written out here (IEC 61966-2-1 in float, as
// 8-bit images were always written): every float of the pow branch, and the linear branch and
// the ends sampled. Any differing float would change the bytes of every PNG rvr writes.
#include <gtest/gtest.h>
#include <stddef.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <memory>

#include "rvr/core/srgb.h"

namespace {

uint8_t by_formula(float v) {
  float e;
  if (!(v > 0.0f))
    e = 0.0f;
  else if (v >= 1.0f)
    e = 1.0f;
  else
    e = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
  return uint8_t(std::lround(e * 255.0f));
}

TEST(Srgb8, EveryFloatOfThePowBranchGivesTheFormulasByte) {
  // From the largest float of the linear branch to 1: ~76 million floats, all of them.
  const uint32_t first = std::bit_cast<uint32_t>(0.0031308f), last = std::bit_cast<uint32_t>(1.0f);
  size_t differing = 0;
  uint32_t example = 0;
  for (uint32_t b = first; b <= last; ++b) {
    const float v = std::bit_cast<float>(b);
    if (rvr::srgb8(v) != by_formula(v) && differing++ == 0) example = b;
  }
  EXPECT_EQ(differing, 0u) << "first at " << std::bit_cast<float>(example);
}

TEST(Srgb8, LinearBranchNegativesNansAndLargeValues) {
  // Every 97th float below the pow branch (all binades down to the denormals), then specials.
  size_t checked = 0;
  for (uint32_t b = 0; b < std::bit_cast<uint32_t>(0.0031308f); b += 97, ++checked)
    ASSERT_EQ(rvr::srgb8(std::bit_cast<float>(b)), by_formula(std::bit_cast<float>(b)))
        << std::bit_cast<float>(b);
  EXPECT_GT(checked, 10'000'000u);
  for (float v : {-0.0f, -1.0f, -INFINITY, NAN, -NAN, 1.0f, 1.0000001f, 2.0f, 1e30f, INFINITY})
    EXPECT_EQ(rvr::srgb8(v), by_formula(v)) << v;
  EXPECT_EQ(rvr::srgb8(0.5f), 188);  // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 -> 187.5... -> 188
  EXPECT_EQ(rvr::srgb8(0.0031308f * 0.5f), 5);  // 12.92 * 0.0015654 * 255 = 5.16
}

// srgb_decode against IEC 61966-2-1's decoding in double at every 8-bit value (what 8-bit
// textures hold), and back: encoding the decoded value gives the byte again.
TEST(SrgbDecode, EveryByteDecodesToTheStandardsValueAndEncodesBack) {
  for (int b = 0; b <= 255; ++b) {
    const double c = b / 255.0;
    const double linear = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    const float decoded = rvr::srgb_decode(float(b) / 255.0f);
    EXPECT_NEAR(decoded, linear, 1e-6 * std::max(linear, 1e-3)) << "byte " << b;
    EXPECT_EQ(rvr::srgb8(decoded), b) << "byte " << b;
  }
  EXPECT_EQ(rvr::srgb_decode(-0.5f), 0.0f);
  EXPECT_EQ(rvr::srgb_decode(std::nanf("")), 0.0f);
  EXPECT_EQ(rvr::srgb_decode(2.0f), 1.0f);
}

}  // namespace
