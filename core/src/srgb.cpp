// srgb8 by table. lround(255 * srgb_encode(v)) never decreases as v grows (tests/test_srgb.cpp
// checks every float of the pow branch; the linear branch is a product, monotone in IEEE
// arithmetic), so it is fixed by the smallest float where each value 1..255 starts. Those are
// found once by bisection on the float bit patterns; a second table gives the value at the
// start of each of the 2^16 ranges of floats sharing exponent and top 8 mantissa bits, so a
// lookup takes that value or the next.
#include "rvr/core/srgb.h"

#include <stddef.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

#include "rvr/core/check.h"

namespace rvr {

float srgb_encode(float v) {
  if (!(v > 0.0f)) return 0.0f;  // also NaN
  if (v >= 1.0f) return 1.0f;
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

float srgb_decode(float c) {
  if (!(c > 0.0f)) return 0.0f;  // also NaN
  if (c >= 1.0f) return 1.0f;
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

namespace {

uint8_t srgb8_by_formula(float v) {
  return uint8_t(std::lround(srgb_encode(v) * 255.0f));
}

constexpr int kBucketShift = 15;  // keeps the exponent and the top 8 mantissa bits
constexpr uint32_t kOneBits = 0x3f800000u;

struct Srgb8Table {
  std::array<float, 257> starts{};  // starts[k]: smallest float giving k; starts[256] = +inf
  std::array<uint8_t, (kOneBits >> kBucketShift) + 1> bucket{};

  Srgb8Table() {
    starts[0] = 0.0f;
    for (int k = 1; k <= 255; ++k) {
      uint32_t lo = 0, hi = kOneBits;  // formula(lo) < k <= formula(hi)
      while (hi - lo > 1) {
        const uint32_t mid = lo + (hi - lo) / 2;
        (srgb8_by_formula(std::bit_cast<float>(mid)) >= k ? hi : lo) = mid;
      }
      starts[size_t(k)] = std::bit_cast<float>(hi);
      RVR_CHECK(starts[size_t(k)] > starts[size_t(k - 1)],
                "srgb8 never decreases, so each value starts past the one before: ", k);
    }
    starts[256] = INFINITY;
    for (uint32_t b = 0; b < bucket.size(); ++b) {
      const float first = std::bit_cast<float>(b << kBucketShift);
      bucket[b] = uint8_t(std::upper_bound(starts.begin() + 1, starts.begin() + 256, first) -
                          (starts.begin() + 1));
    }
  }
};

}  // namespace

uint8_t srgb8(float v) {
  if (!(v > 0.0f)) return 0;
  if (v >= 1.0f) return 255;
  static const Srgb8Table table;
  unsigned out = table.bucket[std::bit_cast<uint32_t>(v) >> kBucketShift];
  // A bucket spans at most a third of a step (near 1, where the ramp is steepest per bucket:
  // 255 * d(encode)/dv * 2^-9 ~ 0.33), so the value is the bucket's or the next.
  out += v >= table.starts[out + 1] ? 1u : 0u;
  RVR_DCHECK(v >= table.starts[out] && v < table.starts[out + 1],
             "a bucket spans at most one step of the table");
  return uint8_t(out);
}

}  // namespace rvr
