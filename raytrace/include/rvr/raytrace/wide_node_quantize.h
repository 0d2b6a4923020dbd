// Quantized child boxes of a wide node (WideNode in wide_bvh_layout.h): how the builder stores
// them and how baseline code reads them back. The kernels dequantize the same way in their own
// units (wide_kernels.inl).
#pragma once

#include "rvr/raytrace/bvh.h"
#include "rvr/raytrace/wide_bvh_layout.h"

namespace rvr {

// Stores boxes[0..count) (2..8 non-empty boxes) as `node`'s quantized children: per axis the
// origin is the lowest lower plane and the step the smallest power of two that reaches the
// highest upper plane in 255 steps; lower planes are rounded down and upper planes up, so the
// dequantized box of child i contains boxes[i]. Sets `valid` to the first `count` slots; leaves
// `child` alone.
void quantize_children(const Aabb* boxes, int count, WideNode& node);

// Child slot i's box as the kernels test it: origin + q * step per plane.
Aabb dequantized_child(const WideNode& node, int i);

// The step of an axis whose biased exponent is e (1..254): 2^(e - 127).
float quantization_step(uint8_t e);

}  // namespace rvr
