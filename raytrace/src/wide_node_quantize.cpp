// Quantized child boxes of a wide node: planes rounded outward to a power-of-two grid.
#include "rvr/raytrace/wide_node_quantize.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "rvr/core/check.h"

namespace rvr {
namespace {

constexpr int kMaxSteps = 255;
constexpr int kBias = 127;
constexpr int kLowestExponent = 1 - kBias;  // the steps stay normal floats
constexpr int kHighestExponent = 254 - kBias;

// origin + q * step, as the kernels compute it (q * step is exact).
float plane(float origin, int q, float step) {
  return origin + float(q) * step;
}

// The planes of every child on one axis with steps of 2^e; false when an upper plane needs more
// than kMaxSteps steps.
bool quantize_axis(const Aabb* boxes, int count, int axis, float origin, int e, WideNode& node) {
  const float step = std::ldexp(1.0f, e);
  for (int i = 0; i < count; ++i) {
    const float lo = boxes[i].lo[axis], hi = boxes[i].hi[axis];
    // Rounding to nearest is monotonic and lo, hi are floats, so planes on the outer side of
    // lo and hi before their rounding to float stay there after it. (lo - origin) / step is
    // exact in double unless the two differ in magnitude by more than 2^29; the loops correct
    // that rounding.
    int q_lo = int(std::clamp(std::floor((double(lo) - origin) / step), 0.0, double(kMaxSteps)));
    while (q_lo > 0 && plane(origin, q_lo, step) > lo) --q_lo;
    int q_hi = int(std::clamp(std::ceil((double(hi) - origin) / step), 0.0, kMaxSteps + 1.0));

    while (q_hi <= kMaxSteps && plane(origin, q_hi, step) < hi) ++q_hi;
    if (q_hi > kMaxSteps) return false;
    node.q[2 * axis][i] = uint8_t(q_lo);
    node.q[2 * axis + 1][i] = uint8_t(q_hi);
  }
  return true;
}

}  // namespace

float quantization_step(uint8_t e) {
  return std::bit_cast<float>(uint32_t(e) << 23);
}

void quantize_children(const Aabb* boxes, int count, WideNode& node) {
  RVR_CHECK(count >= 1 && count <= kWideBvhWidth, "a wide node has 1 to 8 children: ", count);
  Aabb all;
  for (int i = 0; i < count; ++i) {
    RVR_CHECK(!boxes[i].empty(), "child ", i, " of a wide node has an empty box");
    all.grow(boxes[i]);
  }
  for (int a = 0; a < 3; ++a) {
    RVR_CHECK(std::isfinite(all.lo[a]) && std::isfinite(all.hi[a]),
              "a wide node's box must be finite; axis ", a);
    node.origin[a] = all.lo[a];
    // The smallest power of two with 255 steps over the extent, then larger until every upper
    // plane, rounded, fits (rounding of origin + q * step can fall short by an ulp).
    const double extent = double(all.hi[a]) - double(all.lo[a]);
    int e = extent > 0.0 ? int(std::ceil(std::log2(extent / kMaxSteps))) : kLowestExponent;
    e = std::max(e, kLowestExponent);
    while (!quantize_axis(boxes, count, a, node.origin[a], e, node)) {
      ++e;
      RVR_CHECK(e <= kHighestExponent, "no quantization step fits axis ", a, " of a wide node");
    }
    node.scale_exp[a] = uint8_t(e + kBias);
  }
  for (int i = count; i < kWideBvhWidth; ++i) {
    for (int row = 0; row < 6; ++row) node.q[row][i] = 0;
  }
  node.valid = uint8_t((1u << count) - 1u);
}

Aabb dequantized_child(const WideNode& node, int i) {
  Aabb box;
  for (int a = 0; a < 3; ++a) {
    const float step = quantization_step(node.scale_exp[a]);
    box.lo[a] = plane(node.origin[a], node.q[2 * a][i], step);
    box.hi[a] = plane(node.origin[a], node.q[2 * a + 1][i], step);
  }
  return box;
}

}  // namespace rvr
